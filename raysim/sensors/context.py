"""What a sensor renderer is handed: the edge between :mod:`raysim.render` and the sensors.

:class:`raysim.render.RenderContext` is the one implementation; the renderers
(``render_lidar``, ``render_radar``, ``render_ais``) name this protocol so that the
sensors do not import the pipeline that imports them.
"""

from __future__ import annotations

from pathlib import Path
from typing import Protocol

from raysim.sensors.carrier import CarrierScene
from raysim.world import World

__all__ = ["SensorContext"]


class SensorContext(Protocol):
    """The world, the staging directory, whether to show progress, and where to count outputs."""

    world: World
    out_dir: Path
    progress: bool
    counts: dict

    def scene(self) -> CarrierScene:
        """The ray engine for the own ship's sensors (built once, shared by them)."""
        ...

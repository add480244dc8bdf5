"""raysim: physics-based raw sensor renderer for autonomous surface vessels.

Packages and modules (see docs/architecture.md):

- :mod:`raysim.scenario`  strict scenario loading into typed objects
- :mod:`raysim.geodesy`   lat/lon <-> local metres (pyproj)
- :mod:`raysim.pose`      rigid-body poses for arrays of times
- :mod:`raysim.motion`    ships on waypoints, own-ship trajectories, wave motion
- :mod:`raysim.meshes`    procedural icebergs, hulls, buoys, user meshes
- :mod:`raysim.materials` optical and radar material properties
- :mod:`raysim.scene`     the ray engine (Embree via Open3D): first hit of each ray at its own time
- :mod:`raysim.world`     the scenario turned into moving scene objects
- :mod:`raysim.render`    the recording writer pipeline
- :mod:`raysim.cli`       the ``raysim`` command
"""

__version__ = "0.1.0"

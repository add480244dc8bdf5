"""Render a scenario into a recording directory (DESIGN.md "Recording directory contract").

The pipeline: build the world (meshes, motions), then stream each product chunk
by chunk into a staged directory that is moved into place only when everything
succeeded. Sensors plug in through :data:`SENSOR_RENDERERS`.
"""

from __future__ import annotations

import datetime as dt
import json
import platform
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np
from tqdm import tqdm

from raysim import __version__, schema
from raysim.pose import heading_deg_from_yaw
from raysim.recording.jsonl import course_and_speed, write_ownship_chunk, write_truth_chunk
from raysim.recording.staging import MANIFEST, StagedDirectory, atomic_path
from raysim.scenario import Scenario, scenario_to_yaml
from raysim.world import World

TRUTH_RATE_HZ = 10.0  # DESIGN.md: one truth line per object per 0.1 s
CHUNK_S = 30.0  # seconds of truth / navigation formatted at a time (memory stays flat)


@dataclass
class RenderContext:
    """What a sensor renderer gets: the world, the staging directory, and where to report."""

    world: World
    out_dir: Path
    progress: bool
    counts: dict = field(default_factory=dict)
    wall_time_s: dict = field(default_factory=dict)
    _scene: object = None

    def scene(self):
        """The ray engine for the own ship's sensors (built once, shared by them)."""
        if self._scene is None:
            from raysim.materials import material_index
            from raysim.sensors.carrier import CarrierScene

            self._scene = CarrierScene(self.world.scene_objects(), carrier_id=self.world.own_ship.object_id,
                                       sea_material=material_index("sea"))
        return self._scene


def _render_lidar(ctx: "RenderContext") -> None:
    from raysim.sensors.lidar import render_lidar

    render_lidar(ctx)


def _render_radar(ctx: "RenderContext") -> None:
    from raysim.sensors.radar import render_radar

    render_radar(ctx)


#: Sensor name -> renderer(context). Sensors register here as they are implemented.
def _render_ais(ctx: "RenderContext") -> None:
    from raysim.sensors.ais import render_ais

    render_ais(ctx)


def _render_nav(ctx: "RenderContext") -> None:
    """nav/nav.nmea (:func:`write_nav_nmea`); ownship.jsonl is written whether or not nav is enabled."""
    ctx.counts["nav/nav.nmea"] = write_nav_nmea(ctx.world, ctx.out_dir / "nav" / "nav.nmea", ctx.progress)


SENSOR_RENDERERS: dict[str, Callable[[RenderContext], None]] = {"lidar": _render_lidar, "radar": _render_radar,
                                                                "ais": _render_ais, "nav": _render_nav}


@dataclass(frozen=True)
class RenderResult:
    out_dir: Path
    manifest: dict


def _ticks(duration_s: float, rate_hz: float) -> np.ndarray:
    """Times k / rate for k = 0 .. floor(duration * rate), without accumulated rounding."""
    n = int(np.floor(duration_s * rate_hz + 1e-9)) + 1
    return np.arange(n) / rate_hz


def _chunks(t_s: np.ndarray, rate_hz: float):
    step = max(1, int(CHUNK_S * rate_hz))
    for start in range(0, t_s.shape[0], step):
        yield t_s[start : start + step]


def write_truth(world: World, path: Path, progress: bool) -> int:
    """Write truth.jsonl: every object at 10 Hz. Returns the number of lines."""
    t_all = _ticks(world.scenario.duration_s, TRUTH_RATE_HZ)
    lines = 0
    with atomic_path(path) as tmp, open(tmp, "w", encoding="utf-8", newline="\n") as handle:
        for t in tqdm(list(_chunks(t_all, TRUTH_RATE_HZ)), desc="truth", unit="chunk", disable=not progress, leave=False):
            per_object = []
            for o in world.objects:
                poses = o.motion.poses(t)
                lat, lon = world.frame.to_geodetic(poses.position_m[:, 0], poses.position_m[:, 1])
                cog, sog = course_and_speed(o.motion.velocity_mps(t), poses.yaw_rad)
                per_object.append(dict(
                    id=o.object_id, name=o.name, kind=o.kind, length_m=o.length_m, beam_m=o.beam_m, height_m=o.height_m,
                    ais=bool(o.ais is not None and o.ais.enabled), mmsi=o.ais.mmsi if o.ais is not None else None,
                    lat=lat, lon=lon, x=poses.position_m[:, 0], y=poses.position_m[:, 1],
                    heading_deg=heading_deg_from_yaw(poses.yaw_rad), cog_deg=cog, sog_mps=sog,
                ))
            lines += write_truth_chunk(handle, t, per_object)
    return lines


def write_ownship(world: World, path: Path, progress: bool) -> int:
    """Write ownship.jsonl at the navigation rate. Returns the number of lines.

    The lines are the navigation solution: the true motion plus the GNSS/INS errors of
    ``sensors.nav`` (:mod:`raysim.sensors.nav`).
    """
    from raysim.sensors.nav import grid_size, navigation_chunks

    rate = world.scenario.sensors.nav.rate_hz
    step = max(1, int(CHUNK_S * rate))
    chunks = -(-grid_size(world.scenario.duration_s, rate) // step)
    lines = 0
    with atomic_path(path) as tmp, open(tmp, "w", encoding="utf-8", newline="\n") as handle:
        for t, columns in tqdm(navigation_chunks(world, step), total=chunks, desc="ownship", unit="chunk",
                               disable=not progress, leave=False):
            lines += write_ownship_chunk(handle, t, columns)
    return lines


def write_nav_nmea(world: World, path: Path, progress: bool) -> int:
    """Write nav/nav.nmea: TAG block + $GPRMC, $GPGGA, $HEHDT per NMEA epoch. Returns the number of lines.

    The values are the navigation solution of ownship.jsonl at the grid samples of
    :func:`raysim.sensors.nav.nmea_indices` (every 50th sample with the default 50 Hz / 1 Hz).
    """
    from raysim.recording import nmea
    from raysim.sensors.nav import grid_size, navigation_chunks, nmea_indices

    s = world.scenario
    cfg = s.sensors.nav
    indices = nmea_indices(s.duration_s, cfg.rate_hz, cfg.nmea_rate_hz)
    step = max(1, int(CHUNK_S * cfg.rate_hz))
    chunks = -(-grid_size(s.duration_s, cfg.rate_hz) // step)
    lines = 0
    with atomic_path(path) as tmp, open(tmp, "w", encoding="ascii", newline="\n") as handle:
        for t, c in tqdm(navigation_chunks(world, step, indices), total=chunks, desc="nav", unit="chunk",
                         disable=not progress, leave=False):
            out = []
            for k, t_s in enumerate(t.tolist()):
                utc = s.start_time + dt.timedelta(seconds=t_s)
                tag = nmea.tag_block(utc.timestamp())
                lat, lon = float(c["lat"][k]), float(c["lon"][k])
                out += [tag + nmea.gprmc(utc, lat, lon, float(c["sog_mps"][k]), float(c["cog_deg"][k])),
                        tag + nmea.gpgga(utc, lat, lon, float(c["z"][k])),
                        tag + nmea.hehdt(float(c["heading_deg"][k]))]
            handle.write("".join(line + "\n" for line in out))
            lines += len(out)
    return lines


def _versions() -> dict:
    import numpy
    import pyproj
    import trimesh

    versions = {"raysim": __version__, "python": platform.python_version(), "numpy": numpy.__version__,
                "pyproj": pyproj.__version__, "trimesh": trimesh.__version__}
    try:
        import open3d

        versions["open3d"] = open3d.__version__
    except ImportError:  # pragma: no cover - open3d is a hard dependency
        pass
    return versions


def render(scenario: Scenario, out_dir: Path, progress: bool | None = None, formats: tuple[str, ...] = (),
           after_sensors: Callable[[Path], dict[str, int]] | None = None) -> RenderResult:
    """Render ``scenario`` into ``out_dir``; all or nothing.

    Parameters
    ----------
    scenario : Scenario
        Resolved scenario (overrides applied).
    out_dir : Path
        Recording directory; replaced if it holds an older recording.
    progress : bool, optional
        Show progress bars; default: when stderr is a terminal.
    formats : tuple of str
        Extra point-cloud files from the LiDAR sweeps (:data:`raysim.recording.pointclouds.FORMATS`).
    after_sensors : callable, optional
        Called with the staged recording directory once the sensors' files and a provisional
        manifest are written (``raysim run`` runs the TDM here, so its targets join the bag);
        returns counts to add to the manifest. An error in it leaves nothing on disk.
    """
    if progress is None:
        progress = sys.stderr.isatty()
    started = time.perf_counter()
    wall: dict[str, float] = {}
    t0 = time.perf_counter()
    world = World(scenario)
    wall["world"] = time.perf_counter() - t0
    enabled = scenario.sensors.enabled_names()
    with StagedDirectory(Path(out_dir)) as staged:
        ctx = RenderContext(world, staged.path, progress, wall_time_s=wall)
        with atomic_path(staged.path / "scenario.yaml") as tmp:
            tmp.write_text(scenario_to_yaml(scenario), encoding="utf-8")
        t0 = time.perf_counter()
        ctx.counts["truth.jsonl"] = write_truth(world, staged.path / "truth.jsonl", progress)
        wall["truth"] = time.perf_counter() - t0
        t0 = time.perf_counter()
        ctx.counts["ownship.jsonl"] = write_ownship(world, staged.path / "ownship.jsonl", progress)
        wall["ownship"] = time.perf_counter() - t0
        rendered, not_available = [], []
        for name in enabled:
            renderer = SENSOR_RENDERERS.get(name)
            if renderer is None:
                not_available.append(name)
                continue
            t0 = time.perf_counter()
            renderer(ctx)
            wall[name] = time.perf_counter() - t0
            rendered.append(name)
        def manifest_now() -> dict:
            return {
                "format": "raysim-recording",
                "format_version": 1,
                "scenario": scenario.name,
                "seed": scenario.seed,
                "start_time": schema.to_plain(scenario.start_time),
                "duration_s": scenario.duration_s,
                "sensors_enabled": list(enabled),
                "sensors_rendered": rendered,
                "sensors_not_available": not_available,
                "objects": [{"id": o.object_id, "name": o.name, "kind": o.kind} for o in world.objects],
                "counts": dict(sorted(ctx.counts.items())),
                "versions": _versions(),
                "wall_time_s": {k: round(v, 3) for k, v in wall.items()},
            }

        if after_sensors is not None:
            with atomic_path(staged.path / MANIFEST) as tmp:
                tmp.write_text(json.dumps(manifest_now(), indent=2) + "\n", encoding="utf-8")
            t0 = time.perf_counter()
            ctx.counts.update(after_sensors(staged.path))
            wall["tdm"] = time.perf_counter() - t0
        t0 = time.perf_counter()
        from raysim.recording.rosbag import write_rosbag

        for topic, n in write_rosbag(staged.path, scenario).items():
            ctx.counts[f"rosbag{topic}"] = n
        wall["rosbag"] = time.perf_counter() - t0
        from raysim.recording.map_picture import write_map

        write_map(staged.path)
        ctx.counts["map.png"] = 1
        if (staged.path / "lidar" / "sweeps").is_dir():
            from raysim.recording.bev import write_bev

            ctx.counts["lidar/bev"] = write_bev(staged.path, scenario)
        if formats:
            from raysim.recording.pointclouds import write_point_cloud_files

            ctx.counts.update(write_point_cloud_files(staged.path, tuple(formats)))
        wall["total"] = time.perf_counter() - started
        manifest = manifest_now()
        with atomic_path(staged.path / MANIFEST) as tmp:
            tmp.write_text(json.dumps(manifest, indent=2) + "\n", encoding="utf-8")
        staged.commit()
    return RenderResult(Path(out_dir), manifest)


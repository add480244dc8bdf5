"""Render a scenario into a recording directory (docs/contracts.md "Recording directory").

The pipeline: build the world (meshes, motions), then stream each product chunk
by chunk into a staged directory that is moved into place only when everything
succeeded. Sensors plug in through :data:`SENSOR_RENDERERS`.
"""

from __future__ import annotations

import contextlib
import datetime as dt
import json
import multiprocessing
import platform
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Callable, Iterator

import numpy as np
from tqdm import tqdm

from groundfloor.recording import FORMAT, FORMAT_VERSION, LAND, MANIFEST
from raysim import __version__, schema
from raysim.pose import heading_deg_from_yaw
from raysim.progress import bars as progress_bars
from raysim.progress import stage
from raysim.recording.jsonl import centre_positions_m, course_and_speed, write_ownship_chunk, write_truth_chunk
from raysim.recording.staging import StagedDirectory, atomic_path
from raysim.scenario import Scenario, scenario_to_yaml
from raysim.second_process import SecondProcess, can_start
from raysim.sensors.lidar_run import ChunkClaims, join_pcap_parts, render_lidar, render_lidar_later_half
from raysim.world import World

if TYPE_CHECKING:  # pragma: no cover (the renderer loads Open3D: imported when a LiDAR renders)
    from raysim.sensors.lidar import LidarRenderer

TRUTH_RATE_HZ = 10.0  # docs/contracts.md: one truth line per object per 0.1 s
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
    #: In a second process rendering the LiDAR: the chunks it may render (raysim.sensors.lidar_run.ChunkClaims)
    lidar_claims: object = None

    def scene(self):
        """The ray engine for the own ship's sensors (built once, shared by them)."""
        if self._scene is None:
            from raysim.materials import material_index
            from raysim.sensors.carrier import CarrierScene

            self._scene = CarrierScene(self.world.scene_objects(), carrier_id=self.world.own_ship.object_id,
                                       sea_material=material_index("sea"))
        return self._scene


def _lidar_renderer(ctx: "RenderContext") -> "LidarRenderer":
    """A LiDAR renderer for the world and scene of ``ctx``."""
    from raysim.sensors.lidar import LidarRenderer

    return LidarRenderer(ctx.world, ctx.scene())


def _render_lidar(ctx: "RenderContext") -> None:
    render_lidar(_lidar_renderer(ctx), ctx)


def _render_radar(ctx: "RenderContext") -> None:
    from raysim.sensors.radar import render_radar

    render_radar(ctx)


#: Sensor name -> renderer(context). Sensors register here as they are implemented.
def _render_ais(ctx: "RenderContext") -> None:
    from raysim.sensors.ais import render_ais

    render_ais(ctx)


def _render_nav(ctx: "RenderContext") -> None:
    """nav/nav.nmea and nav/nav_plain.nmea (:func:`write_nav_nmea`); ownship.jsonl is written either way."""
    lines = write_nav_nmea(ctx.world, ctx.out_dir / "nav" / "nav.nmea", ctx.progress)
    ctx.counts["nav/nav.nmea"] = ctx.counts["nav/nav_plain.nmea"] = lines


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
                if o.kind == "land":  # land is in manifest.json, not in the epochs (docs/land.md)
                    continue
                poses = o.motion.poses(t)
                lat, lon = world.frame.to_geodetic(poses.position_m[:, 0], poses.position_m[:, 1])
                centre_x, centre_y = centre_positions_m(poses.position_m, poses.yaw_rad, o.centre_body_m)
                centre_lat, centre_lon = world.frame.to_geodetic(centre_x, centre_y)
                cog, sog = course_and_speed(o.motion.velocity_mps(t), poses.yaw_rad)
                per_object.append(dict(
                    id=o.object_id, name=o.name, kind=o.kind, length_m=o.length_m, beam_m=o.beam_m, height_m=o.height_m,
                    ais=bool(o.ais is not None and o.ais.enabled), mmsi=o.ais.mmsi if o.ais is not None else None,
                    lat=lat, lon=lon, x=poses.position_m[:, 0], y=poses.position_m[:, 1],
                    centre_lat=centre_lat, centre_lon=centre_lon, centre_x=centre_x, centre_y=centre_y,
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


def write_nav_nmea(world: World, path: Path, progress: bool, plain_path: Path | None = None) -> int:
    r"""Write nav/nav.nmea and nav/nav_plain.nmea in one pass. Returns the number of lines of each.

    Per NMEA epoch the sentences of :func:`raysim.recording.nmea.nav_epoch` ($GPRMC, $GPGGA, $GPVTG,
    $GPZDA, $HEHDT). ``path`` gets each line prefixed by an NMEA 4.10 TAG block (``\n`` line ends,
    for loggers and the TDM); ``plain_path`` (default ``nav_plain.nmea`` beside ``path``) the same
    sentences without TAG blocks and with CR LF line ends, as on an NMEA 0183 wire (chart plotters,
    pynmea2, gpsd). The values are the navigation solution of ownship.jsonl at the grid samples of
    :func:`raysim.sensors.nav.nmea_indices` (every 50th sample with the default 50 Hz / 1 Hz).
    """
    from raysim.recording import nmea
    from raysim.sensors.nav import grid_size, navigation_chunks, nmea_indices

    s = world.scenario
    cfg = s.sensors.nav
    plain_path = Path(path).with_name(Path(path).stem + "_plain.nmea") if plain_path is None else plain_path
    indices = nmea_indices(s.duration_s, cfg.rate_hz, cfg.nmea_rate_hz)
    step = max(1, int(CHUNK_S * cfg.rate_hz))
    chunks = -(-grid_size(s.duration_s, cfg.rate_hz) // step)
    lines = 0
    with atomic_path(path) as tmp, open(tmp, "w", encoding="ascii", newline="\n") as tagged, \
            atomic_path(plain_path) as plain_tmp, open(plain_tmp, "w", encoding="ascii", newline="\n") as plain:
        for t, c in tqdm(navigation_chunks(world, step, indices), total=chunks, desc="nav", unit="chunk",
                         disable=not progress, leave=False):
            tagged_out, plain_out = [], []
            for k, t_s in enumerate(t.tolist()):
                utc = s.start_time + dt.timedelta(seconds=t_s)
                tag = nmea.tag_block(utc.timestamp())
                epoch = nmea.nav_epoch(utc, float(c["lat"][k]), float(c["lon"][k]), float(c["z"][k]),
                                       float(c["sog_mps"][k]), float(c["cog_deg"][k]), float(c["heading_deg"][k]),
                                       cfg.geoid_separation_m)
                tagged_out += [tag + sentence + "\n" for sentence in epoch]
                plain_out += [sentence + "\r\n" for sentence in epoch]
            tagged.write("".join(tagged_out))
            plain.write("".join(plain_out))
            lines += len(plain_out)
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


def _sensor_plan(scenario: Scenario, name: str) -> str:
    """What sensor ``name`` is about to render, for the progress lines (e.g. ``"60 revolutions"``)."""
    cfg, duration_s = getattr(scenario.sensors, name), scenario.duration_s
    if name == "lidar":
        return f"{duration_s * cfg.rotation_hz:.0f} revolutions of the HDL-32E"
    if name == "radar":
        return f"{int(duration_s * cfg.rpm / 60.0 + 1e-9)} revolutions of {cfg.spokes} spokes"
    return f"{duration_s:g} s of {'AIS traffic' if name == 'ais' else 'navigation NMEA'}"


def write_bag(ctx: RenderContext) -> None:
    """The staged recording's ROS 2 bag (:func:`raysim.recording.rosbag.write_rosbag`); messages a topic
    in ``ctx.counts`` (``rosbag/<topic>``)."""
    from raysim.recording.rosbag import write_rosbag

    for topic, n in write_rosbag(ctx.out_dir, ctx.world.scenario).items():
        ctx.counts[f"rosbag{topic}"] = n


def _bag_done(counts: dict) -> str:
    return f"{sum(v for k, v in counts.items() if k.startswith('rosbag/'))} messages"


def _write_derived(ctx: RenderContext, scenario: Scenario, formats: tuple[str, ...], progress: bool | None,
                   beside: Callable[[Path], None] | None = None, processes: int = 1) -> None:
    """The files made from the staged recording's own: the bag, the pictures, the point-cloud files.

    Each is a progress stage (:func:`raysim.progress.stage`) timed in ``ctx.wall_time_s``
    (``rosbag``, ``pictures``, ``pointclouds``); their counts go to ``ctx.counts``. ``beside(staged
    directory)`` (``raysim run``: the TDM's evaluation) runs first; with ``processes`` >= 2 the bag is
    written in a second process meanwhile (:mod:`raysim.second_process`), and the pictures too.
    """
    wall: dict[str, float] = {}
    apart = _second_process_wanted(processes, scenario)
    with (_in_second_process("rosbag", write_bag, ctx, progress, "ROS 2 bag (MCAP), in a second process", _bag_done)
          if apart else contextlib.nullcontext({})) as bag:
        if beside is not None:
            beside(ctx.out_dir)
        if not apart:
            with stage("rosbag", progress, "ROS 2 bag (MCAP)") as step:
                write_bag(ctx)
                step.done = _bag_done(ctx.counts)
            wall["rosbag"] = step.elapsed_s
        wall.update(_write_pictures(ctx, scenario, formats, progress))
    if apart:
        wall["rosbag"] = bag["wall_s"]
    ctx.wall_time_s.update((k, wall[k]) for k in ("rosbag", "pictures", "pointclouds") if k in wall)


def _write_pictures(ctx: RenderContext, scenario: Scenario, formats: tuple[str, ...],
                    progress: bool | None) -> dict[str, float]:
    """map.png, the LiDAR's bird's-eye views and the point-cloud files ``formats``; their stages' wall times, s."""
    from raysim.recording.map_picture import write_map

    staged, wall = ctx.out_dir, {}
    lidar = (staged / "lidar" / "sweeps").is_dir()
    with stage("pictures", progress, "map.png" + (", LiDAR bird's-eye views" if lidar else "")) as step:
        write_map(staged, scenario.start_time)
        ctx.counts["map.png"] = 1
        if lidar:
            from raysim.recording.bev import write_bev

            ctx.counts["lidar/bev"] = write_bev(staged, scenario)
        step.done = f"{1 + ctx.counts.get('lidar/bev', 0)} pictures"
    wall["pictures"] = step.elapsed_s
    if formats:
        from raysim.recording.pointclouds import write_point_cloud_files

        with stage("pointclouds", progress, ", ".join(formats) + " files") as step:
            made = write_point_cloud_files(staged, tuple(formats))
            ctx.counts.update(made)
            step.done = ", ".join(f"{n} {k}" for k, n in made.items())
        wall["pointclouds"] = step.elapsed_s
    return wall




def _timed_into(wall: dict[str, float], key: str, work: Callable[[Path], None] | None) -> Callable[[Path], None] | None:
    """``work`` whose wall time, s, is added to ``wall[key]`` (None for None)."""
    if work is None:
        return None

    def timed(path: Path) -> None:
        started = time.perf_counter()
        work(path)
        wall[key] = wall.get(key, 0.0) + time.perf_counter() - started
    return timed


def _write_scenario_files(ctx: RenderContext, scenario: Scenario) -> None:
    """The resolved ``scenario.yaml`` and, with land, the recording's chart ``land.geojson`` (groundfloor.recording.LAND)."""
    with atomic_path(ctx.out_dir / "scenario.yaml") as tmp:
        tmp.write_text(scenario_to_yaml(scenario), encoding="utf-8")
    if scenario.land:
        from raysim.land.recording import write_land_geojson

        land_ids = {o.name: o.object_id for o in ctx.world.objects if o.kind == "land"}
        ctx.counts[LAND] = write_land_geojson(scenario, land_ids, ctx.out_dir / LAND)


def _render_sensors(ctx: RenderContext, scenario: Scenario, enabled, progress,
                    processes: int = 1) -> tuple[list[str], list[str]]:
    """Each enabled sensor's renderer (:data:`SENSOR_RENDERERS`) as a progress stage; (rendered, not available).

    With ``processes`` >= 2 (and another sensor to render beside it), the LiDAR renders in a second
    process while this process renders the others (:mod:`raysim.second_process`): the same files. Its
    stage starts with the process and ends when its files are all there.
    """
    names = [name for name in enabled if name in SENSOR_RENDERERS]
    not_available = [name for name in enabled if name not in SENSOR_RENDERERS]
    apart = "lidar" if "lidar" in names and len(names) > 1 and _second_process_wanted(processes, scenario) else None
    claims = ChunkClaims.make(multiprocessing.get_context("spawn")) if apart else None
    wall: dict[str, float] = {}
    started = time.perf_counter()
    with (_in_second_process(apart, SENSOR_RENDERERS[apart], ctx, progress,
                             _sensor_plan(scenario, apart) + ", in a second process", lambda c: _made(c, sorted(c)),
                             claims.shared if claims else None)
          if apart else contextlib.nullcontext({})) as lidar:
        for name in names:
            if name == apart:
                continue
            before = set(ctx.counts)
            with stage(name, progress, _sensor_plan(scenario, name), bar=name != "ais") as step:  # AIS: no bar
                SENSOR_RENDERERS[name](ctx)
                step.done = _made(ctx.counts, sorted(set(ctx.counts) - before))
            wall[name] = step.elapsed_s
        if apart:  # the other sensors are done: this process renders the later half of the LiDAR still to do
            lidar["later_half"] = render_lidar_later_half(_lidar_renderer(ctx), ctx, claims)
    if apart:
        join_pcap_parts(ctx.out_dir / "lidar")
        for key, value in lidar["later_half"].items():
            ctx.counts[key] += value
        wall[apart] = time.perf_counter() - started
    ctx.wall_time_s.update((name, wall[name]) for name in names)  # in the sensors' order
    return names, not_available


def _second_process_wanted(processes: int, scenario: Scenario) -> bool:
    """Whether a render asked for ``processes`` gets a second process (:func:`raysim.second_process.can_start`)."""
    return processes >= 2 and can_start(scenario.duration_s)


@contextlib.contextmanager
def _in_second_process(name: str, renderer: Callable, ctx: RenderContext, progress: bool | None, what: str,
                       done: Callable[[dict], str], claims=None) -> Iterator[dict]:
    """``renderer(ctx)`` in a second process (:class:`raysim.second_process.SecondProcess`) while the block
    runs, as the progress stage ``name``, which starts with the process and ends when it has finished; its
    counts join ``ctx.counts`` and the dict yielded gets ``"wall_s"``, the renderer's own wall time. The
    process is stopped if the block fails."""
    child = SecondProcess(name, renderer, ctx, claims)
    try:
        with stage(name, progress, what) as step:
            timing: dict = {}
            yield timing
            counts, timing["wall_s"] = child.join()
            ctx.counts.update(counts)
            step.done = done(counts)
    finally:
        child.stop()


def _made(counts: dict, keys: list[str]) -> str:
    """What a stage made, for its end line: ``"<count> <file>"`` of each of ``keys``."""
    return ", ".join(f"{counts[k]} {k.split('/', 1)[-1]}" for k in keys)


def _manifest(scenario: Scenario, world: World, enabled, rendered: list[str], not_available: list[str], counts: dict,
              wall: dict) -> dict:
    """manifest.json's content (docs/formats.md)."""
    return {
        "format": FORMAT,
        "format_version": FORMAT_VERSION,
        "scenario": scenario.name,
        "seed": scenario.seed,
        "start_time": schema.to_plain(scenario.start_time),
        "duration_s": scenario.duration_s,
        "sensors_enabled": list(enabled),
        "sensors_rendered": rendered,
        "sensors_not_available": not_available,
        "objects": [{"id": o.object_id, "name": o.name, "kind": o.kind} for o in world.objects],
        "counts": dict(sorted(counts.items())),
        "versions": _versions(),
        "wall_time_s": {k: round(v, 3) for k, v in wall.items()},
    }


def _warn_of_overlaps(world: World) -> None:
    """One line on stderr for each pair of hulls that pass through one another (:mod:`raysim.world_checks`)."""
    from raysim.world_checks import hull_overlaps

    source = world.scenario.source_file or "scenario"
    for overlap in hull_overlaps(world):
        print(f"warning: {source}: {overlap.message()}", file=sys.stderr, flush=True)


def render(scenario: Scenario, out_dir: Path, progress: bool | None = None, formats: tuple[str, ...] = (),
           after_sensors: Callable[[Path], dict[str, int]] | None = None, own_ship_motion=None,
           extra_counts: dict[str, int] | None = None, derived: bool = True,
           beside_derived: Callable[[Path], None] | None = None, processes: int = 1) -> RenderResult:
    """Render ``scenario`` into ``out_dir``; all or nothing.

    Parameters
    ----------
    scenario : Scenario
        Resolved scenario (overrides applied).
    out_dir : Path
        Recording directory; replaced if it holds an older recording.
    progress : bool, optional
        Progress on stderr (:mod:`raysim.progress`): default bars when stderr is a terminal, a line
        per stage start and end otherwise; ``True`` bars, ``False`` nothing.
    formats : tuple of str
        Extra point-cloud files from the LiDAR sweeps (:data:`raysim.recording.pointclouds.FORMATS`).
    after_sensors : callable, optional
        Called with the staged recording directory once the sensors' files and a provisional
        manifest are written (``raysim run`` runs the TDM here, so its targets join the bag);
        returns counts to add to the manifest. An error in it leaves nothing on disk.
    own_ship_motion : raysim.motion.Motion, optional
        The own ship's motion instead of the scenario's (``raysim live --record`` with a fed own ship).
    extra_counts : dict, optional
        Counts to add to the manifest (``raysim live --record``: what was sent and how late).
    derived : bool
        Write the files made from the recording's own (the bag, map.png, the bird's-eye views, the
        point-cloud files); False leaves them out (a recording for the TDM alone, as its tests use).
    beside_derived : callable, optional
        Called with the staged recording directory after ``after_sensors``, before the derived files
        (``raysim run``: the TDM's evaluation); with ``processes`` >= 2 the bag is written meanwhile in a
        second process. Its wall time is added to ``tdm``'s. An error in it leaves nothing on disk.
    processes : int
        2 or more: the LiDAR renders in a second process beside the other sensors, and the bag is written
        in one beside ``beside_derived`` and the pictures (when this process may have children;
        :mod:`raysim.second_process`), the same files; 1: one after another.
    """
    bars = progress_bars(progress)  # the stages' own tqdm bars
    started = time.perf_counter()
    wall: dict[str, float] = {}
    with stage("world", progress, f"meshes and motions of {scenario.name}") as step:
        world = World(scenario)
        if own_ship_motion is not None:
            world.drive_own_ship(own_ship_motion)
        step.done = f"{len(world.objects)} objects"
    _warn_of_overlaps(world)
    wall["world"] = step.elapsed_s
    enabled = scenario.sensors.enabled_names()
    with StagedDirectory(Path(out_dir)) as staged:
        ctx = RenderContext(world, staged.path, bars, wall_time_s=wall)
        ctx.counts.update(extra_counts or {})
        _write_scenario_files(ctx, scenario)
        for name, write in (("truth", write_truth), ("ownship", write_ownship)):
            with stage(name, progress, f"{scenario.duration_s:g} s", bar=True) as step:
                ctx.counts[f"{name}.jsonl"] = write(world, staged.path / f"{name}.jsonl", bars)
                step.done = f"{ctx.counts[f'{name}.jsonl']} lines"
            wall[name] = step.elapsed_s
        rendered, not_available = _render_sensors(ctx, scenario, enabled, progress, processes)
        wall["render"] = time.perf_counter() - started  # world, truth, navigation and sensors

        def manifest_now() -> dict:
            return _manifest(scenario, world, enabled, rendered, not_available, ctx.counts, wall)

        if after_sensors is not None:
            with atomic_path(staged.path / MANIFEST) as tmp:
                tmp.write_text(json.dumps(manifest_now(), indent=2) + "\n", encoding="utf-8")
            t0 = time.perf_counter()
            ctx.counts.update(after_sensors(staged.path))
            wall["tdm"] = time.perf_counter() - t0
        beside = _timed_into(wall, "tdm", beside_derived)
        if derived:
            _write_derived(ctx, scenario, formats, progress, beside, processes)
        elif beside is not None:
            beside(staged.path)
        wall["total"] = time.perf_counter() - started
        manifest = manifest_now()
        with atomic_path(staged.path / MANIFEST) as tmp:
            tmp.write_text(json.dumps(manifest, indent=2) + "\n", encoding="utf-8")
        staged.commit()
    return RenderResult(Path(out_dir), manifest)


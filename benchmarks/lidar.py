"""LiDAR rendering speed on scenarios/busy_open_sea.yaml, against raw Embree in the same run.

Usage::

    python benchmarks/lidar.py [--quick] [--out benchmarks/results/lidar.md]

- Multiple of real time, *marginal*: the wall time of each revolution of a run
  (cast, measure, packets, PCAP and NPZ written), median over the run, start-up
  excluded; also the mean, and the difference of whole ``render`` runs of two
  durations (which a shared VM's bursts of slowness disturb most).
- Fraction of raw Embree: the world rays of one revolution (the same rays the
  renderer casts) against one static Open3D ``RaycastingScene`` of every object at
  its pose at that instant, one ``cast_rays`` on a prebuilt tensor; the renderer's
  rays per second of wall time divided by that.
"""

from __future__ import annotations

import argparse
import datetime as dt
import json
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks.common import FrozenScene, machine_line, peak_memory_mb, publish  # noqa: E402
from raysim import render as render_module  # noqa: E402
from raysim.scenario import load_scenario, with_overrides  # noqa: E402
from groundfloor import hdl32e  # noqa: E402
from raysim.sensors.lidar import LidarRenderer  # noqa: E402
from raysim.world import World  # noqa: E402


def timed_render(scenario, duration_s: float) -> tuple[float, dict]:
    """Wall time of a full LiDAR render of ``duration_s`` into a temporary directory."""
    s = with_overrides(scenario, duration_s=duration_s, sensors=("lidar",))
    with tempfile.TemporaryDirectory() as tmp:
        start = time.perf_counter()
        result = render_module.render(s, Path(tmp) / "rec", progress=False)
        return time.perf_counter() - start, result.manifest


def steady_state(scenario, duration_s: float) -> tuple[float, float]:
    """Median and mean wall time per scenario second over the chunks (revolutions) of one run.

    Each chunk casts, measures and writes its packets and sweep, so this is the
    marginal cost with every output, free of start-up; the median resists the
    bursts of slowness of a shared virtual machine.
    """
    from raysim.materials import material_index
    from raysim.sensors.carrier import CarrierScene

    s = with_overrides(scenario, duration_s=duration_s, sensors=("lidar",))
    world = World(s)
    renderer = LidarRenderer(world, CarrierScene(world.scene_objects(), sea_material=material_index("sea")))
    with tempfile.TemporaryDirectory() as tmp:
        renderer.run(Path(tmp))
    ratio = np.array([wall / sim for sim, wall in renderer.chunk_wall_s[1:]])
    return float(np.median(ratio)), float(ratio.mean())


def raw_embree(scenario, t_s: float) -> FrozenScene:
    """Raw Open3D casting of one revolution's world rays against the frozen scene at t_s (to :meth:`FrozenScene.sample`)."""
    world = World(scenario)
    lidar = LidarRenderer(world, scene=None)
    n = int(round(hdl32e.cycles_per_revolution(lidar.cfg.rotation_hz)))
    k0 = int(t_s / hdl32e.CYCLE_DT_S)
    t = (k0 + np.arange(n)) * hdl32e.CYCLE_DT_S
    block = hdl32e.block_azimuth_centideg(t, lidar.cfg.rotation_hz)
    az = hdl32e.decoder_azimuths_centideg(block[: n // 12 * 12].reshape(-1, 12)).reshape(-1, 32)
    t = t[: az.shape[0]]
    origins, directions = lidar._sensor_rays(az)
    o_w, d_w, _ = lidar._world_rays(t, origins, directions)
    rays = np.concatenate([o_w.reshape(-1, 3), d_w.reshape(-1, 3)], axis=1).astype(np.float32)
    return FrozenScene(world.objects, rays, t_s)


#: Parts of a revolution timed by :func:`part_times`: (owner module, class or None, attribute, label).
PARTS = (
    ("raysim.sensors.lidar", "LidarRenderer", "_rays_past_own_ship",
     "world rays and the own-ship beam table, one compiled pass (poses per cycle included)"),
    ("raysim.sensors.lidar", "LidarRenderer", "_world_rays", "world rays, numpy path (sub-rays, or RAYSIM_JIT=0)"),
    ("raysim.scene.engine", "Scene", "cast", "ray engine: cast into the world (Embree and its pre-pass)"),
    ("raysim.scene.engine", "Scene", "_prepare", "ray engine: its pre-pass (origin box, near table, cells, sea)"),
    ("raysim.scene.static", "StaticPart", "merge_some", "ray engine: the static scene's cast (Embree) and merge"),
    ("raysim.sensors.lidar", "LidarRenderer", "_cast_past_own_ship", "own-ship beam table and the cast, numpy path"),
    ("raysim.sensors.lidar", "LidarRenderer", "_cycle_maps", "own-ship poses per cycle (numpy)"),
    ("raysim.sea", "FoamField", "is_foam", "foam field (raysim.sea)"),
    ("raysim.sensors.lidar", "LidarRenderer", "_world_echoes", "echo physics, foam included"),
    ("raysim.sensors.lidar", "LidarRenderer", "_returns", "returns (echo selection, noise, quantisation)"),
    ("raysim.sensors.lidar", "LidarRenderer", "_cast_stage", "cast stage, on its own thread (rays, own ship, ray engine)"),
    ("raysim.sensors.lidar", "LidarRenderer", "_echo_stage", "echo stage (echo physics and returns)"),
    ("raysim.sensors.lidar", "LidarRenderer", "packets", "data packets"),
    ("raysim.sensors.lidar", "LidarRenderer", "_write_in_order", "PCAP writing (position packets included)"),
    ("raysim.sensors.lidar_sweeps", "LidarSweeps", "add", "sweeps: points and NPZ writing"),
)


def part_times(scenario, duration_s: float) -> tuple[list[tuple[str, float]], float]:
    """Mean wall time per revolution of each of :data:`PARTS` in one render, ms, and of the whole revolution.

    The parts are wrapped with timers for the run and restored after; nested parts overlap (the ray engine
    inside the cast stage). Three threads run at once (the cast stage of one chunk, the echo stage of the
    chunk before, the writer of the one before that), so the parts add up to more than a revolution's wall time.
    """
    import functools
    import importlib

    from raysim.materials import material_index
    from raysim.sensors.carrier import CarrierScene

    spent: dict[str, float] = {label: 0.0 for *_, label in PARTS}
    saved = []
    for module, owner, name, label in PARTS:
        target = getattr(importlib.import_module(module), owner)
        original = getattr(target, name)

        def timed(*args, _original=original, _label=label, **kwargs):
            start = time.perf_counter()
            try:
                return _original(*args, **kwargs)
            finally:
                spent[_label] += time.perf_counter() - start

        saved.append((target, name, original))
        setattr(target, name, functools.wraps(original)(timed))
    try:
        s = with_overrides(scenario, duration_s=duration_s, sensors=("lidar",))
        world = World(s)
        renderer = LidarRenderer(world, CarrierScene(world.scene_objects(), sea_material=material_index("sea")))
        with tempfile.TemporaryDirectory() as tmp:
            renderer.run(Path(tmp))
    finally:
        for target, name, original in saved:
            setattr(target, name, original)
    n = len(renderer.chunk_wall_s)
    whole = sum(wall for _, wall in renderer.chunk_wall_s) / n
    return [(label, 1e3 * spent[label] / n) for *_, label in PARTS], 1e3 * whole


def variation_notes(figures: dict, previous: list[Path]) -> list[str]:
    """A notes table of this run's key figures beside those of earlier runs (their ``--json`` files)."""
    runs = [json.loads(p.read_text(encoding="utf-8")) for p in previous] + [figures]
    keys = [("multiple_of_real_time", "multiple of real time (marginal, median revolution)", "{:.2f}"),
            ("multiple_of_real_time_mean", "multiple of real time, mean revolution", "{:.2f}"),
            ("multiple_of_real_time_whole_runs", "multiple of real time, whole runs", "{:.2f}"),
            ("renderer_rays_per_s", "renderer rays/s, M", "{:.2f}"),
            ("raw_embree_rays_per_s", "raw Embree rays/s, M", "{:.2f}"),
            ("fraction_of_raw_embree", "fraction of raw Embree", "{:.3f}"),
            ("peak_memory_mb", "peak memory (short, long render), MB", "{}")]
    head = "| figure | " + " | ".join(r.get("generated", f"run {i + 1}") for i, r in enumerate(runs)) + " |"
    lines = ["Run-to-run variation (this script run twice, one run after the other; the LiDAR code the same):", "", head,
             "|---|" + "---:|" * len(runs)]
    for key, label, fmt in keys:
        cells = []
        for r in runs:
            v = r.get(key)
            v = v / 1e6 if v is not None and key.endswith("rays_per_s") else v
            cells.append("-" if v is None else fmt.format(v))
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    return lines + [""]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results" / "lidar.md")
    parser.add_argument("--json", type=Path, help="also write the figures as JSON")
    parser.add_argument("--previous", type=Path, action="append", default=[],
                        help="the --json of an earlier run, shown beside this one's figures (repeatable)")
    args = parser.parse_args(argv)
    scenario = load_scenario(ROOT / "scenarios" / "busy_open_sea.yaml")
    short, long = (1.0, 3.0) if args.quick else (2.0, 12.0)
    reps = 1 if args.quick else 3
    walls_short, walls_long, manifest = [], [], None
    frozen = raw_embree(scenario, 60.0)
    raw_repeats = 5 if args.quick else 15
    raw_times = frozen.sample(raw_repeats)  # before, between and after the renderer's timings
    for _ in range(reps):
        walls_short.append(timed_render(scenario, short)[0])
        w, manifest = timed_render(scenario, long)
        walls_long.append(w)
    marginal_two = (statistics.median(walls_long) - statistics.median(walls_short)) / (long - short)
    startup = statistics.median(walls_short) - marginal_two * short
    raw_times += frozen.sample(raw_repeats)
    marginal, mean_chunk = steady_state(scenario, long)
    raw_times += frozen.sample(raw_repeats)
    sim_rays_per_s = 1.0 / hdl32e.CYCLE_DT_S * 32 * scenario.sensors.lidar.sub_rays
    n_rays = frozen.n_rays
    raw = n_rays / statistics.median(raw_times)
    points = manifest["counts"]["lidar/points"] / long
    lidar_rays_per_s = sim_rays_per_s / marginal
    memory = {d: peak_memory_mb(d, "lidar") for d in ((2.0, 6.0) if args.quick else (10.0, 60.0))}
    rows = [
        ("simulated firings per second of scenario", f"{sim_rays_per_s:,.0f}"),
        ("points per second of scenario (busy_open_sea)", f"{points:,.0f}"),
        ("start-up, s (world, meshes, acceleration structures)", f"{startup:.2f}"),
        ("wall time per second of scenario, s: median over revolutions (marginal)", f"{marginal:.3f}"),
        ("**multiple of real time (marginal, median revolution)**", f"**{1.0 / marginal:.2f}**"),
        ("multiple of real time, mean revolution", f"{1.0 / mean_chunk:.2f}"),
        (f"multiple of real time, whole runs ({long:g} s minus {short:g} s)", f"{1.0 / marginal_two:.2f}"),
        ("renderer rays/s (marginal)", f"{lidar_rays_per_s / 1e6:.2f} M"),
        (f"raw Embree rays/s (Open3D cast_rays, same {n_rays:,} rays, frozen scene; median of {len(raw_times)} casts "
         "before, between and after the renderer's timings)", f"{raw / 1e6:.2f} M"),
        ("**fraction of raw Embree**", f"**{lidar_rays_per_s / raw:.2f}**"),
        *[(f"peak memory of a {d:g} s render, MB", f"{mb:.0f}") for d, mb in memory.items()],
    ]
    intro = [
        machine_line("lidar", args.quick),
        "",
        f"Scenario `scenarios/busy_open_sea.yaml`, HDL-32E at {scenario.sensors.lidar.rotation_hz:g} Hz, "
        f"{scenario.sensors.lidar.return_mode} return, {scenario.sensors.lidar.sub_rays} ray(s) per beam; every output "
        f"written (PCAP with position packets, NPZ sweeps, truth, navigation). Wall times are medians of {reps} runs of "
        f"{short:g} s and {long:g} s of scenario.",
    ]
    figures = {"multiple_of_real_time": 1.0 / marginal, "fraction_of_raw_embree": lidar_rays_per_s / raw,
               "renderer_rays_per_s": lidar_rays_per_s, "raw_embree_rays_per_s": raw, "points_per_s": points,
               "startup_s": startup, "wall_s_per_scenario_s": marginal, "multiple_of_real_time_mean": 1.0 / mean_chunk,
               "multiple_of_real_time_whole_runs": 1.0 / marginal_two,
               "peak_memory_mb": ", ".join(f"{mb:.0f}" for mb in memory.values()),
               "generated": f"{dt.datetime.now(dt.timezone.utc):%H:%M} UTC"}
    parts, whole_ms = part_times(scenario, 2.0 if args.quick else 4.0)
    notes = [*variation_notes(figures, args.previous),
             f"Where a revolution's time goes (one {2.0 if args.quick else 4.0:g} s render with the parts timed, "
             f"mean over revolutions; {whole_ms:.1f} ms a revolution in that run; nested parts overlap, and the cast "
             "stage, the echo stage and the writer run on three threads at once):", "",
             "| part | ms a revolution |", "|---|---:|", *[f"| {label} | {ms:.2f} |" for label, ms in parts], ""]
    publish("LiDAR rendering benchmark", intro, rows, args.out, args.json, figures, notes)
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""Ray engine against raw Embree, in one run on this machine.

Usage::

    python benchmarks/ray_engine.py [--quick] [--runs N] [--json FILE] [--out benchmarks/results/ray_engine.md]

Measures (a) a static iceberg scene (Scene.cast against raw Open3D
``cast_rays`` on a prebuilt tensor of the same rays, and raw embreex), (b) the
cost against the triangle count, (c) the cost per ray against the number of
moving ships (576 k-ray batches and one-revolution 69 k-ray batches), and the
own ship around the sensor, cast plainly and through
:class:`raysim.sensors.carrier.CarrierScene`. ``raysim bench`` loads this
script from the source tree's benchmarks/ folder like the other benchmarks.

Every ``bench_*`` function returns plain dicts (JSON-ready);
:func:`to_markdown` formats them and :func:`run` runs everything. Figures are
medians of repeated runs, and every ratio compares two measurements
interleaved in the same loop of the same run, never against a figure from
another machine or another run.

Scenes
------
- icebergs: smooth, watertight, iceberg-like meshes (icospheres with a smooth
  radial perturbation, radius about 15 m, half under water) spread 80-600 m
  around the sensor;
- ships: ellipsoidal hulls with a box superstructure, 10-80 m long, about
  1.3 k or 5.1 k triangles, spread 50-1500 m around the sensor on straight
  constant-velocity tracks (0-10 m/s);
- rays: an HDL-32E firing pattern, 32 lasers from -30.67 to +10.67 deg, the
  azimuth advancing 0.1659 deg per firing (10 Hz rotation), from 3 m above
  the sea.
"""

from __future__ import annotations

import argparse
import datetime as _dt
import json
import os
import platform
import sys
import time
from pathlib import Path
from typing import Callable

import numpy as np
import open3d as o3d
import trimesh

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from raysim.motion import ConstantVelocity, Stationary  # noqa: E402
from raysim.scene import Scene, SceneObject, pack_rays  # noqa: E402
from raysim.sensors.carrier import CarrierScene  # noqa: E402
from benchmarks.ray_engine_report import key_figures, to_markdown  # noqa: E402,F401  (re-exported)

HDL32E_ELEVATIONS_DEG = np.linspace(-30.67, 10.67, 32)
"""HDL-32E laser elevations (docs/reference.md section 2), degrees."""
HDL32E_AZIMUTH_STEP_DEG = 0.1659
"""Azimuth step per firing cycle at 10 Hz (docs/reference.md section 2), degrees."""


# ------------------------------------------------------------------ machine


def machine_info() -> dict:
    """Processor, core count and library versions of this machine."""
    cpu = "unknown"
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    from importlib.metadata import version

    return {
        "date": _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
        "nproc": os.cpu_count(),
        "cpu": cpu,
        "python": platform.python_version(),
        "numpy": np.__version__,
        "open3d": o3d.__version__,
        "embreex": version("embreex"),
        "trimesh": trimesh.__version__,
    }


# ------------------------------------------------------------------- inputs


def hdl32e_rays(n_firings: int, origin_z_m: float = 3.0, duration_s: float = 0.1) -> tuple[np.ndarray, ...]:
    """An HDL-32E-like ray batch.

    Parameters
    ----------
    n_firings : int
        Firing cycles (32 rays each); the azimuth advances 0.1659 deg per cycle.
    origin_z_m : float
        Sensor height above the sea, metres.
    duration_s : float
        The rays' times are spread evenly over ``[0, duration_s]``, seconds.

    Returns
    -------
    origins : (N, 3) float64
    directions : (N, 3) float64
    times : (N,) float64
        With ``N = 32 * n_firings``, firing-major order.
    """
    az = np.radians((np.arange(n_firings) * HDL32E_AZIMUTH_STEP_DEG) % 360.0)
    el = np.radians(HDL32E_ELEVATIONS_DEG)
    a, e = np.meshgrid(az, el, indexing="ij")
    ce = np.cos(e).ravel()
    d = np.column_stack([ce * np.cos(a).ravel(), ce * np.sin(a).ravel(), np.sin(e).ravel()])
    o = np.zeros_like(d)
    o[:, 2] = origin_z_m
    t = np.repeat(np.linspace(0.0, duration_s, n_firings), 32)
    return o, d, t


def iceberg_mesh(seed: int, radius_m: float = 15.0, subdivisions: int = 5) -> tuple[np.ndarray, np.ndarray]:
    """A smooth watertight iceberg-like mesh (icosphere with a smooth radial perturbation).

    Returns
    -------
    vertices : (V, 3) float64, metres (body frame, centred at the waterline)
    faces : (20 * 4**subdivisions, 3) int64
    """
    m = trimesh.creation.icosphere(subdivisions=subdivisions, radius=1.0)
    v = np.asarray(m.vertices)
    rng = np.random.default_rng(seed)
    k = rng.normal(0.0, 1.5, (6, 3))
    phase = rng.uniform(0.0, 2.0 * np.pi, 6)
    bumps = np.sin(v @ k.T + phase).sum(axis=1) / np.sqrt(6.0)
    return v * (radius_m * (1.0 + 0.15 * bumps))[:, None], np.asarray(m.faces)


def ship_mesh(length_m: float, subdivisions: int = 3) -> tuple[np.ndarray, np.ndarray]:
    """A ship-like mesh: ellipsoidal hull plus a box superstructure.

    Returns
    -------
    vertices : (V, 3) float64, metres (x forward, z up, waterline at 0)
    faces : (F, 3) int64, about 20 * 4**subdivisions + 12 triangles
    """
    hull = trimesh.creation.icosphere(subdivisions=subdivisions, radius=1.0)
    hull.vertices = np.asarray(hull.vertices) * [length_m / 2, length_m / 8, length_m / 12]
    house = trimesh.creation.box(extents=(length_m / 5, length_m / 6, length_m / 10))
    house.apply_translation((-length_m / 8, 0.0, length_m / 12 + length_m / 20 - 0.01))
    merged = trimesh.util.concatenate([hull, house])
    return np.asarray(merged.vertices), np.asarray(merged.faces)


def _ring_positions(rng: np.random.Generator, n: int, r_min: float, r_max: float) -> np.ndarray:
    """(n, 3) positions at random bearings and distances (uniform in area), z = 0."""
    r = np.sqrt(rng.uniform(r_min**2, r_max**2, n))
    a = rng.uniform(-np.pi, np.pi, n)
    return np.column_stack([r * np.cos(a), r * np.sin(a), np.zeros(n)])


def iceberg_objects(
    n: int,
    seed: int = 0,
    subdivisions: int = 5,
    radius_m: float = 15.0,
    min_distance_m: float = 80.0,
    max_distance_m: float = 600.0,
) -> list[SceneObject]:
    """``n`` static icebergs at random bearings, ``min_distance_m``-``max_distance_m`` from the origin."""
    rng = np.random.default_rng(seed)
    pos = _ring_positions(rng, n, min_distance_m, max_distance_m)
    out = []
    for i in range(n):
        v, f = iceberg_mesh(seed * 1000 + i, radius_m, subdivisions)
        mat = np.zeros(len(f), dtype=np.int16)
        out.append(SceneObject(i, v, f, mat, Stationary(pos[i], rng.uniform(-np.pi, np.pi))))
    return out


def ship_objects(n: int, seed: int = 0) -> list[SceneObject]:
    """``n`` ships 50-1500 m around the origin on constant-velocity tracks (0-10 m/s)."""
    rng = np.random.default_rng(seed)
    pos = _ring_positions(rng, n, 50.0, 1500.0)
    out = []
    for i in range(n):
        length = rng.uniform(10.0, 80.0)
        v, f = ship_mesh(length, subdivisions=3 if rng.uniform() < 0.5 else 4)
        heading = rng.uniform(-np.pi, np.pi)
        speed = rng.uniform(0.0, 10.0)
        motion = ConstantVelocity(pos[i], speed * np.array([np.cos(heading), np.sin(heading), 0.0]), heading)
        out.append(SceneObject(1000 + i, v, f, np.ones(len(f), dtype=np.int16), motion))
    return out


# ---------------------------------------------------------------- measuring


def _timed(fn: Callable[[], object]) -> float:
    """Wall time of one call, seconds."""
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


def _interleaved_medians(fns: dict[str, Callable[[], object]], reps: int) -> dict[str, float]:
    """Median wall time of each function, calls interleaved rep by rep (one warm-up each)."""
    for fn in fns.values():
        fn()
    times: dict[str, list[float]] = {k: [] for k in fns}
    for _ in range(reps):
        for k, fn in fns.items():
            times[k].append(_timed(fn))
    return {k: float(np.median(v)) for k, v in times.items()}


def _raw_o3d_cast(scene: Scene, origins: np.ndarray, directions: np.ndarray) -> Callable[[], object]:
    """Raw Embree through Open3D: one cast_rays of a prebuilt tensor on the scene's own static structure."""
    rays = o3d.core.Tensor.from_numpy(pack_rays(origins, directions, scene.static_offset_m))
    rc = scene.static_raycasting_scene
    return lambda: rc.cast_rays(rays)


def _raw_embreex_cast(objects: list[SceneObject], origins: np.ndarray, directions: np.ndarray) -> Callable[[], object]:
    """Raw Embree through embreex (one thread): prebuilt float32 rays against the same meshes."""
    from embreex import rtcore_scene
    from embreex.mesh_construction import TriangleMesh

    es = rtcore_scene.EmbreeScene()
    verts, faces, base = [], [], 0
    for obj in objects:
        pose = obj.motion.poses(np.zeros(1))
        verts.append(obj.vertices_m @ pose.rotation()[0].T + pose.position_m[0])
        faces.append(obj.faces + base)
        base += len(obj.vertices_m)
    TriangleMesh(es, np.vstack(verts).astype(np.float32), np.vstack(faces).astype(np.int32))
    o32 = origins.astype(np.float32)
    d32 = directions.astype(np.float32)
    return lambda: es.run(o32, d32, output=1)


def bench_static(n_firings: int = 18000, reps: int = 5, with_embreex: bool = True, dense: bool = False) -> dict:
    """(a) Static iceberg scene: Scene.cast against raw Embree on the same rays.

    Parameters
    ----------
    n_firings : int
        HDL-32E firings (32 rays each).
    reps : int
        Repetitions (median).
    with_embreex : bool
        Also time raw embreex (one thread).
    dense : bool
        Put the icebergs 25-60 m away instead of 80-600 m (most rays hit).

    Returns
    -------
    dict
        triangles, rays, hit_fraction, raw/scene (and embreex) rays/s and
        ``fraction_of_raw`` = scene rays/s / raw Open3D rays/s, also for the
        scene with culling off.
    """
    near, far = (25.0, 60.0) if dense else (80.0, 600.0)
    objects = iceberg_objects(14, seed=1, subdivisions=5, min_distance_m=near, max_distance_m=far)
    scene = Scene(objects, sea=False)
    plain = Scene(objects, sea=False, cull=False)
    o, d, t = hdl32e_rays(n_firings)
    fns = {
        "raw_o3d": _raw_o3d_cast(scene, o, d),
        "scene": lambda: scene.cast(o, d, t),
        "nocull": lambda: plain.cast(o, d, t),
    }
    med = _interleaved_medians(fns, reps)
    n = len(o)
    out = {
        "triangles": int(sum(len(x.faces) for x in objects)),
        "objects": len(objects),
        "distance_m": [near, far],
        "rays": n,
        "hit_fraction": float(np.mean(scene.cast(o, d, t).object_id >= 0)),
        "raw_o3d_rays_per_s": n / med["raw_o3d"],
        "scene_rays_per_s": n / med["scene"],
        "fraction_of_raw": med["raw_o3d"] / med["scene"],
        "scene_nocull_rays_per_s": n / med["nocull"],
        "nocull_fraction_of_raw": med["raw_o3d"] / med["nocull"],
        "reps": reps,
    }
    if with_embreex:
        emb = _raw_embreex_cast(objects, o, d)
        out["raw_embreex_rays_per_s"] = n / _interleaved_medians({"e": emb}, max(1, reps // 2))["e"]
    return out


def bench_triangles(
    targets: tuple[int, ...] = (10_000, 100_000, 1_000_000), n_firings: int = 18000, reps: int = 5
) -> list[dict]:
    """(b) Cost against scene size (static icebergs 80-600 m away, sea off).

    Icospheres come in steps of 4x triangles, so each target is reached with
    icebergs of the subdivision closest to ``target / 14`` triangles each, as
    many of them (at least 4) as bring the total nearest to the target.
    """
    o, d, t = hdl32e_rays(n_firings)
    rows = []
    for target in targets:
        sub = int(np.clip(np.round(np.log(target / 14 / 20) / np.log(4)), 1, 7))
        n_obj = max(4, int(round(target / (20 * 4**sub))))
        objects = iceberg_objects(n_obj, seed=2, subdivisions=sub)
        scene = Scene(objects, sea=False)
        med = _interleaved_medians({"raw": _raw_o3d_cast(scene, o, d), "scene": lambda: scene.cast(o, d, t)}, reps)
        rows.append(
            {
                "target_triangles": target,
                "triangles": int(sum(len(x.faces) for x in objects)),
                "objects": n_obj,
                "rays": len(o),
                "hit_fraction": float(np.mean(scene.cast(o, d, t).object_id >= 0)),
                "raw_o3d_rays_per_s": len(o) / med["raw"],
                "scene_rays_per_s": len(o) / med["scene"],
                "fraction_of_raw": med["raw"] / med["scene"],
            }
        )
    return rows


def bench_moving(
    counts: tuple[int, ...] = (1, 10, 100),
    n_firings: int = 18000,
    reps: int = 5,
    duration_s: float = 0.1,
    with_icebergs: bool = False,
) -> list[dict]:
    """(c) Cost per ray against the number of moving ships (sea on).

    The first ``k`` ships of one random fleet are used for each count ``k``, so
    the scenes are nested. With ``with_icebergs`` the 14 static icebergs of (a)
    are added to every scene.
    """
    o, d, t = hdl32e_rays(n_firings, duration_s=duration_s)
    fleet = ship_objects(max(counts), seed=3)
    bergs = iceberg_objects(14, seed=1) if with_icebergs else []
    scenes = {k: Scene(bergs + fleet[:k], sea=True) for k in counts}
    med = _interleaved_medians({k: (lambda s=s: s.cast(o, d, t)) for k, s in scenes.items()}, reps)
    base = med[counts[0]]
    rows = []
    for k in counts:
        hits = scenes[k].cast(o, d, t)
        rows.append(
            {
                "moving_objects": k,
                "static_icebergs": len(bergs),
                "triangles_moving": int(sum(len(x.faces) for x in fleet[:k])),
                "rays": len(o),
                "ship_hit_fraction": float(np.mean(hits.object_id >= 1000)),
                "rays_per_s": len(o) / med[k],
                "ns_per_ray": 1e9 * med[k] / len(o),
                "cost_per_ray_vs_first": med[k] / base,
            }
        )
    return rows


def bench_own_ship(n_firings: int = 18000, reps: int = 5, duration_s: float = 0.1) -> dict:
    """Cost of a moving object around the sensor (the ship carrying it), cast plainly and as the sensors do.

    Its swept sphere contains every ray origin, so in a plain cast every ray is a
    candidate and needs its pose: the worst case of the moving-object path.
    Compares one ship 50-1500 m away with the same scene plus a 12 m own ship
    (yawing, 5.1 k triangles) centred under the sensor, cast plainly with
    :class:`raysim.scene.Scene` and with
    :class:`raysim.sensors.carrier.CarrierScene` (the rays also in the own ship's
    body frame, as a sensor on it has them, built outside the timed loop; the own
    ship cast there without a pose, the other rays into the world); sea on.
    """
    o, d, t = hdl32e_rays(n_firings, duration_s=duration_s)
    fleet = ship_objects(1, seed=3)
    v, f = ship_mesh(12.0, subdivisions=4)
    own = SceneObject(999, v, f, np.zeros(len(f), dtype=np.int16), ConstantVelocity((0, 0, 0), (0, 0, 0), 0.0, 0.05))
    pose = own.motion.poses(t)
    rot = pose.rotation()
    o_b = np.einsum("nji,nj->ni", rot, o - pose.position_m)
    d_b = np.einsum("nji,nj->ni", rot, d)
    without, with_own = Scene(fleet, sea=True), Scene(fleet + [own], sea=True)
    carrier = CarrierScene(fleet + [own], carrier_id=999)
    fns = {
        "without": lambda: without.cast(o, d, t),
        "with": lambda: with_own.cast(o, d, t),
        "carrier": lambda: carrier.cast(o, d, t, o_b, d_b),
    }
    med = _interleaved_medians(fns, reps)
    n = len(o)
    plain, (fast, _) = with_own.cast(o, d, t), carrier.cast(o, d, t, o_b, d_b)
    return {
        "rays": n,
        "own_ship_hit_fraction": float(np.mean(plain.object_id == 999)),
        "carrier_same_ids": bool(np.array_equal(plain.object_id, fast.object_id)),
        "ns_per_ray_without": 1e9 * med["without"] / n,
        "ns_per_ray_with": 1e9 * med["with"] / n,
        "ns_per_ray_with_carrier": 1e9 * med["carrier"] / n,
    }


def run_all(quick: bool = False) -> dict:
    """All measurements in one run (``quick``: fewer rays and repetitions)."""
    n_firings = 4000 if quick else 18000
    reps = 3 if quick else 7
    return {
        "machine": machine_info(),
        "quick": quick,
        "static": bench_static(n_firings, reps),
        "dense": bench_static(n_firings, reps, with_embreex=False, dense=True),
        "triangles": bench_triangles(n_firings=n_firings, reps=reps),
        "moving": bench_moving(n_firings=n_firings, reps=reps),
        "moving_with_icebergs": bench_moving(n_firings=n_firings, reps=reps, with_icebergs=True),
        "moving_one_revolution": bench_moving(n_firings=2170, reps=max(reps, 5)),
        "own_ship": bench_own_ship(n_firings=n_firings, reps=reps),
    }


def _write_atomic(path: Path, text: str) -> None:
    """Write ``text`` to ``path`` through a temporary name and a rename."""
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(text, encoding="utf-8")
    os.replace(tmp, path)


def run(quick: bool = False, json_path: Path | None = None, out_path: Path | None = None, runs: int = 1) -> int:
    """Run every measurement, print the markdown report, write it and the JSON when asked.

    Parameters
    ----------
    quick : bool
        Fewer rays and repetitions.
    json_path : Path, optional
        Also write the raw results (of run 1, plus every run's key figures) as JSON.
    out_path : Path, optional
        Also write the markdown report there.
    runs : int
        Complete runs; with more than one, the report starts with each run's headline
        figures and their median (the noise between runs).

    Returns
    -------
    int
        0 (exit status).
    """
    results = [run_all(quick=quick) for _ in range(max(1, int(runs)))]
    res = dict(results[0])
    res["runs"] = [key_figures(r) for r in results]
    text = to_markdown(res)
    if out_path is not None:
        _write_atomic(Path(out_path), text)
    if json_path is not None:
        _write_atomic(Path(json_path), json.dumps(res, indent=2) + "\n")
    print(text)
    return 0


def main(argv: list[str] | None = None) -> int:
    """Command line: parse the arguments and :func:`run` (exit status 0)."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer rays and repetitions")
    ap.add_argument("--runs", type=int, default=3, help="complete runs (their headline figures show the noise)")
    ap.add_argument("--json", type=Path, help="also write the raw results as JSON")
    ap.add_argument("--out", type=Path, default=Path(__file__).resolve().parent / "results" / "ray_engine.md")
    args = ap.parse_args(argv)
    return run(quick=args.quick, json_path=args.json, out_path=args.out, runs=args.runs)


if __name__ == "__main__":
    raise SystemExit(main())

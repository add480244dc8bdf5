"""``raysim rcs``: the monostatic RCS of a mesh file over a turn of aspects.

Far field: the radar's wave is a plane wave (``--range-m`` is checked and reported against
the far-field distance ``2 D^2 / lambda`` but does not change sigma). ``--sea``: Fresnel
reflection of sea water times the rough-sea reduction of ``--sea-state`` (:mod:`raysim.rcs.sea`);
``--plating-rms-mm``: the plating's unfairness (default 3 mm, ship plating; 0 for a smooth body).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from raysim.errors import InputError
from raysim.rcs.engine import C_M_S, POLARISATIONS, monostatic_rcs

__all__ = ["material_gamma", "check_number", "sweep", "run"]


def material_gamma(name: str) -> float:
    """Amplitude reflection coefficient of a material: ``steel`` 1.0, else the radar table's dB."""
    from raysim.materials import MATERIALS

    if name == "steel":
        return 1.0
    table = {m.name: m.radar_reflectivity_db for m in MATERIALS}
    if name not in table:
        raise InputError("command line", "--material",
                         f"unknown material {name!r} (known: steel, {', '.join(table)})")
    return 10.0 ** (table[name] / 20.0)


def check_number(option: str, value: float, low: float, high: float) -> float:
    """``value`` if finite and in [low, high], else :class:`InputError` on the command line."""
    if not (math.isfinite(value) and low <= value <= high):
        raise InputError("command line", option, f"must be a finite number in [{low:g}, {high:g}], got {value}")
    return value


def sweep(
    vertices_m: np.ndarray, faces: np.ndarray, aspects: int, **kwargs,
) -> tuple[np.ndarray, np.ndarray]:
    """RCS at ``aspects`` evenly spaced aspects from 0 deg: aspect (N,) deg and sigma (N,) m^2."""
    aspect = np.arange(aspects) * (360.0 / aspects)
    sigma = np.array([monostatic_rcs(vertices_m, faces, float(a), **kwargs) for a in aspect])
    return aspect, sigma


def _db(x: float) -> str:
    return f"{10.0 * math.log10(x):.1f} dBsm" if x > 0 else "-inf dBsm"


def run(args) -> int:
    """Run ``raysim rcs`` for parsed arguments (see :func:`raysim.cli.build_parser`)."""
    from raysim.meshes.files import MeshError, load_mesh

    check_number("--range-m", args.range_m, 1.0, 1e6)
    check_number("--elevation-deg", args.elevation_deg, 0.0 if args.sea else -89.0, 89.0)
    check_number("--frequency-ghz", args.frequency_ghz, 0.1, 300.0)
    check_number("--aspects", args.aspects, 1, 36000)
    sea_state = check_number("--sea-state", args.sea_state, 0, 6)
    if sea_state != int(sea_state):
        raise InputError("command line", "--sea-state", f"must be an integer 0..6, got {sea_state:g}")
    plating_rms_m = check_number("--plating-rms-mm", args.plating_rms_mm, 0.0, 100.0) * 1e-3
    if args.ray_spacing_m is not None:
        check_number("--ray-spacing-m", args.ray_spacing_m, 1e-4, 10.0)
    if args.polarisation not in POLARISATIONS:
        raise InputError("command line", "--polarisation",
                         f"unknown polarisation {args.polarisation!r} (known: {', '.join(POLARISATIONS)})")
    gamma = material_gamma(args.material)
    try:
        mesh = load_mesh(args.mesh)
    except MeshError as exc:
        raise InputError(exc.path, "mesh", exc.message) from None
    frequency = args.frequency_ghz * 1e9
    aspect, sigma = sweep(mesh.vertices_m, mesh.faces, args.aspects, elevation_deg=args.elevation_deg,
                          frequency_hz=frequency, polarisation=args.polarisation, gamma=gamma, sea=args.sea,
                          n_bounces=args.bounces, spacing_m=args.ray_spacing_m, sea_state=int(sea_state),
                          plating_rms_m=plating_rms_m)
    size = float(np.linalg.norm(mesh.vertices_m.max(axis=0) - mesh.vertices_m.min(axis=0)))
    far = 2.0 * size**2 / (C_M_S / frequency)
    result = {"aspect_deg": aspect.tolist(), "rcs_m2": sigma.tolist(), "median_m2": float(np.median(sigma)),
              "min_m2": float(sigma.min()), "max_m2": float(sigma.max())}
    where = f"over the sea (sea state {int(sea_state)})" if args.sea else "free space"
    print(f"{args.mesh}: {args.aspects} aspects, elevation {args.elevation_deg:g} deg, "
          f"{args.frequency_ghz:g} GHz {args.polarisation}, {args.material}, plating rms "
          f"{args.plating_rms_mm:g} mm, {where}")
    print(f"far field (plane wave); range {args.range_m:g} m, far-field distance 2 D^2 / lambda = {far:.0f} m")
    if args.sea:
        print("sea: Fresnel reflection of sea water (Klein and Swift 1977) times the Ament roughness reduction "
              "at the grazing angle (docs/radar.md)")
    for key in ("median", "min", "max"):
        value = result[f"{key}_m2"]
        print(f"{key:>6}: {value:.4g} m^2  {_db(value)}")
    if args.json is not None:
        Path(args.json).write_text(json.dumps(result) + "\n", encoding="utf-8")
    return 0

"""Fixed and floating structures: a navigation buoy and a concrete pier."""

from __future__ import annotations

import numpy as np

from raysim.materials import material_index
from raysim.meshes.body import BodyMesh
from raysim.meshes.parts import assemble, box, require_positive

__all__ = ["buoy", "pier"]


def _revolve_mesh(
    profile_rz_m: np.ndarray, segment_material: list[str], n_around: int, name: str
) -> BodyMesh:
    """Closed surface of revolution about the z axis as one watertight :class:`BodyMesh`.

    Parameters
    ----------
    profile_rz_m : (K, 2) float64
        (radius, z) from the bottom pole (radius 0) to the top pole (radius 0), m; the
        K - 2 interior points must have radius > 0.
    segment_material : list of str
        Material of each of the K - 1 profile segments (bottom cap first).
    n_around : int
        Number of sectors around the axis.
    name : str
        Mesh name.
    """
    rings_rz = profile_rz_m[1:-1]
    n_rings = rings_rz.shape[0]
    theta = np.linspace(0.0, 2.0 * np.pi, n_around, endpoint=False)
    ring_xyz = np.stack(
        [
            rings_rz[:, :1] * np.cos(theta)[None, :],
            rings_rz[:, :1] * np.sin(theta)[None, :],
            np.repeat(rings_rz[:, 1:2], n_around, axis=1),
        ],
        axis=-1,
    ).reshape(-1, 3)
    bottom, top = 0, 1 + n_rings * n_around
    vertices = np.concatenate(
        [[[0.0, 0.0, profile_rz_m[0, 1]]], ring_xyz, [[0.0, 0.0, profile_rz_m[-1, 1]]]]
    )
    j = np.arange(n_around)
    j_next = (j + 1) % n_around
    first, last = 1, 1 + (n_rings - 1) * n_around
    faces = [np.column_stack([np.full(n_around, bottom), first + j_next, first + j])]
    for k in range(n_rings - 1):  # loop over profile segments, not vertices
        a, b = 1 + k * n_around + j, 1 + k * n_around + j_next
        c, d = b + n_around, a + n_around
        faces.append(np.concatenate([np.column_stack([a, b, c]), np.column_stack([a, c, d])]))
    faces.append(np.column_stack([last + j, last + j_next, np.full(n_around, top)]))
    materials = [
        np.full(f.shape[0], material_index(m), dtype=np.int16)
        for f, m in zip(faces, segment_material, strict=True)
    ]
    return BodyMesh(vertices, np.concatenate(faces), np.concatenate(materials), name)


# Buoy profile (radius m, z m) from the bottom pole to the top pole and segment materials:
# a 1 m diameter can buoy, 1 m below water, a retro-reflective band from 1.0 to 1.4 m and a
# conical top to 2.5 m (shape after IALA can/spar buoys; dimensions unverified).
_BUOY_PROFILE_RZ_M = np.array(
    [
        [0.0, -1.0],
        [0.30, -1.0],
        [0.50, -0.6],
        [0.50, 1.0],
        [0.50, 1.4],
        [0.50, 1.5],
        [0.12, 2.3],
        [0.12, 2.5],
        [0.0, 2.5],
    ]
)
_BUOY_SEGMENT_MATERIALS = [
    "steel_painted",  # bottom cap
    "steel_painted",  # bilge
    "steel_painted",  # body
    "retroreflector",  # band, z 1.0-1.4 m
    "steel_painted",  # shoulder
    "steel_painted",  # cone
    "steel_painted",  # top mark stem
    "steel_painted",  # top cap
]


def buoy(n_around: int = 24) -> BodyMesh:
    """Navigation buoy: 1 m diameter, 2.5 m above and 1 m below water, retro-reflective band.

    A closed surface of revolution (steel body and conical top) with a band of material
    ``retroreflector`` from z = 1.0 m to 1.4 m.

    Parameters
    ----------
    n_around : int, optional
        Sectors around the axis (24 gives 336 triangles).

    Returns
    -------
    BodyMesh
        One watertight component; ``name`` ``"buoy"``.
    """
    if n_around < 3:
        raise ValueError(f"n_around must be >= 3, got {n_around}")
    return _revolve_mesh(_BUOY_PROFILE_RZ_M, _BUOY_SEGMENT_MATERIALS, int(n_around), "buoy")


# Pier piles: spacing along the pier, square side, and depth of their foot (m, unverified).
_PIER_PILE_SPACING_M = 6.0
_PIER_PILE_SIDE_M = 0.5
_PIER_PILE_FOOT_Z_M = -3.0


def _pier_station(
    x: float, side: float, half_w: float, deck_height_m: float, slab_m: float, fenders: bool
) -> list[tuple[np.ndarray, np.ndarray, str]]:
    """Pile (and fender) boxes at station ``x`` on one side (``side`` = +1 port, -1 starboard)."""
    half_pile = 0.5 * _PIER_PILE_SIDE_M
    y = side * (half_w - 0.5)
    pile = box(
        (x - half_pile, y - half_pile, _PIER_PILE_FOOT_Z_M),
        (x + half_pile, y + half_pile, deck_height_m - 0.5 * slab_m),
    )
    parts = [(*pile, "concrete")]
    if fenders:
        inner, outer = side * (half_w - 0.05), side * (half_w + 0.3)
        fender = box(
            (x - 0.2, min(inner, outer), min(0.3, 0.5 * deck_height_m)),
            (x + 0.2, max(inner, outer), deck_height_m),
        )
        parts.append((*fender, "rubber"))
    return parts


def pier(
    length_m: float = 60.0,
    width_m: float = 8.0,
    deck_height_m: float = 2.0,
    fenders: bool = True,
) -> BodyMesh:
    """Concrete pier: a deck slab on square piles, with rubber fenders along both sides.

    The origin is at the centre of the landward end; the pier extends along +x to
    ``length_m``. Deck: top at ``deck_height_m``, thickness ``min(0.6, deck_height_m / 2)`` m.
    Piles: 0.5 m square, every 6 m (at least two rows), 0.5 m in from each side, from 3 m
    below water into the deck. Fenders: 0.3 m thick, 0.4 m wide rubber blocks on the outer
    side faces at each pile station, from 0.3 m above water to the deck top.

    Parameters
    ----------
    length_m, width_m, deck_height_m : float, optional
        Pier length along x, width along y, deck top above the waterline, m.
    fenders : bool, optional
        Add the rubber fenders.

    Returns
    -------
    BodyMesh
        Closed boxes; deck and piles ``concrete``, fenders ``rubber``; ``name`` ``"pier"``.
    """
    require_positive(length_m=length_m, width_m=width_m, deck_height_m=deck_height_m)
    half_w = 0.5 * width_m
    slab_m = min(0.6, 0.5 * deck_height_m)
    deck = box((0.0, -half_w, deck_height_m - slab_m), (length_m, half_w, deck_height_m))
    parts = [(*deck, "concrete")]
    n_stations = max(2, int(round(length_m / _PIER_PILE_SPACING_M)))
    station_x = (np.arange(n_stations) + 0.5) * (length_m / n_stations)
    for x in station_x:  # loop over pile stations (objects), not vertices
        for side in (-1.0, 1.0):
            parts.extend(_pier_station(x, side, half_w, deck_height_m, slab_m, fenders))
    return assemble(parts, name="pier")

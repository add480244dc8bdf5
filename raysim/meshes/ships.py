"""Generated ships (hull, superstructure, mast) and the own ship; default dimensions from length.

Default dimensions are rules of thumb chosen to look plausible on sensors (unverified,
documented on each function); scenarios can override length, beam and height.
"""

from __future__ import annotations

import numpy as np
import trimesh

from raysim.meshes.body import BodyMesh
from raysim.meshes.parts import assemble, box, require_positive

__all__ = [
    "OWN_SHIP_MAX_HEIGHT_M",
    "default_beam_m",
    "default_freeboard_m",
    "default_draft_m",
    "ship_hull",
    "own_ship",
]

#: Nothing of :func:`own_ship` rises above this height (m above the waterline), so that
#: sensors mounted at z >= 3 m are outside the own-ship mesh.
OWN_SHIP_MAX_HEIGHT_M = 2.5

# Smallest ship length (m) built in steel; shorter craft are GRP (rule of thumb, unverified).
STEEL_HULL_MIN_LENGTH_M = 15.0


def default_beam_m(length_m: float) -> float:
    """Default beam of a generated ship, m: ``L / (3.2 + 0.03 L)`` (rule of thumb, unverified).

    10.9 m -> 3.1 m, 30 m -> 7.3 m, 100 m -> 16.1 m.
    """
    return float(length_m) / (3.2 + 0.03 * float(length_m))


def default_freeboard_m(length_m: float) -> float:
    """Default hull depth above the waterline (deck height), m: ``0.08 L + 1.0`` (unverified)."""
    return 0.08 * float(length_m) + 1.0


def default_draft_m(length_m: float) -> float:
    """Default draft (keel depth below the waterline), m: ``0.04 L + 0.4`` (unverified)."""
    return 0.04 * float(length_m) + 0.4


def _superstructure_height_m(length_m: float) -> float:
    """Default superstructure height above the deck, m: ``0.10 L + 1.2`` (unverified)."""
    return 0.10 * length_m + 1.2


def _mast_height_m(length_m: float) -> float:
    """Default mast height above the superstructure top, m: ``0.10 L + 0.5`` (unverified).

    With the defaults a 100 m ship's mast top is at 9.0 + 11.2 + 10.5 = 30.7 m above water.
    """
    return 0.10 * length_m + 0.5


def _deck_half_beam(s: np.ndarray) -> np.ndarray:
    """Deck half-beam as a fraction of beam/2 at stations s in [0, 1] (stern to bow).

    0.85 at the transom, full from s = 0.15 to 0.6, then a parabolic taper to a point at
    the bow. The outline is convex, so a convex hull keeps it.
    """
    stern = 0.85 + 0.15 * np.clip(s / 0.15, 0.0, 1.0)
    taper = 1.0 - np.clip((s - 0.6) / 0.4, 0.0, 1.0) ** 2
    return stern * taper


def _hull(length_m: float, beam_m: float, freeboard_m: float, draft_m: float):
    """Closed convex hull of a ship: ((V, 3) vertices, (F, 3) faces).

    Deck outline at z = freeboard from x = -L/2 (transom) to x = +L/2 (bow point), the
    waterline outline at z = 0 spans x in [-0.46 L, 0.46 L] (raked bow and overhanging
    transom, so the waterline footprint is centred on the origin), the keel at z = -draft
    spans x in [-0.40 L, 0.30 L] with a narrow flat bottom, and a forefoot rounds the stem.
    """
    half_l, half_b = 0.5 * length_m, 0.5 * beam_m
    s = np.linspace(0.0, 1.0, 17)
    deck = _outline(-half_l + length_m * s, half_b * _deck_half_beam(s), freeboard_m)
    waterline_x = -0.46 * length_m + 0.92 * length_m * s
    waterline = _outline(waterline_x, 0.95 * half_b * _deck_half_beam(s), 0.0)
    keel_x = np.array([-0.40, -0.1, 0.30]) * length_m
    keel = _outline(keel_x, np.full(3, 0.12 * half_b), -draft_m)
    transom_bottom = _outline(
        np.array([-0.45 * length_m]), np.array([0.5 * half_b]), -0.5 * draft_m
    )
    forefoot = np.array([[0.42 * length_m, 0.0, -0.35 * draft_m]])
    points = np.concatenate([deck, waterline, keel, transom_bottom, forefoot])
    hull = trimesh.convex.convex_hull(points)
    return np.asarray(hull.vertices, dtype=np.float64), np.asarray(hull.faces, dtype=np.int64)


def _outline(x: np.ndarray, half_beam: np.ndarray, z: float) -> np.ndarray:
    """(2N, 3) points at (x, +-half_beam, z); points with zero half-beam appear twice."""
    port = np.column_stack([x, half_beam, np.full_like(x, z)])
    starboard = port * np.array([1.0, -1.0, 1.0])
    return np.concatenate([port, starboard])


def ship_hull(
    length_m: float,
    beam_m: float | None = None,
    height_m: float | None = None,
    mast: bool = True,
) -> BodyMesh:
    """Generated ship of a given length: hull, superstructure and (optionally) a mast.

    Dimensions (rules of thumb, unverified):

    - beam ``default_beam_m(L) = L / (3.2 + 0.03 L)`` unless given;
    - hull: convex hull with a pointed, raked bow and a transom stern; deck (freeboard)
      ``0.08 L + 1.0`` m above water, draft ``0.04 L + 0.4`` m;
    - superstructure of two tiers (deckhouse 0.8 B wide, bridge 0.95 B wide on top), total
      height ``0.10 L + 1.2`` m above the deck; aft of midships (centre near x = -0.2 L) for
      L >= 15 m, slightly forward of midships (a wheelhouse) for smaller craft;
    - mast: a thin square box (side ``0.005 L + 0.1`` m) on the bridge, ``0.10 L + 0.5`` m
      tall (100 m ship: mast top 30.7 m above water).

    If ``height_m`` is given, the superstructure and mast heights are scaled so that the
    highest point is at ``height_m`` (the freeboard is reduced to ``height_m / 2`` if it
    would otherwise exceed that).

    Parameters
    ----------
    length_m : float
        Length overall, m (the hull spans x in [-L/2, L/2]).
    beam_m : float, optional
        Beam, m; default ``default_beam_m(length_m)``.
    height_m : float, optional
        Overall height above the waterline, m; default from the rules above.
    mast : bool, optional
        Add the mast (material ``aluminium``).

    Returns
    -------
    BodyMesh
        Separate closed components: hull, deckhouse, bridge[, mast]. Hull and superstructure
        are ``steel_painted`` for L >= 15 m, ``grp`` for smaller craft.
    """
    beam_m = default_beam_m(length_m) if beam_m is None else beam_m
    require_positive(length_m=length_m, beam_m=beam_m, height_m=height_m)
    freeboard_m = default_freeboard_m(length_m)
    super_m = _superstructure_height_m(length_m)
    mast_m = _mast_height_m(length_m) if mast else 0.0
    if height_m is not None:
        freeboard_m = min(freeboard_m, 0.5 * height_m)
        scale = (height_m - freeboard_m) / (super_m + mast_m)
        super_m, mast_m = super_m * scale, mast_m * scale
    body = "steel_painted" if length_m >= STEEL_HULL_MIN_LENGTH_M else "grp"
    hull_v, hull_f = _hull(length_m, beam_m, freeboard_m, default_draft_m(length_m))
    parts = [(hull_v, hull_f, body)]
    centre_x = -0.2 * length_m if length_m >= STEEL_HULL_MIN_LENGTH_M else 0.05 * length_m
    parts += _superstructure(length_m, beam_m, centre_x, freeboard_m, super_m, body)
    if mast:
        parts.append(_mast(length_m, centre_x, freeboard_m + super_m, mast_m))
    return assemble(parts, name="ship")


def _superstructure(
    length_m: float, beam_m: float, centre_x: float, deck_z: float, height_m: float, material: str
) -> list[tuple[np.ndarray, np.ndarray, str]]:
    """Deckhouse (0.20 L long, 0.8 B wide, 60 % of height) and bridge (0.12 L, 0.95 B) boxes.

    Both boxes reach below the level they stand on (into the hull or the deckhouse) so that
    no coplanar faces meet and no gap is visible.
    """
    house_top = deck_z + 0.6 * height_m
    house = box(
        (centre_x - 0.10 * length_m, -0.40 * beam_m, 0.5 * deck_z),
        (centre_x + 0.10 * length_m, 0.40 * beam_m, house_top),
    )
    bridge = box(
        (centre_x - 0.06 * length_m, -0.475 * beam_m, house_top - 0.2 * height_m),
        (centre_x + 0.06 * length_m, 0.475 * beam_m, deck_z + height_m),
    )
    return [(*house, material), (*bridge, material)]


def _mast(
    length_m: float, centre_x: float, base_z: float, height_m: float
) -> tuple[np.ndarray, np.ndarray, str]:
    """Thin square aluminium box from 0.25 m (or a quarter of its height) below ``base_z``."""
    half_w = 0.5 * (0.005 * length_m + 0.1)
    embed = min(0.25, 0.25 * height_m)
    vertices, faces = box(
        (centre_x - half_w, -half_w, base_z - embed), (centre_x + half_w, half_w, base_z + height_m)
    )
    return vertices, faces, "aluminium"


def own_ship(length_m: float, beam_m: float) -> BodyMesh:
    """Own ship: a small GRP workboat hull with a low wheelhouse, nothing above 2.5 m.

    The hull is the :func:`ship_hull` hull with freeboard ``clip(0.1 L, 0.4, 1.2)`` m and
    draft ``0.04 L + 0.4`` m; a wheelhouse box (0.3 L long, 0.7 B wide, x in
    [-0.15 L, 0.15 L]) reaches 2.4 m above water. There is no mast: everything stays below
    :data:`OWN_SHIP_MAX_HEIGHT_M` = 2.5 m, so sensors mounted at z >= 3 m are outside the
    mesh (the real sensor mast is not modelled). Low LiDAR beams do see the deck and
    wheelhouse roof, as on the real boat.

    Parameters
    ----------
    length_m : float
        Length overall, m (Odin: 10.9).
    beam_m : float
        Beam, m (Odin: 3.5).

    Returns
    -------
    BodyMesh
        Two closed components (hull, wheelhouse), all ``grp``; ``name`` ``"own_ship"``.
    """
    require_positive(length_m=length_m, beam_m=beam_m)
    freeboard_m = float(np.clip(0.1 * length_m, 0.4, 1.2))
    wheelhouse_top_m = OWN_SHIP_MAX_HEIGHT_M - 0.1
    hull_v, hull_f = _hull(length_m, beam_m, freeboard_m, default_draft_m(length_m))
    house = box(
        (-0.15 * length_m, -0.35 * beam_m, 0.5 * freeboard_m),
        (0.15 * length_m, 0.35 * beam_m, wheelhouse_top_m),
    )
    return assemble([(hull_v, hull_f, "grp"), (*house, "grp")], name="own_ship")

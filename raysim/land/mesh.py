"""Land polygons as closed triangle meshes in the local frame.

:func:`land_mesh` turns a polygon in local east/north metres into a watertight mesh: vertical
faces at the shoreline from a little below the sea (``base_z_m``, so a ray at the waterline hits
land and not a gap) up to the top height, a flat top, and a flat bottom at ``base_z_m`` that
closes the solid (it is under the sea; no ray reaches it). With a ``slope_deg`` the faces above
the sea slope: the top is the polygon inset by ``height / tan(slope)`` (a negative shapely buffer
with mitre joins), joined to the shoreline at sea level by a band of triangles that each span both
(see :func:`_slope_band`).
Only the outline's vertices (and the inset's) are used, never interior points, so the triangle
count is proportional to the outline's vertex count. Faces are wound counter-clockwise seen from
outside (outward normals). :func:`to_local` converts lon/lat polygons to the local frame.
"""

from __future__ import annotations

import math

import numpy as np
import shapely
from scipy.spatial import cKDTree
from shapely.geometry import MultiPolygon, Point, Polygon
from shapely.geometry.polygon import orient
from shapely.validation import explain_validity
from trimesh.creation import triangulate_polygon

from groundfloor.frames import LocalFrame

__all__ = ["DEFAULT_BASE_Z_M", "LAND_MATERIALS", "INSET_FRACTION", "land_mesh", "to_local"]

#: Materials land may be made of (names in :mod:`raysim.materials`).
LAND_MATERIALS: tuple[str, ...] = ("rock", "vegetation", "sand", "concrete")
#: Bottom of the shoreline faces, m (below the sea surface, so waves and rays at the waterline meet land).
DEFAULT_BASE_Z_M = -2.0
#: Where a sloped island's inset vanishes (narrower than twice height / tan(slope)), the top is the inset
#: by this fraction of the largest inscribed circle's radius, and the height is lowered to match the slope.
INSET_FRACTION = 0.9


def to_local(polygon_lonlat: Polygon, frame: LocalFrame) -> Polygon:
    """A lon/lat polygon in local east/north metres.

    Parameters
    ----------
    polygon_lonlat : shapely.geometry.Polygon
        x = longitude, y = latitude, degrees (WGS84), holes allowed.
    frame : groundfloor.frames.LocalFrame
        The scene's local frame.

    Returns
    -------
    shapely.geometry.Polygon
        x east, y north in metres; the shoreline counter-clockwise, holes clockwise.
    """

    def ring(coords) -> np.ndarray:
        lonlat = np.asarray(coords, dtype=np.float64)[:, :2]
        x_m, y_m = frame.to_local(lonlat[:, 1], lonlat[:, 0])
        return np.column_stack([x_m, y_m])

    local = Polygon(ring(polygon_lonlat.exterior.coords), [ring(r.coords) for r in polygon_lonlat.interiors])
    return orient(local, 1.0)


def _parts(geometry) -> list[Polygon]:
    """The non-empty polygons of a Polygon, MultiPolygon or GeometryCollection."""
    if geometry.is_empty:
        return []
    if isinstance(geometry, Polygon):
        return [geometry]
    return [g for g in getattr(geometry, "geoms", []) if isinstance(g, Polygon) and not g.is_empty]


def _triangles_2d(polygon: Polygon) -> np.ndarray:
    """(T, 3, 2) counter-clockwise triangles of a polygon by earcut (its own vertices only)."""
    vertices, faces = triangulate_polygon(polygon, engine="earcut")
    if len(faces) == 0:
        return np.zeros((0, 3, 2))
    triangles = np.asarray(vertices, dtype=np.float64)[np.asarray(faces)][:, :, :2]
    edge_1 = triangles[:, 1] - triangles[:, 0]
    edge_2 = triangles[:, 2] - triangles[:, 0]
    clockwise = edge_1[:, 0] * edge_2[:, 1] - edge_1[:, 1] * edge_2[:, 0] < 0.0
    triangles[clockwise] = triangles[clockwise][:, ::-1]
    return triangles


def _flat(triangles_2d: np.ndarray, z_m: float, up: bool) -> np.ndarray:
    """(T, 3, 3) horizontal triangles at ``z_m``, facing up or (reversed) down."""
    z = np.full(triangles_2d.shape[:2] + (1,), z_m)
    triangles = np.concatenate([triangles_2d, z], axis=2)
    return triangles if up else triangles[:, ::-1]


def _walls(polygon: Polygon, bottom_z_m: float, top_z_m: float) -> np.ndarray:
    """(2E, 3, 3) vertical faces on every ring of a polygon (shoreline CCW, holes CW), facing outward."""
    walls = []
    for ring in [polygon.exterior, *polygon.interiors]:
        xy = np.asarray(ring.coords, dtype=np.float64)[:, :2]
        a, b = xy[:-1], xy[1:]
        low_a, low_b = (np.column_stack([xy, np.full(len(xy), bottom_z_m)]) for xy in (a, b))
        up_a, up_b = (np.column_stack([xy, np.full(len(xy), top_z_m)]) for xy in (a, b))
        # interior on the left of travel: (a_low, b_low, b_up) has normal (b - a) x z, to the right (outward)
        walls.append(np.stack([low_a, low_b, up_b], axis=1))
        walls.append(np.stack([low_a, up_b, up_a], axis=1))
    return np.concatenate(walls) if walls else np.zeros((0, 3, 3))


def _inset(polygon: Polygon, height_m: float, slope_deg: float) -> tuple[list[Polygon], float, float]:
    """The top of a sloped polygon: (inset polygons, inset distance m, top height m)."""
    distance_m = height_m / math.tan(math.radians(slope_deg))
    inset = _parts(polygon.buffer(-distance_m, join_style="mitre", mitre_limit=5.0))
    if not inset:  # narrower than the slope allows: a small plateau at a lower height
        radius_m = shapely.maximum_inscribed_circle(polygon).length
        distance_m = INSET_FRACTION * radius_m
        height_m = distance_m * math.tan(math.radians(slope_deg))
        inset = _parts(polygon.buffer(-distance_m, join_style="mitre", mitre_limit=5.0))
    return [orient(p, 1.0) for p in inset], distance_m, height_m


def _ring_positions(ring_xy: np.ndarray, points_xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Arc-length positions (0..1) along a closed ring of its own vertices and of points' nearest places.

    A point's place is its projection on the two edges at its nearest ring vertex (a k-d tree, so
    O((n + m) log m) where shapely's line_locate_point is O(n m)).
    """
    closed = np.vstack([ring_xy, ring_xy[:1]])
    edges = np.diff(closed, axis=0)
    lengths = np.hypot(edges[:, 0], edges[:, 1])
    start = np.concatenate([[0.0], np.cumsum(lengths)])
    total = start[-1]
    nearest = cKDTree(ring_xy).query(points_xy)[1]
    best_t, best_d = start[nearest], np.sum((points_xy - ring_xy[nearest]) ** 2, axis=1)
    for edge in (nearest, (nearest - 1) % len(ring_xy)):
        dot = np.sum((points_xy - closed[edge]) * edges[edge], axis=1)
        along = np.clip(dot / np.maximum(lengths[edge] ** 2, 1e-300), 0.0, 1.0)
        foot = closed[edge] + along[:, None] * edges[edge]
        d = np.sum((points_xy - foot) ** 2, axis=1)
        better = d < best_d
        best_t = np.where(better, start[edge] + along * lengths[edge], best_t)
        best_d = np.minimum(d, best_d)
    return start[:-1] / total, np.mod(best_t / total, 1.0)


def _stitch(outer: np.ndarray, inner: np.ndarray) -> np.ndarray:
    """(n + m, 3, 3) triangles joining two closed rings of n and m (x, y, z) points, same direction.

    Both rings are walked once, in step by a position along the inner ring: an inner vertex's is its
    arc length, an outer vertex's that of its nearest point on the inner ring (kept non-decreasing, so a
    bay or a spit fans to one inner vertex). Each triangle takes the next vertex with the lower
    position; every triangle spans both rings, so the band slopes everywhere.
    """
    n, m = len(outer), len(inner)
    t_inner, t_outer = _ring_positions(inner[:, :2], outer[:, :2])
    step = np.mod(np.diff(t_outer) + 0.5, 1.0) - 0.5  # signed shortest step along the closed ring
    s_outer = np.clip(np.maximum.accumulate(np.concatenate([[0.0], np.cumsum(step)])), 0.0, 1.0)
    t_rel = np.mod(t_inner - t_outer[0], 1.0)
    j0 = int(np.argmin(t_rel))
    inner, t_rel = np.roll(inner, -j0, axis=0), np.roll(t_rel, -j0)
    s_next = np.append(s_outer[1:], 1.0)  # position of outer vertex i + 1 (the last one closes the ring)
    t_next = np.append(t_rel[1:], 1.0)
    triangles, i, j = [], 0, 0
    while i < n or j < m:
        o, o_next, p, p_next = outer[i % n], outer[(i + 1) % n], inner[j % m], inner[(j + 1) % m]
        if j == m or (i < n and s_next[i] <= t_next[j]):
            triangles.append((o, o_next, p))
            i += 1
        else:
            triangles.append((o, p_next, p))
            j += 1
    return np.asarray(triangles, dtype=np.float64)


def _ring_xyz(ring, z_m: float, ccw: bool) -> np.ndarray:
    """(n, 3) points of a closed ring (without the repeated last one) at ``z_m``, in the given direction."""
    xy = np.asarray(ring.coords, dtype=np.float64)[:-1, :2]
    if ring.is_ccw != ccw:
        xy = xy[::-1]
    return np.column_stack([xy, np.full(len(xy), z_m)])


def _slope_band(polygon: Polygon, inset: list[Polygon], top_z_m: float) -> np.ndarray:
    """(T, 3, 3) triangles of the band between the shoreline (z = 0) and the inset (z = top).

    A band part between one shoreline ring and one inset ring (an island's shore, a lake's) is
    stitched ring to ring (:func:`_stitch`). Other parts (where the inset splits or loses a lobe) are
    triangulated by earcut on their boundary vertices; a vertex nearer the inset's boundary than the
    shoreline is at the top, the others at sea level, so a triangle joining three shoreline vertices
    (across a spit the inset left out) stays at sea level.
    """
    union = MultiPolygon(inset) if len(inset) > 1 else inset[0]
    shore, top = polygon.boundary, union.boundary
    parts, loose = [], []
    for part in _parts(polygon.difference(union)):
        rings = [part.exterior, *part.interiors]
        if len(rings) == 2:
            outer_on_top = shapely.distance(Point(rings[0].coords[0]), top) < shapely.distance(
                Point(rings[0].coords[0]), shore)
            z_outer, z_inner = (top_z_m, 0.0) if outer_on_top else (0.0, top_z_m)
            parts.append(_stitch(_ring_xyz(rings[0], z_outer, True), _ring_xyz(rings[1], z_inner, True)))
        else:
            loose.append(_triangles_2d(orient(part, 1.0)))
    if loose:
        triangles_2d = np.concatenate(loose)
        points = shapely.points(triangles_2d.reshape(-1, 2))
        on_top = shapely.distance(points, top) < shapely.distance(points, shore)
        parts.append(np.concatenate([triangles_2d, np.where(on_top, top_z_m, 0.0).reshape(-1, 3, 1)], axis=2))
    return np.concatenate(parts) if parts else np.zeros((0, 3, 3))


def _indexed(triangles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Shared vertices (V, 3) and faces (F, 3) of (T, 3, 3) triangles, exact duplicates merged."""
    points = triangles.reshape(-1, 3)
    order = np.lexsort((points[:, 2], points[:, 1], points[:, 0]))
    ordered = points[order]
    first = np.concatenate([[True], np.any(ordered[1:] != ordered[:-1], axis=1)])
    inverse = np.empty(len(points), dtype=np.int64)
    inverse[order] = np.cumsum(first) - 1
    faces = inverse.reshape(-1, 3)
    keep = (faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2]) & (faces[:, 0] != faces[:, 2])
    return ordered[first].astype(np.float64), faces[keep]


def land_mesh(
    polygon_enu: Polygon,
    height_m: float,
    slope_deg: float | None = None,
    base_z_m: float = DEFAULT_BASE_Z_M,
) -> tuple[np.ndarray, np.ndarray]:
    """A closed mesh of one land polygon.

    Parameters
    ----------
    polygon_enu : shapely.geometry.Polygon
        Valid polygon in local metres (x east, y north), holes allowed (any orientation).
    height_m : float
        Top height above the sea, m (>= 0).
    slope_deg : float or None, optional
        Slope of the faces above the sea, degrees in (0, 90]; None or 90 for vertical faces.
        Where the inset ``height / tan(slope)`` leaves nothing, the top is the inset by
        :data:`INSET_FRACTION` of the largest inscribed circle's radius and lower (that distance
        times tan(slope)). A spit or peninsula narrower than twice the inset fans up to the nearest
        part of the top where the band between shore and top is one ring; where the inset splits the
        island in two or more, such parts may stay at sea level (:func:`_slope_band`).
    base_z_m : float, optional
        Bottom of the shoreline faces and of the solid, m (< 0 and < ``height_m``).

    Returns
    -------
    vertices : numpy.ndarray
        (V, 3) float64, local metres, z up from the sea surface.
    faces : numpy.ndarray
        (F, 3) int64, counter-clockwise seen from outside.

    Raises
    ------
    ValueError
        Empty or invalid polygon, non-finite or negative height, slope outside (0, 90], base not below.
    """
    if polygon_enu.is_empty or not polygon_enu.is_valid:
        raise ValueError(f"land polygon must be valid and non-empty: {explain_validity(polygon_enu)}")
    if not (math.isfinite(height_m) and height_m >= 0.0):
        raise ValueError(f"height must be finite and >= 0 m, got {height_m}")
    if not (math.isfinite(base_z_m) and base_z_m < min(0.0, height_m)):
        raise ValueError(f"base must be below the sea and the top, got {base_z_m} m")
    if slope_deg is not None and not (math.isfinite(slope_deg) and 0.0 < slope_deg <= 90.0):
        raise ValueError(f"slope must be in (0, 90] deg, got {slope_deg}")
    polygon = orient(shapely.remove_repeated_points(polygon_enu), 1.0)
    footprint = _triangles_2d(polygon)
    bottom = _flat(footprint, base_z_m, up=False)
    if slope_deg is None or slope_deg >= 90.0 or height_m == 0.0:
        parts = [_walls(polygon, base_z_m, height_m), _flat(footprint, height_m, up=True), bottom]
    else:
        inset, _, top_z_m = _inset(polygon, height_m, slope_deg)
        tops = [_flat(_triangles_2d(p), top_z_m, up=True) for p in inset]
        parts = [_walls(polygon, base_z_m, 0.0), _slope_band(polygon, inset, top_z_m), *tops, bottom]
    return _indexed(np.concatenate(parts))

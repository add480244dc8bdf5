"""Direction cells and analytic ray tests: the sea plane, spheres, boxes.

The cheap geometry that decides which rays go to Embree at all: a 16-bit
*direction cell* per ray (:data:`AZ_BINS` bins of a monotonic pseudo-azimuth,
no trigonometry, times :data:`EL_BINS` bins of the direction's z component),
the cells through which rays from a box of origins can reach a sphere
(:func:`sphere_cells`), exact ray/sphere and ray/box tests on (ray, object)
pairs, and the analytic sea plane ``z = 0`` (:func:`intersect_sea`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

AZ_BINS = 1024
"""Pseudo-azimuth bins of the direction cells (about 0.35 deg each)."""
EL_BINS = 64
"""Bins of the direction's z component (about 1.8 deg each near the horizon)."""
CELLS = AZ_BINS * EL_BINS  # fits uint16
"""Number of direction cells."""
CELL_PAD_RAD = 1e-5
"""Angular padding of a sphere's cells: covers float32 round-off of the rays' cells, radians."""
SPHERE_PAD_M = 0.01
"""Safety margin added to bounding spheres (float32 round-off), metres."""


def intersect_sea(oz_m: np.ndarray, dz: np.ndarray, max_range_m: float | np.ndarray | None = None) -> np.ndarray:
    """Range along each ray to the flat sea surface ``z = 0``.

    Parameters
    ----------
    oz_m : (N,) float64
        Ray origin heights above mean sea level, metres.
    dz : (N,) float
        Vertical components of the unit ray directions.
    max_range_m : float, (N,) float or None
        Ranges beyond this count as no hit (``inf``), metres (compared in float64);
        None: no limit.

    Returns
    -------
    (N,) float64
        Range to the plane, metres; ``inf`` where the ray runs parallel to it or
        away from it (or meets it beyond ``max_range_m``).
    """
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.divide(oz_m, dz, dtype=np.float64)
        np.negative(t, out=t)
        keep = t >= 0.0  # also drops nan (0 / 0)
    if max_range_m is not None:
        keep &= t <= max_range_m
    return np.where(keep, t, np.inf)


def pseudo_azimuth(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Monotonic stand-in for ``atan2(y, x)`` (the "diamond angle").

    Parameters
    ----------
    x, y : (N,) float
        Horizontal components of the directions.

    Returns
    -------
    (N,) float (dtype of the inputs)
        Values in [-2, 2], increasing with ``atan2(y, x)`` over (-pi, pi); 0
        where ``x = y = 0``.
    """
    s = np.abs(x)
    s += np.abs(y)
    s += np.asarray(1e-30, dtype=s.dtype)  # no 0 / 0; negligible otherwise
    p = np.divide(y, s)
    back = np.copysign(np.asarray(2.0, dtype=p.dtype), y)
    back -= p
    np.copyto(p, back, where=x < 0)
    return p


_AZ_SCALE = AZ_BINS / 4.0 * (1.0 - 2.0**-20)  # pseudo-azimuth + 2 in [0, 4] -> [0, AZ_BINS)
_EL_SCALE = EL_BINS / 2.0 * (1.0 - 2.0**-20)  # dz + 1 in [0, 2] -> [0, EL_BINS)


def direction_cells(dx: np.ndarray, dy: np.ndarray, dz: np.ndarray) -> np.ndarray:
    """Direction cell of each ray: pseudo-azimuth bin * EL_BINS + z bin.

    Parameters
    ----------
    dx, dy, dz : (N,) float32 (or float64)
        Unit direction components.

    Returns
    -------
    (N,) uint16
        Cell index in [0, AZ_BINS * EL_BINS).
    """
    a = pseudo_azimuth(dx, dy)
    a += 2.0
    a *= _AZ_SCALE
    cell = a.astype(np.uint16)
    cell *= EL_BINS
    e = dz + 1.0
    e *= _EL_SCALE
    np.clip(e, 0.0, EL_BINS - 0.5, out=e)
    cell += e.astype(np.uint16)
    return cell


def _az_bins(angle_rad: np.ndarray) -> np.ndarray:
    """Pseudo-azimuth bins of azimuth angles (float64 version of :func:`direction_cells`).

    The rays' cells use float32: callers pad the angles by :data:`CELL_PAD_RAD`.
    """
    p = pseudo_azimuth(np.cos(angle_rad), np.sin(angle_rad))
    return np.clip(np.floor((p + 2.0) * _AZ_SCALE), 0, AZ_BINS - 1).astype(np.int64)


def _el_bins(dz: np.ndarray) -> np.ndarray:
    """z-component bins of directions (clamped to the valid range)."""
    return np.clip(np.floor((dz + 1.0) * _EL_SCALE), 0, EL_BINS - 1).astype(np.int64)


@dataclass(frozen=True)
class SphereCells:
    """Direction cells K spheres may be seen in from a box of origins.

    Conservative: any ray from an origin of the box that meets sphere ``k`` has
    its direction in azimuth bins ``a0[k]..a1[k]`` (wrapping at +-pi when
    ``a0 > a1``) and z bins ``e0[k]..e1[k]``, and meets it no nearer than
    ``near_m[k]``.
    """

    near_m: np.ndarray  # (K,) float64, metres
    a0: np.ndarray  # (K,) int64
    a1: np.ndarray  # (K,) int64
    e0: np.ndarray  # (K,) int64
    e1: np.ndarray  # (K,) int64

    def runs(self, keep: np.ndarray) -> tuple[np.ndarray, ...]:
        """Non-wrapping azimuth runs of the spheres ``keep`` (ascending).

        Returns
        -------
        label, lo, hi, e0, e1 : (R,) int64
            Sphere index, inclusive azimuth-bin run and z-bin range, grouped by
            label in ascending order.
        """
        wrap = self.a0[keep] > self.a1[keep]
        label = np.concatenate([keep, keep[wrap]])
        lo = np.concatenate([self.a0[keep], np.zeros(int(wrap.sum()), dtype=np.int64)])
        hi = np.concatenate([np.where(wrap, AZ_BINS - 1, self.a1[keep]), self.a1[keep][wrap]])
        order = np.argsort(label, kind="stable")
        label, lo, hi = label[order], lo[order], hi[order]
        return label, lo, hi, self.e0[label], self.e1[label]


def _sphere_distances(centres: np.ndarray, radii: np.ndarray, origin_centre: np.ndarray,
                      spread: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Offsets (K, 3), distances (K,) and grown radii (K,) of K spheres from the origin box, metres."""
    rs = radii + spread  # Minkowski sum with the origin box's bounding sphere
    v = np.asarray(centres, dtype=np.float64).reshape(-1, 3) - origin_centre
    dist = np.sqrt(np.einsum("ij,ij->i", v, v))
    return v, dist, rs


def sphere_near_m(centres: np.ndarray, radii: np.ndarray, origin_centre: np.ndarray, spread: float) -> np.ndarray:
    """(K,) float64: :attr:`SphereCells.near_m` of :func:`sphere_cells` alone (the same values), metres.

    The nearest distance at which a ray from the origin box can meet each sphere, without the
    cells: enough to see that no sphere is within a range limit.
    """
    _, dist, rs = _sphere_distances(centres, radii, origin_centre, spread)
    return np.maximum(dist - rs, 0.0)


def sphere_cells(
    centres: np.ndarray, radii: np.ndarray, origin_centre: np.ndarray, spread: float
) -> SphereCells:
    """The cells through which rays from the origin box can reach each of K spheres.

    Parameters
    ----------
    centres : (K, 3) float64
        Sphere centres, metres.
    radii : (K,) float64
        Sphere radii, metres.
    origin_centre : (3,) float64
        Centre ``m`` of the origins' bounding box, metres.
    spread : float
        Half-diagonal ``s`` of that box, metres.

    Returns
    -------
    SphereCells
    """
    v, dist, rs = _sphere_distances(centres, radii, origin_centre, spread)
    h = np.hypot(v[:, 0], v[:, 1])
    pad = CELL_PAD_RAD
    with np.errstate(divide="ignore", invalid="ignore"):
        alpha = np.arcsin(np.clip(rs / dist, 0.0, 1.0))
        half = np.arcsin(np.clip(rs / h, 0.0, 1.0)) + pad
    el = np.arctan2(v[:, 2], h)
    e0 = _el_bins(np.sin(np.clip(el - alpha - pad, -np.pi / 2, np.pi / 2)) - pad)
    e1 = _el_bins(np.sin(np.clip(el + alpha + pad, -np.pi / 2, np.pi / 2)) + pad)
    az = np.arctan2(v[:, 1], v[:, 0])
    a0, a1 = _az_bins(az - half), _az_bins(az + half)
    inside = dist <= rs  # an origin may be inside: every direction
    all_az = inside | (h <= rs)  # the vertical through m meets the sphere: every azimuth
    a0[all_az], a1[all_az] = 0, AZ_BINS - 1
    e0[inside], e1[inside] = 0, EL_BINS - 1
    return SphereCells(np.maximum(dist - rs, 0.0), a0, a1, e0, e1)


def gather_columns(a: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """(3, P) float64: rows ``rows`` of a C-contiguous (N, 3) float64 array, as columns."""
    out = np.empty((3, rows.size))
    r3 = rows * 3
    flat = a.reshape(-1)
    for axis in range(3):
        np.take(flat[axis:], r3, out=out[axis], mode="clip")  # in range; "clip" avoids a buffer
    return out


def pairs_reach_spheres(
    o: np.ndarray, d: np.ndarray, centres: np.ndarray, radii: np.ndarray, best: np.ndarray
) -> np.ndarray:
    """Which rays enter their sphere ahead of their origin and before their current best.

    Parameters
    ----------
    o, d : (3, P) float64
        Origin (metres) and unit direction of each pair's ray.
    centres : (3, P) float64
        Sphere centre of each pair, metres.
    radii : (P,) float64
        Sphere radius of each pair, metres.
    best : (P,) float64
        Current best range of each pair's ray, metres.

    Returns
    -------
    (P,) bool
    """
    w = np.empty(radii.size)
    dw = np.empty(radii.size)
    b = np.zeros(radii.size)
    c = radii * radii
    np.negative(c, out=c)  # accumulates |w|^2 - r^2
    for axis in range(3):
        np.subtract(centres[axis], o[axis], out=w)
        np.multiply(d[axis], w, out=dw)
        b += dw
        w *= w
        c += w
    disc = b * b
    disc -= c
    ok = disc >= 0
    np.sqrt(disc, out=disc, where=ok)
    ok &= (b + disc) >= 0  # exit point ahead of the origin
    ok &= (b - disc) < best  # entry point before the current best hit
    return ok


def pairs_hit_boxes(o: np.ndarray, d: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Which body-frame rays meet their body's axis-aligned bounding box (slab test).

    Parameters
    ----------
    o, d : (3, P) float64
        Body-frame origins (metres) and unit directions.
    lo, hi : (3, P) float64
        Box corners of each pair's body, metres.

    Returns
    -------
    (P,) bool
        False only where the ray surely misses the box (a cheap filter before Embree).
    """
    near = np.zeros(o.shape[1])
    far = np.full(o.shape[1], np.inf)
    with np.errstate(divide="ignore", invalid="ignore"):
        for axis in range(3):
            inv = 1.0 / d[axis]
            t1 = (lo[axis] - o[axis]) * inv
            t2 = (hi[axis] - o[axis]) * inv
            np.fmax(near, np.fmin(t1, t2), out=near)  # fmax/fmin ignore nan (o on a slab plane, d = 0)
            np.fmin(far, np.fmax(t1, t2), out=far)
    return near <= far


def bounding_sphere(points: np.ndarray) -> tuple[np.ndarray, float]:
    """A (not minimal) bounding sphere of (V, 3) points: bbox centre, max distance."""
    centre = (points.min(axis=0) + points.max(axis=0)) / 2
    radius = float(np.sqrt(((points - centre) ** 2).sum(axis=1).max())) if len(points) else 0.0
    return centre, radius + SPHERE_PAD_M + 1e-6 * (radius + float(np.abs(centre).max()))


def origin_box(origins: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per-axis min and max of (N, 3) origins (blockwise: avoids slow (N, 3) axis-0 reductions)."""
    k = 256
    n = origins.shape[0] // k * k
    parts_lo, parts_hi = [], []
    if n:
        block = origins[:n].reshape(-1, 3 * k)
        parts_lo.append(block.min(axis=0).reshape(k, 3).min(axis=0))
        parts_hi.append(block.max(axis=0).reshape(k, 3).max(axis=0))
    if n < origins.shape[0]:
        parts_lo.append(origins[n:].min(axis=0))
        parts_hi.append(origins[n:].max(axis=0))
    return np.min(parts_lo, axis=0), np.max(parts_hi, axis=0)


def face_against(normal: np.ndarray, rows: np.ndarray, dirs: np.ndarray) -> None:
    """Flip normals (in place) that point along their rays.

    Parameters
    ----------
    normal : (M, 3) float32
        Normals, modified in place.
    rows : (K,) int
        Rows of ``normal`` to check.
    dirs : (K, 3) float
        The ray direction of each checked row.
    """
    if rows.size == 0:
        return
    r3 = rows * 3
    flat = normal.reshape(-1)
    dot = np.take(flat, r3) * dirs[:, 0]
    dot += np.take(flat[1:], r3) * dirs[:, 1]
    dot += np.take(flat[2:], r3) * dirs[:, 2]
    flip = rows[dot > 0]
    if flip.size:
        normal[flip] *= -1.0

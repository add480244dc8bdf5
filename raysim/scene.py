"""The ray engine: first hit of each ray, each ray at its own time.

Embree (through Open3D's :class:`open3d.t.geometry.RaycastingScene`) does the
triangle work; this module decides which rays go to which acceleration
structure and turns Embree's answers into :class:`Hits`.

Acceleration structures
-----------------------
Static objects (motion :class:`raysim.motion.Stationary`)
    Transformed once to world coordinates and put together in ONE
    ``RaycastingScene`` built in ``__init__``, in coordinates relative to
    ``static_offset_m`` (the mean of the static objects' positions snapped to
    a 1024 m grid, so zero for a scene centred near the world origin) so that
    float32 keeps sub-millimetre precision at kilometre-scale coordinates; ray
    origins are shifted by the same offset, in float64, before casting.
Moving objects
    All moving objects share ONE ``RaycastingScene``, the *atlas*, built once in
    ``__init__`` and never rebuilt: each object's body-frame mesh (its own copy,
    even where objects share a mesh) sits in its own cell of a square grid in
    the x-z plane, the cells ``2 r_max + 10 m`` apart (``r_max``: the largest
    bounding radius of a body about its origin), so the cells' spheres are
    disjoint and coordinates stay within a few kilometres (float32 keeps
    sub-millimetre precision). For a batch, candidate (ray, object) pairs are
    culled (below), each object's pose is evaluated at each candidate ray's own
    time, the rays are moved into the body frame (``o' = R^T (o - p)``,
    ``d' = R^T d``, float64), their origins are moved forward to the entry of
    the body's bounding sphere (``t_entry = max(0, entry)``) and shifted into
    the body's cell, and ALL objects' rays are cast in ONE call. A hit counts
    only if its geometry is the ray's own object: a ray that misses its object
    may go on into other cells, but since it starts at its own sphere and the
    spheres are disjoint, any hit on its own object comes first. The range is
    ``t_entry + t_hit`` in float64; normals are rotated back to the world frame;
    hits nearer than the current best replace it. The grid is a vertical plane
    because sensors see bodies along near-horizontal rays, which then leave the
    plane instead of crossing other cells (Embree time).
Poses
    A :class:`_PoseBank` packs the motions of known kinds (exactly
    :class:`~raysim.motion.ConstantVelocity`, :class:`~raysim.motion.SampledTrack`,
    :class:`~raysim.motion.ShipMotion` of a ``SampledTrack`` with or without
    :class:`~raysim.motion.WaveMotion`) into parameter tables once, and evaluates
    the poses of all pairs of a kind in one vectorised pass, with the motions'
    own arithmetic (the same numbers); other motions are asked object by
    object. Objects with neither pitch nor roll take a yaw-only rotation.
The carrier (optional, per batch)
    A sensor on the own ship knows its rays in the ship's body frame. Passed as
    ``Scene.cast(..., carrier=Carrier(object_id, origins_body_m,
    directions_body[, rotation]))``, these rays are cast as they are, with one
    extra Open3D call on a scene holding only the carrier's body-frame mesh
    (built on first use): no pose, no culling, no transform for that object
    (whose sphere holds every ray origin, so it would otherwise make every ray
    a candidate). Normals of carrier hits are rotated to the world frame with
    ``rotation`` if given, else with the carrier's pose at those hits' times.
    The carrier is cast before the other moving objects, so rays stopped by
    the own deck drop out of their culling.
The sea
    The flat analytic plane ``z = 0`` (:func:`intersect_sea`).

Culling
-------
Each batch first gets a cheap pre-pass over its rays (numpy, chunked and
split over threads): the bounding box of the origins (centre ``m``,
half-diagonal ``s``), the range to the sea, and a 16-bit *direction cell* per
ray: :data:`AZ_BINS` bins of a monotonic pseudo-azimuth
(:func:`pseudo_azimuth`, no trigonometry) times :data:`EL_BINS` bins of the
direction's z component.

Every object is bounded by a sphere. For a moving object it is a swept sphere
over the batch's time span ``[tmin, tmax]``: the span is cut into k equal parts
(k = 1 for short spans), the pose is sampled at their middles, and the
bounding sphere of those positions is grown by the mesh's radius about its
origin (rotation-proof) and by ``max_speed_mps * span / (2 k)`` (within its
part, the body origin stays that close to the part's middle sample).
Enlarged by ``s`` (a Minkowski sum), the sphere's cone seen from ``m``
contains the direction of every ray of the batch that can reach the sphere;
the cells it overlaps (angles padded by 1e-5 rad against float32 round-off)
and the nearest distance at which the sphere can be met are what the culling
uses.

- Static scene: a table cell -> nearest static sphere distance; a ray is cast
  against the static scene only if that distance is below its sea range and
  ``max_range_m``. When a subsample shows that most rays would be cast anyway
  (a sensor surrounded by geometry), the table is skipped and all rays are
  cast.
- Moving objects: the rays that can still get a hit beyond the nearest moving
  sphere are counting-sorted by cell once per batch (a stable argsort of
  uint16 is a radix sort). For all objects at once (vectorised over
  (ray, object) pairs): the rays of each object's cells (contiguous runs of
  the sorted order; two runs when the azimuth interval wraps at +-pi), minus
  those whose current best hit (sea, static scene, carrier, ``max_range_m``)
  is nearer than the sphere can be, minus those failing an exact ray/sphere
  test (on origins and directions gathered once, as columns). An object seen
  in every direction (its sphere holds the origins: the own ship when no
  carrier is given) takes all rays that can still get a hit, in ray order.
  The survivors get their poses (the pose bank; one pose per run of pairs
  sharing an instant when that halves the work), are moved into the body
  frame, pass a slab test against the body's bounding box, and go to the
  atlas in one Open3D call; the nearest hit per ray wins. Swept spheres are
  computed for all objects in one pass too. The cost per ray thus grows with
  the number of (ray, object) pairs, i.e. with the objects the rays can
  actually reach. No Python loop runs over the objects (except over those
  seen in every direction and those with motions of unknown kinds); what is
  left per object and batch is a few table entries of vectorised work.

Per-ray numpy work is kept to a few contiguous passes; hit bookkeeping
touches hits only. Open3D holds the GIL while casting, so numpy work cannot
overlap with Embree; instead large batches split their numpy work over a
small thread pool (numpy releases the GIL in its loops).
"""

from __future__ import annotations

import hashlib
import os
import threading
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import Callable, Sequence

import numpy as np
import open3d as o3d

from raysim.motion import ConstantVelocity, Motion, SampledTrack, ShipMotion, Stationary, WaveMotion
from raysim.pose import rotation_matrices

SEA_ID = -2
"""Object id reported for hits on the sea surface."""
NO_HIT = -1
"""Object id reported for rays that hit nothing (within range)."""

AZ_BINS = 1024
"""Pseudo-azimuth bins of the direction cells (about 0.35 deg each)."""
EL_BINS = 64
"""Bins of the direction's z component (about 1.8 deg each near the horizon)."""
_CELLS = AZ_BINS * EL_BINS  # fits uint16

_CHUNK = 65536
"""Rays per chunk of the per-ray numpy passes (keeps temporaries in cache)."""
_PARALLEL_MIN_RAYS = 262144
"""Batches at least this large split their per-ray numpy work over threads."""
_STATIC_CULL_MAX_FRACTION = 0.5
"""Cast all rays at the static scene when more than this fraction are candidates."""
_SUBSAMPLE_RAYS = 2048
"""Rays sampled to estimate the static candidate fraction."""
_CELL_PAD_RAD = 1e-5
"""Angular padding of a sphere's cells: covers float32 round-off of the rays' cells, radians."""
_SPHERE_PAD_M = 0.01
"""Safety margin added to bounding spheres (float32 round-off), metres."""
_MAX_POSE_SAMPLES = 16
"""Maximum number of pose samples per object for its swept sphere."""
_SWEEP_MARGIN_M = 1.0
"""Target motion margin of a swept sphere (more pose samples for long, fast sweeps), metres."""
_OFFSET_GRID_M = 1024.0
"""The static scene's offset is snapped to this grid, metres."""


@dataclass(frozen=True)
class SceneObject:
    """One rigid object of the scene.

    Attributes
    ----------
    object_id : int
        Truth id, >= 0.
    vertices_m : (V, 3) float64
        Vertices in the body frame (x forward, y left, z up, z = 0 at the
        waterline), metres.
    faces : (F, 3) int
        Triangle vertex indices.
    face_material : (F,) int16
        Material index of each face.
    motion : Motion
        Pose over time; :class:`raysim.motion.Stationary` for fixed objects
        (those go into the static acceleration structure).
    """

    object_id: int
    vertices_m: np.ndarray
    faces: np.ndarray
    face_material: np.ndarray
    motion: Motion

    @property
    def is_static(self) -> bool:
        """True if the object never moves (Stationary motion, zero speed)."""
        return isinstance(self.motion, Stationary) and float(self.motion.max_speed_mps) == 0.0


@dataclass
class Hits:
    """First hit of each of N rays.

    Attributes
    ----------
    range_m : (N,) float64
        Distance along the unit direction to the first hit, metres; ``inf`` if
        none.
    object_id : (N,) int32
        Truth id of the object hit, :data:`SEA_ID`, or :data:`NO_HIT`.
    normal : (N, 3) float32
        Unit surface normal in the world frame, facing against the ray
        (``n . d <= 0``); zeros if no hit.
    material : (N,) int16
        Material index of the face hit (the scene's ``sea_material`` for the
        sea); -1 if no hit.
    primitive : (N,) int32
        Triangle index within the object's mesh; -1 for the sea or no hit.
    """

    range_m: np.ndarray
    object_id: np.ndarray
    normal: np.ndarray
    material: np.ndarray
    primitive: np.ndarray

    @classmethod
    def empty(cls, n: int) -> "Hits":
        """Hits of ``n`` rays that hit nothing."""
        return cls(
            np.full(n, np.inf),
            np.full(n, NO_HIT, dtype=np.int32),
            np.zeros((n, 3), dtype=np.float32),
            np.full(n, -1, dtype=np.int16),
            np.full(n, -1, dtype=np.int32),
        )

    @property
    def hit(self) -> np.ndarray:
        """(N,) bool, True where the ray hit something (object or sea)."""
        return self.object_id != NO_HIT


@dataclass(frozen=True)
class Carrier:
    """The rays of a :meth:`Scene.cast` batch in the body frame of the object carrying the sensor.

    A sensor on the own ship knows its rays in the ship's body frame (the mount
    is fixed) and builds the world rays from them with the ship's pose at each
    ray's time; passed along, they let the engine cast the carrier without any
    pose evaluation or culling (see the module docstring).

    Attributes
    ----------
    object_id : int
        Truth id of the carrying object; must be a moving object of the scene
        (otherwise the carrier is ignored and the batch is cast as usual).
    origins_body_m : (N, 3) float64
        The batch's ray origins in the carrier's body frame at each ray's time, metres.
    directions_body : (N, 3) float
        The batch's unit ray directions in that frame.
    rotation : (N, 3, 3) float64 or None
        Body-to-world rotation of the carrier at each ray's time, used only to turn
        the normals of carrier hits into the world frame; if None, the engine
        evaluates the carrier's pose at the times of those hits.
    """

    object_id: int
    origins_body_m: np.ndarray
    directions_body: np.ndarray
    rotation: np.ndarray | None = None


# ------------------------------------------------------------ ray geometry


def intersect_sea(oz_m: np.ndarray, dz: np.ndarray) -> np.ndarray:
    """Range along each ray to the flat sea surface ``z = 0``.

    Parameters
    ----------
    oz_m : (N,) float64
        Ray origin heights above mean sea level, metres.
    dz : (N,) float
        Vertical components of the unit ray directions.

    Returns
    -------
    (N,) float64
        Range to the plane, metres; ``inf`` where the ray runs parallel to it or
        away from it.
    """
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.divide(oz_m, dz, dtype=np.float64)
    np.negative(t, out=t)
    t[~(t >= 0.0)] = np.inf  # also catches nan (0 / 0)
    return t


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

    The rays' cells use float32: callers pad the angles by :data:`_CELL_PAD_RAD`.
    """
    p = pseudo_azimuth(np.cos(angle_rad), np.sin(angle_rad))
    return np.clip(np.floor((p + 2.0) * _AZ_SCALE), 0, AZ_BINS - 1).astype(np.int64)


def _el_bins(dz: np.ndarray) -> np.ndarray:
    """z-component bins of directions (clamped to the valid range)."""
    return np.clip(np.floor((dz + 1.0) * _EL_SCALE), 0, EL_BINS - 1).astype(np.int64)


@dataclass(frozen=True)
class _SphereCells:
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


def _sphere_cells(
    centres: np.ndarray, radii: np.ndarray, origin_centre: np.ndarray, spread: float
) -> _SphereCells:
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
    _SphereCells
    """
    rs = radii + spread  # Minkowski sum with the origin box's bounding sphere
    v = np.asarray(centres, dtype=np.float64).reshape(-1, 3) - origin_centre
    dist = np.sqrt(np.einsum("ij,ij->i", v, v))
    h = np.hypot(v[:, 0], v[:, 1])
    pad = _CELL_PAD_RAD
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
    return _SphereCells(np.maximum(dist - rs, 0.0), a0, a1, e0, e1)


def _gather_columns(a: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """(3, P) float64: rows ``rows`` of a C-contiguous (N, 3) float64 array, as columns."""
    out = np.empty((3, rows.size))
    r3 = rows * 3
    flat = a.reshape(-1)
    for axis in range(3):
        np.take(flat[axis:], r3, out=out[axis], mode="clip")  # in range; "clip" avoids a buffer
    return out


def _pairs_reach_spheres(
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


def _pairs_hit_boxes(o: np.ndarray, d: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
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


_KIND_CONSTANT_VELOCITY, _KIND_TRACK, _KIND_OTHER = 0, 1, 2


class _PoseBank:
    """Poses of many moving objects, evaluated together for (object, time) pairs.

    Motions of the known kinds (exactly :class:`raysim.motion.ConstantVelocity`,
    :class:`raysim.motion.SampledTrack`, or :class:`raysim.motion.ShipMotion` of a
    ``SampledTrack`` with or without :class:`raysim.motion.WaveMotion`) are packed
    into parameter tables at construction and evaluated for all their pairs in
    one vectorised pass per kind, with the same arithmetic as their own
    ``poses`` (the same numbers). Any other motion is asked object by object.

    Parameters
    ----------
    motions : sequence of Motion
        One per moving object (label = index).
    """

    def __init__(self, motions: Sequence[Motion]) -> None:
        k = len(motions)
        self.motions = list(motions)
        self.kind = np.full(k, _KIND_OTHER, dtype=np.int8)
        self.planar = np.zeros(k, dtype=bool)  # pitch and roll are always zero
        self.cv_position = np.zeros((3, k))
        self.cv_velocity = np.zeros((3, k))
        self.cv_yaw = np.zeros(k)
        self.cv_yaw_rate = np.zeros(k)
        self.tr_base = np.zeros(k, dtype=np.int64)  # first sample of each track in tr_samples
        self.tr_last = np.zeros(k)  # n - 1
        self.tr_imax = np.zeros(k, dtype=np.int64)  # max(n - 2, 0)
        self.tr_dt = np.ones(k)
        self.has_waves = np.zeros(k, dtype=bool)
        self.waves = np.zeros((9, k))  # amplitude, angular frequency, phase of roll, pitch, heave
        samples, base = [], 0
        for i, m in enumerate(motions):
            if type(m) is ConstantVelocity:
                self.kind[i] = _KIND_CONSTANT_VELOCITY
                self.planar[i] = True
                self.cv_position[:, i] = m.position_m
                self.cv_velocity[:, i] = m.velocity
                self.cv_yaw[i], self.cv_yaw_rate[i] = m.yaw_rad, m.yaw_rate
                continue
            track, waves = None, None
            if type(m) is SampledTrack:
                track = m
            elif type(m) is ShipMotion and type(m.track) is SampledTrack and (m.waves is None or type(m.waves) is WaveMotion):
                track, waves = m.track, m.waves
            if track is None:
                continue
            n = track.x.shape[0]
            block = np.stack([track.x, track.y, track.z, track.yaw, track.pitch, track.roll])
            samples.append(np.concatenate([block, block[:, -1:]], axis=1))  # a pad sample: index i + 1 stays valid
            self.kind[i] = _KIND_TRACK
            self.tr_base[i], self.tr_last[i], self.tr_imax[i], self.tr_dt[i] = base, n - 1, max(n - 2, 0), track.dt_s
            base += n + 1
            if waves is not None:
                self.has_waves[i] = True
                self.waves[:, i] = [*waves.roll, waves.phases[0], *waves.pitch, waves.phases[1], *waves.heave, waves.phases[2]]
            self.planar[i] = waves is None and not track.pitch.any() and not track.roll.any()
        self.tr_samples = np.concatenate(samples, axis=1) if samples else np.zeros((6, 0))
        self.single_kind = k > 0 and bool(np.all(self.kind == self.kind[0]))
        self.all_planar = bool(self.planar.all())

    def poses(self, label: np.ndarray | int, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray | None, np.ndarray | None]:
        """Poses of objects ``label`` at times ``t`` (one per pair).

        Parameters
        ----------
        label : (P,) int, or int
            Object (index into ``motions``) of each pair, or one object for all.
        t : (P,) float64
            Time of each pair, seconds.

        Returns
        -------
        position : (3, P) float64
            Body origin in the world frame, metres (x, y, z rows).
        yaw : (P,) float64
        pitch, roll : (P,) float64, or None where all of them are zero (planar motions only)
            FLU Euler angles, radians.
        """
        p = t.size
        one = np.ndim(label) == 0
        if one:
            k = int(label)
            planar = bool(self.planar[k])
            kinds = [int(self.kind[k])]
        else:
            planar = self.all_planar or bool(np.take(self.planar, label).all())
            kinds = [int(self.kind[0])] if self.single_kind else np.unique(np.take(self.kind, label)).tolist()
        position = np.empty((3, p))
        yaw = np.empty(p)
        pitch = None if planar else np.zeros(p)
        roll = None if planar else np.zeros(p)
        for kind in kinds:
            idx = None if len(kinds) == 1 else np.flatnonzero(np.take(self.kind, label) == kind)
            lab = np.full(1, k) if one else (label if idx is None else label[idx])  # one: broadcast
            tt = t if idx is None else t[idx]
            sel = slice(None) if idx is None else idx
            if kind == _KIND_CONSTANT_VELOCITY:  # ConstantVelocity.poses
                vel = np.take(self.cv_velocity, lab, axis=1) * tt
                vel += np.take(self.cv_position, lab, axis=1)  # p0 + t v
                position[:, sel] = vel
                yaw[sel] = np.take(self.cv_yaw, lab) + np.take(self.cv_yaw_rate, lab) * tt
            elif kind == _KIND_TRACK:  # SampledTrack.poses (+ ShipMotion's waves)
                u = np.clip(tt / np.take(self.tr_dt, lab), 0.0, np.take(self.tr_last, lab))
                i = np.minimum(u.astype(np.int64), np.take(self.tr_imax, lab))
                f = u - i
                i += np.take(self.tr_base, lab)
                a = np.take(self.tr_samples, i, axis=1)
                v = np.take(self.tr_samples, i + 1, axis=1)
                v -= a
                v *= f
                v += a  # a + (b - a) * f
                if one:
                    w = slice(None) if self.has_waves[k] else None
                    wp = self.waves[:, k : k + 1]
                else:
                    w = np.flatnonzero(np.take(self.has_waves, lab))
                    w = w if w.size else None
                    wp = None if w is None else np.take(self.waves, lab[w], axis=1)
                if w is not None:
                    tw = tt[w]
                    v[5, w] = v[5, w] + wp[0] * np.sin(wp[1] * tw + wp[2])  # roll
                    v[4, w] = v[4, w] + -(wp[3] * np.sin(wp[4] * tw + wp[5]))  # pitch (marine sign flipped)
                    v[2, w] += wp[6] * np.sin(wp[7] * tw + wp[8])  # heave
                position[:, sel] = v[:3]
                yaw[sel] = v[3]
                if pitch is not None:
                    pitch[sel], roll[sel] = v[4], v[5]
            else:
                groups = [(k, np.arange(p))] if one else [(m, np.flatnonzero(lab == m)) for m in np.unique(lab).tolist()]
                for m, j in groups:
                    pose = self.motions[m].poses(tt[j])
                    rows = j if idx is None else idx[j]
                    position[:, rows] = pose.position_m.T
                    yaw[rows] = pose.yaw_rad
                    if pitch is not None:
                        pitch[rows], roll[rows] = pose.pitch_rad, pose.roll_rad
        return position, yaw, pitch, roll


def _swept_spheres(
    bank: _PoseBank, speeds: np.ndarray, mesh_radii: np.ndarray, tmin: float, tmax: float
) -> tuple[np.ndarray, np.ndarray]:
    """Bounding spheres of K moving bodies over ``[tmin, tmax]`` (all bodies at once).

    Each span is cut into k equal parts (more for fast bodies and long spans, at
    most :data:`_MAX_POSE_SAMPLES`) and the pose is sampled at their middles:
    within a part the body origin stays within ``speed * span / (2 k)`` of its
    middle sample.

    Parameters
    ----------
    bank : _PoseBank
        The bodies' motions.
    speeds : (K,) float64
        ``max_speed_mps`` of each body.
    mesh_radii : (K,) float64
        Largest distance of a vertex from each body origin, metres.
    tmin, tmax : float
        Time span, seconds.

    Returns
    -------
    centres : (K, 3) float64
        World positions of the spheres' centres, metres.
    radii : (K,) float64
        Radii, metres: each covers its mesh at every instant of the span.
    """
    span = max(tmax - tmin, 0.0)
    k = np.clip(np.ceil(speeds * span / (2.0 * _SWEEP_MARGIN_M)), 1, _MAX_POSE_SAMPLES).astype(np.int64)
    n = k.size
    if int(k.max(initial=1)) == 1:  # the common case: one sample each
        pos = bank.poses(np.arange(n), np.full(n, tmin + 0.5 * span))[0]
        centre, path = pos, 0.0
    else:
        start = np.cumsum(k) - k
        label = np.repeat(np.arange(n), k)
        j = np.arange(label.size) - start[label]
        pos = bank.poses(label, tmin + (j + 0.5) * (span / k[label]))[0]
        centre = (np.minimum.reduceat(pos, start, axis=1) + np.maximum.reduceat(pos, start, axis=1)) / 2
        dev = pos - np.take(centre, label, axis=1)
        path = np.sqrt(np.maximum.reduceat(np.einsum("ij,ij->j", dev, dev), start))
    radius = mesh_radii + path + speeds * span / (2 * k)
    radius += _SPHERE_PAD_M + 1e-6 * (radius + np.abs(centre).max(axis=0))
    return np.ascontiguousarray(centre.T), radius


def _bounding_sphere(points: np.ndarray) -> tuple[np.ndarray, float]:
    """A (not minimal) bounding sphere of (V, 3) points: bbox centre, max distance."""
    centre = (points.min(axis=0) + points.max(axis=0)) / 2
    radius = float(np.sqrt(((points - centre) ** 2).sum(axis=1).max())) if len(points) else 0.0
    return centre, radius + _SPHERE_PAD_M + 1e-6 * (radius + float(np.abs(centre).max()))


def _origin_box(origins: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
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


# ------------------------------------------------------------ numpy helpers

_POOLS: dict[int, ThreadPoolExecutor] = {}
_POOL_LOCK = threading.Lock()


def _pool(workers: int) -> ThreadPoolExecutor:
    """A shared thread pool with ``workers`` threads (created on first use)."""
    with _POOL_LOCK:
        if workers not in _POOLS:
            _POOLS[workers] = ThreadPoolExecutor(workers, thread_name_prefix="raysim-scene")
        return _POOLS[workers]


def _split_run(n: int, workers: int, fn: Callable[[int, int], object]) -> list:
    """Run ``fn(a, b)`` over contiguous parts of ``range(n)``, in parallel if large.

    Returns the results in the order of the parts.
    """
    if workers <= 1 or n < _PARALLEL_MIN_RAYS:
        return [fn(0, n)]
    bounds = np.linspace(0, n, workers + 1).astype(int)
    futures = [_pool(workers).submit(fn, int(a), int(b)) for a, b in zip(bounds[:-1], bounds[1:])]
    return [f.result() for f in futures]


_SCRATCH = threading.local()


def _scratch(name: str, shape: tuple[int, ...], dtype: type = np.float32) -> np.ndarray:
    """A per-thread scratch array of at least ``shape`` (reused across calls, never returned)."""
    buf = getattr(_SCRATCH, name, None)
    if buf is None or buf.shape[0] < shape[0] or buf.shape[1:] != shape[1:] or buf.dtype != dtype:
        buf = np.empty(shape, dtype=dtype)
        setattr(_SCRATCH, name, buf)
    return buf[: shape[0]]


def _pack_rays_part(
    origins: np.ndarray,
    directions: np.ndarray,
    idx: np.ndarray | None,
    offset_tile: np.ndarray | None,
    out: np.ndarray,
    a: int,
    b: int,
) -> None:
    """Fill ``out[a:b]`` with float32 ``[o - offset, d]`` rows of rays ``a:b`` (or ``idx[a:b]``).

    Works chunk by chunk through a float64 (chunk, 6) scratch array that stays in
    cache: rows are interleaved as 24-byte items (one long 1-D copy per input
    instead of N tiny row copies), the offset is subtracted with one flat
    vectorised pass, and a single contiguous cast writes the float32 rows.
    """
    s64 = _scratch("pack_s64", (_CHUNK, 6), np.float64)
    o_items = origins.view("V24")[:, 0]
    d_items = directions.view("V24")[:, 0]
    for s in range(a, b, _CHUNK):
        e = min(b, s + _CHUNK)
        rows = s64[: e - s]
        items = rows.view("V24")
        if idx is None:
            items[:, 0] = o_items[s:e]
            items[:, 1] = d_items[s:e]
        else:
            items[:, 0] = np.take(o_items, idx[s:e])
            items[:, 1] = np.take(d_items, idx[s:e])
        if offset_tile is not None:
            flat = rows.reshape(-1)
            np.subtract(flat, offset_tile[: flat.size], out=flat)
        np.copyto(out[s:e], rows, casting="same_kind")


def _offset_tile(offset_m: np.ndarray | None) -> np.ndarray | None:
    """``[ox, oy, oz, 0, 0, 0]`` repeated for one chunk (None for no offset)."""
    if offset_m is None or not np.any(offset_m):
        return None
    return np.tile(np.concatenate([np.asarray(offset_m, dtype=np.float64), np.zeros(3)]), _CHUNK)


def pack_rays(
    origins_m: np.ndarray,
    directions: np.ndarray,
    offset_m: np.ndarray | None = None,
    workers: int = 1,
    out: np.ndarray | None = None,
    idx: np.ndarray | None = None,
) -> np.ndarray:
    """Pack rays into the float32 (N, 6) layout Open3D casts.

    Parameters
    ----------
    origins_m : (N, 3) float64, C-contiguous
        Ray origins, metres.
    directions : (N, 3) float64, C-contiguous
        Unit directions.
    offset_m : (3,) float64 or None
        Subtracted from the origins in float64 before rounding to float32.
    workers : int
        Threads to split large batches over.
    out : (>= M, 6) float32 or None
        Where to write (a new array if None).
    idx : (M,) int or None
        Pack only these rays (all if None).

    Returns
    -------
    (M, 6) float32
        ``[ox - offset_x, oy - offset_y, oz - offset_z, dx, dy, dz]`` rows.
    """
    m = origins_m.shape[0] if idx is None else idx.shape[0]
    out = np.empty((m, 6), dtype=np.float32) if out is None else out[:m]
    tile = _offset_tile(offset_m)
    _split_run(m, workers, lambda a, b: _pack_rays_part(origins_m, directions, idx, tile, out, a, b))
    return out


# ------------------------------------------------------------ scene parts


@dataclass
class _StaticPart:
    """All static objects in one Open3D scene (world frame shifted by ``offset_m``)."""

    scene: o3d.t.geometry.RaycastingScene
    offset_m: np.ndarray  # (3,) float64
    offset_tile: np.ndarray | None  # offset pattern for pack_rays
    geometry_object: np.ndarray  # (G,) int32: object id per geometry id
    geometry_face_offset: np.ndarray  # (G,) int64: first face of each geometry in face_material
    face_material: np.ndarray  # (F_total,) int16
    geometry_object_ext: np.ndarray  # (G + 1,) geometry_object + [NO_HIT] (index -1 = miss)
    geometry_face_offset_ext: np.ndarray  # (G + 1,) geometry_face_offset + [F_total + 1]
    face_material_ext: np.ndarray  # (F_total + 1,) face_material + [-1]
    sphere_centres: np.ndarray  # (G, 3) float64: world bounding sphere per object
    sphere_radii: np.ndarray  # (G,) float64


@dataclass
class _Body:
    """A distinct moving mesh (shared by the objects that use the same one; each still gets its atlas copy)."""

    radius_m: float  # max vertex distance from the body origin


@dataclass
class _Mover:
    """A moving object and its body-frame mesh."""

    obj: SceneObject
    body: _Body
    face_material: np.ndarray  # (F,) int16


@dataclass
class _Batch:
    """One cast's rays and the per-batch quantities shared by all objects."""

    origins: np.ndarray  # (N, 3) float64
    directions: np.ndarray  # (N, 3) float64
    times: np.ndarray  # (N,) float64
    max_range: np.ndarray | None  # scalar or (N,) float64; None if unlimited
    origin_centre: np.ndarray | None = None  # (3,) centre of the origins' bounding box
    spread_m: float = 0.0  # half-diagonal of that box
    cells: np.ndarray | None = None  # (N,) uint16 direction cells
    sea_range: np.ndarray | None = None  # (N,) float64 range to the sea (inf if none)
    static_candidates: np.ndarray | None = None  # (M,) rays to cast at the static scene
    order: np.ndarray | None = None  # (N,) rays sorted by cell
    cell_start: np.ndarray | None = None  # (_CELLS + 1,) first sorted position of each cell

    @property
    def n(self) -> int:
        return self.origins.shape[0]

    def limit(self, s: slice | np.ndarray) -> np.ndarray | float:
        """Nearest range at which rays ``s`` can still get a new hit (sea, max range), metres."""
        lim: np.ndarray | float = np.inf if self.sea_range is None else self.sea_range[s]
        if self.max_range is not None:
            mr = self.max_range[s] if self.max_range.ndim else float(self.max_range)
            lim = np.minimum(lim, mr)
        return lim

    def sort_by_cell(self, limit: np.ndarray, min_near_m: float) -> None:
        """Counting-sort by direction cell the rays that may reach beyond ``min_near_m``.

        Parameters
        ----------
        limit : (N,) float64
            Range beyond which each ray can get no new hit, metres.
        min_near_m : float
            Nearest distance at which any moving object can be met, metres.
        """
        reach = np.flatnonzero(limit > min_near_m)
        cells = self.cells if reach.size == self.n else self.cells[reach]
        order = np.argsort(cells, kind="stable")
        self.order = order if reach.size == self.n else reach[order]
        self.cell_start = np.concatenate(([0], np.cumsum(np.bincount(cells, minlength=_CELLS))))


def _mesh_key(vertices: np.ndarray, faces: np.ndarray) -> bytes:
    """Content hash of a mesh (objects with equal meshes share one :class:`_Body` record)."""
    h = hashlib.blake2b(digest_size=16)
    h.update(np.ascontiguousarray(vertices, dtype=np.float64).tobytes())
    h.update(np.ascontiguousarray(faces, dtype=np.int64).tobytes())
    return h.digest()


def _make_scene(vertices: np.ndarray, faces: np.ndarray, nthreads: int) -> o3d.t.geometry.RaycastingScene:
    """An Open3D scene holding one mesh (vertices already in the scene's frame)."""
    scene = o3d.t.geometry.RaycastingScene(nthreads=nthreads)
    scene.add_triangles(
        o3d.core.Tensor(np.ascontiguousarray(vertices, dtype=np.float32)),
        o3d.core.Tensor(np.ascontiguousarray(faces, dtype=np.uint32)),
    )
    return scene


def _check_object(obj: SceneObject) -> None:
    """Raise ValueError if an object's arrays are inconsistent."""
    v, f, m = np.asarray(obj.vertices_m), np.asarray(obj.faces), np.asarray(obj.face_material)
    if v.ndim != 2 or v.shape[1] != 3 or f.ndim != 2 or f.shape[1] != 3:
        raise ValueError(f"object {obj.object_id}: vertices and faces must be (V, 3) and (F, 3)")
    if m.shape != (f.shape[0],):
        raise ValueError(f"object {obj.object_id}: face_material must have one entry per face")
    if f.size and (f.min() < 0 or f.max() >= v.shape[0]):
        raise ValueError(f"object {obj.object_id}: face index out of range")
    if obj.object_id < 0:
        raise ValueError(f"object id must be >= 0, got {obj.object_id}")


def _static_results_part(
    st: "_StaticPart",
    directions: np.ndarray,
    rays: np.ndarray,
    t32: np.ndarray,
    gid: np.ndarray,
    prim: np.ndarray,
    normal: np.ndarray,
    rng: np.ndarray,
    obj: np.ndarray,
    material: np.ndarray,
    a: int,
    b: int,
) -> None:
    """Turn Open3D's answers for rays ``a:b`` into ranges, ids, materials; flip normals.

    Chunk by chunk (small temporaries stay in cache). A chunk with many hits is
    handled with whole-chunk table look-ups (misses index the sentinels) and a
    normal/direction dot product against the packed float32 rays; a chunk with
    few hits is filled, then only its hits are touched.
    """
    for s in range(a, b, _CHUNK):
        e = min(b, s + _CHUNK)
        np.copyto(rng[s:e], t32[s:e])
        g = gid[s:e]
        if 16 * np.count_nonzero(g[::16] >= 0) > (e - s) // 8:  # many hits (a subsample decides)
            np.take(st.geometry_object_ext, g, out=obj[s:e], mode="wrap")
            face = np.take(st.geometry_face_offset_ext, g, mode="wrap")
            face += prim[s:e]
            np.take(st.face_material_ext, face, out=material[s:e], mode="wrap")
            n_c, r_c = normal[s:e], rays[s:e]
            dot = n_c[:, 0] * r_c[:, 3]  # 0 where no hit (zero normal)
            dot += n_c[:, 1] * r_c[:, 4]
            dot += n_c[:, 2] * r_c[:, 5]
            flip = np.flatnonzero(dot > 0)
            if flip.size:
                n_c[flip] *= -1.0
        else:
            obj[s:e] = NO_HIT
            material[s:e] = -1
            hit = np.flatnonzero(g >= 0)
            j = hit + s
            gh = g[hit]
            obj[j] = st.geometry_object[gh]
            material[j] = st.face_material[st.geometry_face_offset[gh] + prim[j]]
            _face_against(normal, j, np.take(directions, j, axis=0))


def _face_against(normal: np.ndarray, rows: np.ndarray, dirs: np.ndarray) -> None:
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


def _drop_beyond(hits: Hits, max_range: np.ndarray) -> None:
    """Turn hits farther than ``max_range`` (scalar or (N,)) into no hits (in place)."""
    idx = np.flatnonzero(hits.range_m > max_range)
    if idx.size == 0:
        return
    hits.range_m[idx] = np.inf
    hits.object_id[idx] = NO_HIT
    hits.material[idx] = -1
    hits.primitive[idx] = -1
    hits.normal[idx] = 0.0


# ------------------------------------------------------------------ scene


class Scene:
    """Objects and the sea, answering "what does this ray hit at its time".

    Parameters
    ----------
    objects : sequence of SceneObject
        Static and moving objects (ids need not be unique or dense).
    sea : bool
        Include the flat sea surface z = 0.
    sea_material : int
        Material index reported for sea hits.
    nthreads : int
        Threads for Embree (0 = all cores); also bounds the threads used for
        per-ray numpy work.
    cull : bool
        Cull rays (see module docstring). ``False`` casts every ray at the
        static scene and at every moving object (a brute-force reference).
    """

    def __init__(
        self,
        objects: Sequence[SceneObject],
        sea: bool = True,
        sea_material: int = -1,
        nthreads: int = 0,
        cull: bool = True,
    ) -> None:
        for obj in objects:
            _check_object(obj)
        objects = [o for o in objects if len(o.faces)]  # nothing to hit on an empty mesh
        self.sea = bool(sea)
        self.sea_material = int(sea_material)
        self.nthreads = int(nthreads)
        self.cull = bool(cull)
        self._workers = max(1, min(self.nthreads or (os.cpu_count() or 1), 4))
        static = [o for o in objects if o.is_static]
        self._static = self._build_static(static) if static else None
        self._movers = self._build_movers([o for o in objects if not o.is_static])
        self._mover_ids = np.array([m.obj.object_id for m in self._movers], dtype=np.int32)
        self._mover_speed = np.array([float(m.obj.motion.max_speed_mps) for m in self._movers], dtype=np.float64)
        self._bank = _PoseBank([m.obj.motion for m in self._movers])
        self._carrier_scenes: dict[int, o3d.t.geometry.RaycastingScene] = {}
        self._carrier_lock = threading.Lock()
        n_faces = [len(m.face_material) for m in self._movers]
        self._mover_face_offset = np.concatenate(([0], np.cumsum(n_faces)[:-1])).astype(np.int64)
        boxes = [(m.obj.vertices_m.min(axis=0), m.obj.vertices_m.max(axis=0)) for m in self._movers]
        pad = _SPHERE_PAD_M
        self._mover_box_lo = np.array([b[0] - pad for b in boxes]).reshape(-1, 3).T  # (3, K) body frame
        self._mover_box_hi = np.array([b[1] + pad for b in boxes]).reshape(-1, 3).T
        self._mover_materials = (
            np.concatenate([m.face_material for m in self._movers]) if self._movers else np.zeros(0, np.int16)
        )
        self._mover_radius = np.array([m.body.radius_m for m in self._movers], dtype=np.float64) + _SPHERE_PAD_M
        self._mover_radius2 = self._mover_radius**2
        self._atlas, self._atlas_offset = self._build_atlas(self._movers, self._mover_radius)

    # ------------------------------------------------------------------ build

    def _build_static(self, objects: list[SceneObject]) -> _StaticPart:
        """Put all static objects, in world coordinates minus an offset, in one scene."""
        poses = [o.motion.poses(np.zeros(1)) for o in objects]
        mean = np.mean([p.position_m[0] for p in poses], axis=0)
        offset = np.round(mean / _OFFSET_GRID_M) * _OFFSET_GRID_M
        scene = o3d.t.geometry.RaycastingScene(nthreads=self.nthreads)
        geometry_object, face_offset, materials, centres, radii = [], [], [], [], []
        n_faces = 0
        for obj, pose in zip(objects, poses):
            world = np.asarray(obj.vertices_m, dtype=np.float64) @ pose.rotation()[0].T + pose.position_m[0]
            gid = scene.add_triangles(
                o3d.core.Tensor(np.ascontiguousarray(world - offset, dtype=np.float32)),
                o3d.core.Tensor(np.ascontiguousarray(obj.faces, dtype=np.uint32)),
            )
            if gid != len(geometry_object):
                raise RuntimeError(f"unexpected Open3D geometry id {gid}")
            geometry_object.append(obj.object_id)
            face_offset.append(n_faces)
            materials.append(np.asarray(obj.face_material, dtype=np.int16))
            n_faces += len(obj.faces)
            c, r = _bounding_sphere(world)
            centres.append(c)
            radii.append(r)
        return _StaticPart(
            scene=scene,
            offset_m=offset,
            offset_tile=_offset_tile(offset),
            geometry_object=np.array(geometry_object, dtype=np.int32),
            geometry_face_offset=np.array(face_offset, dtype=np.int64),
            face_material=np.concatenate(materials),
            geometry_object_ext=np.array(geometry_object + [NO_HIT], dtype=np.int32),
            geometry_face_offset_ext=np.array(face_offset + [n_faces + 1], dtype=np.int32),
            face_material_ext=np.concatenate(materials + [np.array([-1], dtype=np.int16)]),
            sphere_centres=np.array(centres),
            sphere_radii=np.array(radii),
        )

    def _build_movers(self, objects: list[SceneObject]) -> list[_Mover]:
        """One entry per moving object; its body record (bounding radius) computed once per distinct mesh."""
        bodies: dict[bytes, _Body] = {}
        movers = []
        for obj in objects:
            key = _mesh_key(obj.vertices_m, obj.faces)
            if key not in bodies:
                v = np.asarray(obj.vertices_m, dtype=np.float64)
                radius = float(np.sqrt((v * v).sum(axis=1).max())) if len(v) else 0.0
                bodies[key] = _Body(radius)
            movers.append(_Mover(obj, bodies[key], np.asarray(obj.face_material, dtype=np.int16)))
        return movers

    def _build_atlas(self, movers: list[_Mover], radii: np.ndarray):
        """ONE Open3D scene holding every moving object's body-frame mesh in its own cell.

        Object k's mesh (its own copy, even where objects share a mesh) sits at
        ``offset[:, k]``, the centre of cell k of a square grid in the body x-z plane
        whose spacing is twice the largest bounding radius plus 10 m, so the cells'
        bounding spheres are disjoint and coordinates stay within a few kilometres of the
        atlas origin (float32 keeps sub-millimetre precision). A batch casts all
        objects' candidate rays in one call: each ray starts at the entry of its own
        object's sphere, so a hit on its own object, if any, comes before anything in
        another cell (geometry id = object label). The grid is a vertical plane because
        sensors see bodies along near-horizontal rays: a ray that misses its object
        leaves the plane instead of crossing other cells (which costs Embree time).

        Parameters
        ----------
        movers : list of _Mover
        radii : (K,) float64
            Bounding radius of each body about its origin (padded), metres.

        Returns
        -------
        scene : RaycastingScene or None
        offsets : (3, K) float64
            Atlas position of each body origin, metres.
        """
        if not movers:
            return None, np.zeros((3, 0))
        spacing = 2.0 * float(radii.max()) + 10.0
        side = 1
        while side**2 < len(movers):
            side += 1
        index = np.arange(len(movers))
        cells = np.stack([index % side, np.full(len(movers), (side - 1) / 2.0), index // side]).astype(np.float64)
        offsets = (cells - (side - 1) / 2.0) * spacing  # y = 0
        scene = o3d.t.geometry.RaycastingScene(nthreads=self.nthreads)
        for k, mover in enumerate(movers):
            vertices = np.asarray(mover.obj.vertices_m, dtype=np.float64) + offsets[:, k]
            gid = scene.add_triangles(
                o3d.core.Tensor(np.ascontiguousarray(vertices, dtype=np.float32)),
                o3d.core.Tensor(np.ascontiguousarray(mover.obj.faces, dtype=np.uint32)),
            )
            if gid != k:
                raise RuntimeError(f"unexpected Open3D geometry id {gid}")
        return scene, offsets

    @property
    def static_raycasting_scene(self) -> o3d.t.geometry.RaycastingScene | None:
        """The Open3D scene of the static objects (coordinates minus ``static_offset_m``)."""
        return None if self._static is None else self._static.scene

    @property
    def static_offset_m(self) -> np.ndarray:
        """(3,) world position of the static scene's coordinate origin, metres."""
        return np.zeros(3) if self._static is None else self._static.offset_m.copy()

    @property
    def n_bodies(self) -> int:
        """Number of distinct moving meshes (each moving object has its own copy in the atlas)."""
        return len({id(m.body) for m in self._movers})

    @property
    def n_atlas_geometries(self) -> int:
        """Meshes in the moving objects' one acceleration structure (one per moving object)."""
        return 0 if self._atlas is None else len(self._movers)

    # ------------------------------------------------------------------- cast

    def cast(
        self,
        origins_m: np.ndarray,
        directions: np.ndarray,
        times_s: np.ndarray,
        max_range_m: float | np.ndarray = np.inf,
        carrier: Carrier | None = None,
    ) -> Hits:
        """First hit of each ray, each ray seeing the world at its own time.

        Parameters
        ----------
        origins_m : (N, 3) float64
            Ray origins in the world (ENU) frame, metres.
        directions : (N, 3) float
            Unit ray directions in the world frame.
        times_s : (N,) float64
            Time of each ray, seconds since scenario start.
        max_range_m : float or (N,) float
            Hits farther than this count as no hit, metres.
        carrier : Carrier, optional
            The same rays in the body frame of the moving object that carries the
            sensor (the own ship): that object is then cast with these rays as they
            are, without pose evaluation or culling. The hits are the same as
            without it (up to float32 round-off).

        Returns
        -------
        Hits
            One entry per ray.
        """
        origins = np.ascontiguousarray(origins_m, dtype=np.float64)
        dirs = np.ascontiguousarray(directions, dtype=np.float64)
        times = np.ascontiguousarray(times_s, dtype=np.float64).reshape(-1)
        n = origins.shape[0]
        if origins.shape != (n, 3) or dirs.shape != (n, 3) or times.shape != (n,):
            raise ValueError("origins and directions must be (N, 3) and times (N,)")
        max_range = np.asarray(max_range_m, dtype=np.float64)
        if max_range.ndim and max_range.shape != (n,):
            raise ValueError("max_range_m must be a scalar or (N,)")
        if n == 0:
            return Hits.empty(0)
        carrier_label = None if carrier is None else self._carrier_label(carrier, n)
        n_others = len(self._movers) - (carrier_label is not None)
        finite_range = bool(np.any(np.isfinite(max_range)))
        batch = _Batch(origins, dirs, times, max_range if finite_range else None)
        self._prepare(batch, n_others > 0)

        if self._static is not None and batch.static_candidates is None:
            hits = self._cast_static_all(batch)
            if self.sea:
                self._merge_sea(hits, batch)
        else:
            hits = self._sea_hits(batch)
            if self._static is not None:
                self._merge_static_some(hits, batch, batch.static_candidates)
        if finite_range:
            _drop_beyond(hits, max_range)
        if carrier_label is not None:
            self._cast_carrier(hits, batch, carrier, carrier_label)
        if n_others:
            self._cast_moving(hits, batch, skip=carrier_label)
        return hits

    # ---------------------------------------------------------- batch prepass

    def _prepare(self, batch: _Batch, movers: bool | None = None) -> None:
        """Per-batch pre-pass: origin box, direction cells, sea ranges, static candidates.

        ``movers``: whether moving objects will be culled (default: the scene has any).
        """
        movers = bool(self._movers) if movers is None else movers
        need_cells = self.cull and (self._static is not None or movers)
        if not need_cells:
            if self.sea:
                batch.sea_range = intersect_sea(batch.origins[:, 2], batch.directions[:, 2])
            return
        parts = _split_run(batch.n, self._workers, lambda a, b: _origin_box(batch.origins[a:b]))
        lo = np.min([p[0] for p in parts], axis=0)
        hi = np.max([p[1] for p in parts], axis=0)
        batch.origin_centre = (lo + hi) / 2
        batch.spread_m = float(np.linalg.norm(hi - lo) / 2) * (1 + 1e-9) + 1e-9
        near_table = self._static_near_table(batch) if self._static is not None else None
        if near_table is not None and self._static_fraction(batch, near_table) > _STATIC_CULL_MAX_FRACTION:
            near_table = None
        if near_table is None and not movers:  # cells are of no use: sea only
            if self.sea:
                batch.sea_range = intersect_sea(batch.origins[:, 2], batch.directions[:, 2])
            return
        n = batch.n
        batch.cells = np.empty(n, dtype=np.uint16)
        if self.sea:
            batch.sea_range = np.empty(n, dtype=np.float64)
        parts = _split_run(n, self._workers, lambda a, b: self._prepass_part(batch, near_table, a, b))
        if near_table is not None:
            batch.static_candidates = parts[0] if len(parts) == 1 else np.concatenate(parts)

    def _prepass_part(self, batch: _Batch, near_table: np.ndarray | None, a: int, b: int) -> np.ndarray | None:
        """Fill the cells and sea ranges of rays ``a:b``; return their static candidates (or None)."""
        cand = []
        for s in range(a, b, _CHUNK):
            e = min(b, s + _CHUNK)
            d32 = batch.directions[s:e].T.astype(np.float32)
            batch.cells[s:e] = direction_cells(d32[0], d32[1], d32[2])
            if batch.sea_range is not None:
                batch.sea_range[s:e] = intersect_sea(batch.origins[s:e, 2], batch.directions[s:e, 2])
            if near_table is not None:
                near = np.take(near_table, batch.cells[s:e])
                cand.append(np.flatnonzero(near < batch.limit(slice(s, e))) + s)
        if near_table is None:
            return None
        return np.concatenate(cand) if len(cand) != 1 else cand[0]

    def _static_near_table(self, batch: _Batch) -> np.ndarray:
        """(_CELLS,) float32: nearest distance a static object can be met at through each cell."""
        st = self._static
        table = np.full((AZ_BINS, EL_BINS), np.inf, dtype=np.float32)
        cells = _sphere_cells(st.sphere_centres, st.sphere_radii, batch.origin_centre, batch.spread_m)
        near = np.nextafter((cells.near_m * (1 - 1e-6)).astype(np.float32), np.float32(-np.inf))  # round down
        for k, lo, hi, e0, e1 in zip(*cells.runs(np.arange(len(near)))):
            block = table[lo : hi + 1, e0 : e1 + 1]
            np.minimum(block, near[k], out=block)
        return table.reshape(-1)

    def _static_fraction(self, batch: _Batch, near_table: np.ndarray) -> float:
        """Fraction of the batch's rays the static table would keep (estimated on a subsample)."""
        step = max(1, batch.n // _SUBSAMPLE_RAYS)
        sub = slice(0, batch.n, step)
        d = batch.directions[sub]
        cells = direction_cells(d[:, 0], d[:, 1], d[:, 2])
        lim = np.full(cells.shape[0], np.inf)
        if self.sea:
            lim = intersect_sea(batch.origins[sub, 2], d[:, 2])
        if batch.max_range is not None:
            mr = batch.max_range[sub] if batch.max_range.ndim else float(batch.max_range)
            lim = np.minimum(lim, mr)
        return float(np.mean(near_table[cells] < lim))

    # ------------------------------------------------------------------ static

    def _cast_static_all(self, batch: _Batch) -> Hits:
        """Cast all rays at the static scene.

        Per-ray work: packing, one float32 -> float64 copy of ``t_hit``, one
        comparison (plus three table look-ups when many rays hit); the rest
        touches hits only. Open3D's own primitive and normal arrays are
        returned as they are (-1 and zeros where no hit).
        """
        st = self._static
        n = batch.n
        rays = _scratch("rays", (n, 6))
        pack_rays(batch.origins, batch.directions, st.offset_m, self._workers, out=rays)
        res = st.scene.cast_rays(o3d.core.Tensor.from_numpy(rays), nthreads=self.nthreads)
        t32 = res["t_hit"].numpy()
        gid = res["geometry_ids"].numpy().view(np.int32)  # INVALID_ID -> -1
        prim = res["primitive_ids"].numpy().view(np.int32)  # INVALID_ID -> -1
        normal = res["primitive_normals"].numpy()  # zeros where no hit
        rng = np.empty(n, dtype=np.float64)
        obj = np.empty(n, dtype=np.int32)
        material = np.empty(n, dtype=np.int16)
        _split_run(
            n,
            self._workers,
            lambda a, b: _static_results_part(st, batch.directions, rays, t32, gid, prim, normal, rng, obj, material, a, b),
        )
        return Hits(rng, obj, normal, material, prim)

    def _merge_static_some(self, hits: Hits, batch: _Batch, idx: np.ndarray) -> None:
        """Cast rays ``idx`` at the static scene; keep hits nearer than the current ones (in place)."""
        st = self._static
        if idx.size == 0:
            return
        rays = _scratch("rays", (idx.size, 6))
        pack_rays(batch.origins, batch.directions, st.offset_m, self._workers, out=rays, idx=idx)
        res = st.scene.cast_rays(o3d.core.Tensor.from_numpy(rays), nthreads=self.nthreads)
        t = res["t_hit"].numpy()
        sel = np.flatnonzero(t < hits.range_m[idx])  # misses are inf
        if sel.size == 0:
            return
        j = idx[sel]
        g = res["geometry_ids"].numpy().view(np.int32)[sel]
        prim = res["primitive_ids"].numpy().view(np.int32)[sel]
        normal = res["primitive_normals"].numpy()[sel]
        _face_against(normal, np.arange(sel.size), np.take(batch.directions, j, axis=0))
        hits.range_m[j] = t[sel]
        hits.object_id[j] = st.geometry_object[g]
        hits.primitive[j] = prim
        hits.material[j] = st.face_material[st.geometry_face_offset[g] + prim]
        hits.normal[j] = normal

    # --------------------------------------------------------------------- sea

    def _sea_normal_z(self, batch: _Batch) -> np.ndarray:
        """(N,) float32: z of the sea normal facing each ray (+1 from above, -1 from below)."""
        return np.where(batch.directions[:, 2] < 0, np.float32(1.0), np.float32(-1.0))

    def _sea_hits(self, batch: _Batch) -> Hits:
        """Hits of the sea alone (no hit everywhere if the scene has no sea)."""
        n = batch.n
        if not self.sea:
            return Hits.empty(n)
        rng = batch.sea_range  # owned by this batch: returned as is
        hit = rng < np.inf
        obj = np.full(n, NO_HIT, dtype=np.int32)
        np.copyto(obj, SEA_ID, where=hit)
        material = np.full(n, -1, dtype=np.int16)
        np.copyto(material, self.sea_material, where=hit)
        normal = np.zeros((n, 3), dtype=np.float32)
        np.copyto(normal[:, 2], self._sea_normal_z(batch), where=hit)
        return Hits(rng, obj, normal, material, np.full(n, -1, dtype=np.int32))

    def _merge_sea(self, hits: Hits, batch: _Batch) -> None:
        """Let the sea surface replace farther hits (in place)."""
        t = batch.sea_range
        nearer = t < hits.range_m
        replaced = nearer & (hits.object_id != NO_HIT)  # rows with a farther object hit
        if replaced.any():
            rows = np.flatnonzero(replaced)
            hits.primitive[rows] = -1
            hits.normal[rows] = 0.0
        np.copyto(hits.range_m, t, where=nearer)
        np.copyto(hits.object_id, SEA_ID, where=nearer)
        np.copyto(hits.material, self.sea_material, where=nearer)
        np.copyto(hits.normal[:, 2], self._sea_normal_z(batch), where=nearer)

    # ----------------------------------------------------------------- moving

    def _carrier_label(self, carrier: Carrier, n: int) -> int | None:
        """Validate ``carrier`` for a batch of ``n`` rays; the label of its moving object (None if none)."""
        if carrier.origins_body_m.shape != (n, 3) or carrier.directions_body.shape != (n, 3):
            raise ValueError("carrier rays must be (N, 3) like the world rays")
        if carrier.rotation is not None and np.shape(carrier.rotation) != (n, 3, 3):
            raise ValueError("carrier rotation must be (N, 3, 3)")
        labels = np.flatnonzero(self._mover_ids == carrier.object_id)
        if labels.size > 1:
            raise ValueError(f"carrier id {carrier.object_id} is shared by several moving objects")
        return int(labels[0]) if labels.size else None

    def _carrier_scene(self, k: int) -> o3d.t.geometry.RaycastingScene:
        """The body-frame scene of moving object ``k`` alone (built on first use, then kept)."""
        with self._carrier_lock:
            if k not in self._carrier_scenes:
                obj = self._movers[k].obj
                self._carrier_scenes[k] = _make_scene(obj.vertices_m, obj.faces, self.nthreads)
            return self._carrier_scenes[k]

    def _cast_carrier(self, hits: Hits, batch: _Batch, carrier: Carrier, k: int) -> None:
        """Cast every ray, in the carrier's body frame, at the carrier alone (in place).

        No pose and no culling: the caller's body-frame rays go to Embree as they
        are (one call on a scene holding only the carrier's mesh). Normals of the
        hits are rotated to the world frame with ``carrier.rotation`` or, if None,
        with the carrier's pose at the hit rays' times.
        """
        n = batch.n
        o_b = np.ascontiguousarray(carrier.origins_body_m, dtype=np.float64)
        d_b = np.ascontiguousarray(carrier.directions_body, dtype=np.float64)
        rays = _scratch("rays", (n, 6))
        pack_rays(o_b, d_b, None, self._workers, out=rays)
        res = self._carrier_scene(k).cast_rays(o3d.core.Tensor.from_numpy(rays), nthreads=self.nthreads)
        t32 = res["t_hit"].numpy()
        better = t32 < hits.range_m  # misses are inf
        if batch.max_range is not None:
            better &= t32 <= batch.max_range
        j = np.flatnonzero(better)
        if j.size == 0:
            return
        prim = res["primitive_ids"].numpy().view(np.int32)[j]
        n_body = res["primitive_normals"].numpy()[j].astype(np.float64)
        if carrier.rotation is not None:
            n_world = np.einsum("nij,nj->ni", np.asarray(carrier.rotation, dtype=np.float64)[j], n_body)
        else:
            _, yaw, pitch, roll = self._bank.poses(k, np.take(batch.times, j))
            if pitch is None:  # yaw only
                c, s = np.cos(yaw), np.sin(yaw)
                n_world = np.stack([c * n_body[:, 0] - s * n_body[:, 1], s * n_body[:, 0] + c * n_body[:, 1], n_body[:, 2]], axis=1)
            else:
                n_world = np.einsum("nij,nj->ni", rotation_matrices(yaw, pitch, roll), n_body)
        flip = np.einsum("ni,ni->n", n_world, np.take(batch.directions, j, axis=0)) > 0
        n_world[flip] *= -1.0
        hits.range_m[j] = t32[j]
        hits.object_id[j] = self._mover_ids[k]
        hits.primitive[j] = prim
        hits.material[j] = self._mover_materials[self._mover_face_offset[k] + prim]
        hits.normal[j] = n_world

    def _cast_moving(self, hits: Hits, batch: _Batch, skip: int | None = None) -> None:
        """Cast against every moving object but ``skip`` (the carrier), keeping nearer hits (in place).

        Candidate (ray, object) pairs are selected for all objects at once, their
        poses are evaluated in one vectorised pass per motion kind, transformed with
        one vectorised pass, cast with one Open3D call for all objects (the atlas),
        and the nearest hit per ray is merged in one pass.
        """
        n_movers = len(self._movers)
        if not self.cull:  # brute force, one object at a time (bounded memory)
            ray = np.arange(batch.n)
            o, d = np.ascontiguousarray(batch.origins.T), np.ascontiguousarray(batch.directions.T)
            for k in range(n_movers):
                if k != skip:
                    self._merge_moving(hits, self._cast_pairs(batch, hits, ray, np.full(batch.n, k), o, d))
            return
        tmin, tmax = float(batch.times.min()), float(batch.times.max())
        range_cap = np.inf if batch.max_range is None else float(np.max(batch.max_range))
        centres, radii = _swept_spheres(self._bank, self._mover_speed, self._mover_radius, tmin, tmax)
        cells = _sphere_cells(centres, radii, batch.origin_centre, batch.spread_m)
        reachable = cells.near_m <= range_cap
        if skip is not None:
            reachable[skip] = False
        live = np.flatnonzero(reachable)
        if live.size == 0:
            return
        limit = hits.range_m
        if batch.max_range is not None:
            limit = np.minimum(limit, batch.max_range)
        everywhere = (cells.a0 == 0) & (cells.a1 == AZ_BINS - 1) & (cells.e0 == 0) & (cells.e1 == EL_BINS - 1)
        around, rest = live[everywhere[live]], live[~everywhere[live]]
        rays, labels, os_, ds = [], [], [], []
        if rest.size:  # rays of the objects' cells, via the cell-sorted order
            batch.sort_by_cell(limit, float(cells.near_m[rest].min()))
            ray, label = self._pairs_in_cells(batch, *cells.runs(rest))
            keep = np.take(limit, ray) > np.take(cells.near_m, label)
            ray, label = ray[keep], label[keep]
            o, d = _gather_columns(batch.origins, ray), _gather_columns(batch.directions, ray)
            keep = np.flatnonzero(
                _pairs_reach_spheres(o, d, np.take(centres.T, label, axis=1), np.take(radii, label), np.take(limit, ray))
            )
            if keep.size < ray.size:
                ray, label, o, d = ray[keep], label[keep], np.take(o, keep, axis=1), np.take(d, keep, axis=1)
            rays.append(ray)
            labels.append(label)
            os_.append(o)
            ds.append(d)
        for k in around.tolist():
            # An object seen in every direction (e.g. the ship carrying the sensor, when
            # no carrier is given): its rays in ray order (runs of equal times share one
            # pose); a sphere test would filter next to nothing.
            ray = np.flatnonzero(limit > cells.near_m[k])
            rays.append(ray)
            labels.append(np.full(ray.size, k))
            os_.append(_gather_columns(batch.origins, ray))
            ds.append(_gather_columns(batch.directions, ray))
        if len(rays) > 1:
            ray, label = np.concatenate(rays), np.concatenate(labels)
            o, d = np.concatenate(os_, axis=1), np.concatenate(ds, axis=1)
        else:
            ray, label, o, d = rays[0], labels[0], os_[0], ds[0]
        if ray.size:
            self._merge_moving(hits, self._cast_pairs(batch, hits, ray, label, o, d))

    @staticmethod
    def _pairs_in_cells(
        batch: _Batch, label: np.ndarray, lo: np.ndarray, hi: np.ndarray, e0: np.ndarray, e1: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """All (ray, object label) pairs whose ray direction lies in the object's cells.

        Parameters
        ----------
        label, lo, hi, e0, e1 : (R,) int64
            Azimuth runs (see :meth:`_SphereCells.runs`).

        Returns
        -------
        ray, label : (P,) int64
            Pairs grouped by label, labels ascending.
        """
        full = (e0 == 0) & (e1 == EL_BINS - 1)  # whole azimuth run is one contiguous block
        n_bins = np.where(full, 1, hi - lo + 1)
        row = np.repeat(np.arange(label.size), n_bins)
        a = lo[row] + (np.arange(row.size) - np.repeat(np.cumsum(n_bins) - n_bins, n_bins))  # azimuth bin
        first = np.where(full[row], lo[row] * EL_BINS, a * EL_BINS + e0[row])
        end = np.where(full[row], (hi[row] + 1) * EL_BINS, a * EL_BINS + e1[row] + 1)
        start = batch.cell_start
        first = start[first]
        length = start[end] - first
        total = int(length.sum())
        if total == 0:
            return np.empty(0, dtype=np.int64), np.empty(0, dtype=np.int64)
        pos = np.repeat(first - (np.cumsum(length) - length), length) + np.arange(total)
        return batch.order[pos], np.repeat(label[row], length)

    def _cast_pairs(
        self, batch: _Batch, hits: Hits, ray: np.ndarray, label: np.ndarray, o: np.ndarray, d: np.ndarray
    ) -> dict[str, np.ndarray] | None:
        """Cast (ray, object) pairs at the objects' poses at the rays' times (one Embree call).

        Parameters
        ----------
        ray, label : (P,) int
            Pairs (consecutive pairs of one object and one time share a pose).
        o, d : (3, P) float64
            World origin (metres) and unit direction of each pair's ray.

        Returns
        -------
        dict or None
            For the pairs that hit their object nearer than the ray's current best:
            ``ray``, ``label``, ``t`` (range, m), ``prim``, ``normal`` (world, (M, 3)).
        """
        # Consecutive pairs of one object may share an instant (the rays of a LiDAR
        # firing or a radar spoke in ray order): one pose per run of equal times,
        # when that saves much; otherwise one pose per pair.
        times = np.take(batch.times, ray)
        new = np.empty(ray.size, dtype=bool)
        new[0] = True
        np.not_equal(times[1:], times[:-1], out=new[1:])
        new[1:] |= label[1:] != label[:-1]
        first = np.flatnonzero(new)  # first pair of each instant
        if 2 * first.size > ray.size:
            first, instant = None, None
            position, yaw, pitch, roll = self._bank.poses(label, times)
        else:
            instant = np.cumsum(new) - 1
            position, yaw, pitch, roll = self._bank.poses(label[first], times[first])
            position = np.take(position, instant, axis=1)
        planar = pitch is None
        if planar:  # yaw only: R = Rz(yaw)
            rot = np.stack([np.cos(yaw), np.sin(yaw)])  # (2, U)
        else:
            rot = rotation_matrices(yaw, pitch, roll).reshape(-1, 9).T  # (9, U): row 3 i + j = R[i, j]
        if instant is None:
            instant = np.arange(ray.size)
            r = rot
        else:
            r = np.take(rot, instant, axis=1)
        w = o - position
        body_o, body_d = np.empty((3, ray.size)), np.empty((3, ray.size))
        for src, dst in ((w, body_o), (d, body_d)):  # R^T v
            if planar:
                c, s = r
                dst[0] = c * src[0] + s * src[1]
                dst[1] = c * src[1] - s * src[0]
                dst[2] = src[2]
            else:
                for i in range(3):
                    dst[i] = r[i] * src[0] + r[3 + i] * src[1] + r[6 + i] * src[2]
        lo = np.take(self._mover_box_lo, label, axis=1)
        hi = np.take(self._mover_box_hi, label, axis=1)
        inside = np.flatnonzero(_pairs_hit_boxes(body_o, body_d, lo, hi))
        if inside.size == 0:
            return None
        if inside.size < ray.size:
            ray, label, instant = ray[inside], label[inside], instant[inside]
            body_o, body_d, d = (np.take(x, inside, axis=1) for x in (body_o, body_d, d))
        # One Open3D call for all objects (the atlas): each ray starts where it enters
        # its object's bounding sphere (float64), moved into the object's atlas cell.
        b = np.einsum("ij,ij->j", body_o, body_d)
        c = np.einsum("ij,ij->j", body_o, body_o) - np.take(self._mover_radius2, label)
        disc = b * b - c
        np.maximum(disc, 0.0, out=disc)
        np.sqrt(disc, out=disc)
        t_entry = -b - disc
        np.maximum(t_entry, 0.0, out=t_entry)
        shifted = np.empty((ray.size, 6), dtype=np.float32)
        shifted[:, :3] = (body_o + t_entry * body_d + np.take(self._atlas_offset, label, axis=1)).T
        shifted[:, 3:] = body_d.T
        res = self._atlas.cast_rays(o3d.core.Tensor.from_numpy(shifted), nthreads=self.nthreads)
        own = res["geometry_ids"].numpy().view(np.int32) == label  # another cell's object is never nearer
        t = t_entry + res["t_hit"].numpy()
        better = own & (t < np.take(hits.range_m, ray))
        if batch.max_range is not None:
            better &= t <= (np.take(batch.max_range, ray) if batch.max_range.ndim else float(batch.max_range))
        sel = np.flatnonzero(better)
        if sel.size == 0:
            return None
        n_b = res["primitive_normals"].numpy()[sel].T.astype(np.float64)  # (3, S) body frame
        r = np.take(rot, instant[sel], axis=1)
        if planar:  # R n
            c, s = r
            n_world = np.stack([c * n_b[0] - s * n_b[1], s * n_b[0] + c * n_b[1], n_b[2]], axis=1)
        else:
            n_world = np.stack([r[3 * i] * n_b[0] + r[3 * i + 1] * n_b[1] + r[3 * i + 2] * n_b[2] for i in range(3)], axis=1)
        flip = np.einsum("ni,in->n", n_world, np.take(d, sel, axis=1)) > 0
        n_world[flip] *= -1.0
        prim = res["primitive_ids"].numpy().view(np.int32)[sel]
        return {"ray": ray[sel], "label": label[sel], "t": t[sel], "prim": prim, "normal": n_world}

    def _merge_moving(self, hits: Hits, found: dict[str, np.ndarray] | None) -> None:
        """Write the nearest moving-object hit of each ray into ``hits`` (in place)."""
        if found is None:
            return
        ray, t = found["ray"], found["t"]
        order = np.lexsort((t, ray))
        first = order[np.r_[True, ray[order][1:] != ray[order][:-1]]]  # nearest per ray
        first = first[t[first] < hits.range_m[ray[first]]]
        j, label, prim = ray[first], found["label"][first], found["prim"][first]
        hits.range_m[j] = t[first]
        hits.object_id[j] = self._mover_ids[label]
        hits.primitive[j] = prim
        hits.material[j] = self._mover_materials[self._mover_face_offset[label] + prim]
        hits.normal[j] = found["normal"][first]

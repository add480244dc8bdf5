"""Poses of the moving objects, for many (object, time) pairs at once, and their swept spheres.

Each ray sees a moving object at the ray's own time, so a batch asks for
thousands of poses of many objects. :class:`PoseBank` packs the parameters of
the motions of known kinds (exactly :class:`~raysim.motion.ConstantVelocity`,
:class:`~raysim.motion.SampledTrack`, :class:`~raysim.motion.ShipMotion` of a
``SampledTrack`` with or without :class:`~raysim.motion.WaveMotion`) into
tables once, and evaluates all pairs of a kind in one vectorised pass with
the motions' own kernels (:func:`raysim.motion.at_constant_rate`,
:func:`~raysim.motion.track_index`, :func:`~raysim.motion.lerp`,
:func:`~raysim.motion.wave_angles`): the same numbers as the motions'
``poses``. Any other motion is asked object by object.
"""

from __future__ import annotations

from typing import Sequence

import numpy as np

from raysim.motion import (ConstantVelocity, Motion, SampledTrack, ShipMotion, WaveMotion, at_constant_rate, lerp,
                           track_index, wave_angles)
from raysim.scene.geometry import SPHERE_PAD_M

_MAX_POSE_SAMPLES = 16
"""Maximum number of pose samples per object for its swept sphere."""
_SWEEP_MARGIN_M = 1.0
"""Target motion margin of a swept sphere (more pose samples for long, fast sweeps), metres."""

_KIND_CONSTANT_VELOCITY, _KIND_TRACK, _KIND_OTHER = 0, 1, 2

Pose = tuple[np.ndarray, np.ndarray, "np.ndarray | None", "np.ndarray | None"]
"""position (3, P) metres, yaw (P,), pitch and roll (P,) or None (radians)."""


def _packed_track(m: Motion) -> tuple[SampledTrack | None, WaveMotion | None]:
    """The sampled track (and waves) of a motion the bank packs as a track, else (None, None)."""
    if type(m) is SampledTrack:
        return m, None
    if type(m) is ShipMotion and type(m.track) is SampledTrack and (m.waves is None or type(m.waves) is WaveMotion):
        return m.track, m.waves
    return None, None


class PoseBank:
    """Poses of many moving objects, evaluated together for (object, time) pairs.

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
        self.waves = np.zeros((9, k))  # WaveMotion.params of each object
        samples, base = [], 0
        for i, m in enumerate(motions):
            if type(m) is ConstantVelocity:
                self.kind[i] = _KIND_CONSTANT_VELOCITY
                self.planar[i] = True
                self.cv_position[:, i], self.cv_velocity[:, i] = m.position_m, m.velocity
                self.cv_yaw[i], self.cv_yaw_rate[i] = m.yaw_rad, m.yaw_rate
                continue
            track, waves = _packed_track(m)
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
                self.waves[:, i] = waves.params
            self.planar[i] = waves is None and not track.pitch.any() and not track.roll.any()
        self.tr_samples = np.concatenate(samples, axis=1) if samples else np.zeros((6, 0))
        self.single_kind = k > 0 and bool(np.all(self.kind == self.kind[0]))
        self.all_planar = bool(self.planar.all())

    def poses(self, label: np.ndarray | int, t: np.ndarray) -> Pose:
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
        out = (np.empty((3, p)), np.empty(p), None if planar else np.zeros(p), None if planar else np.zeros(p))
        for kind in kinds:
            idx = None if len(kinds) == 1 else np.flatnonzero(np.take(self.kind, label) == kind)
            lab = np.full(1, int(label)) if one else (label if idx is None else label[idx])  # one: broadcast
            tt = t if idx is None else t[idx]
            sel = slice(None) if idx is None else idx
            if kind == _KIND_CONSTANT_VELOCITY:
                self._constant_velocity(out, sel, lab, tt)
            elif kind == _KIND_TRACK:
                self._tracks(out, sel, lab, tt, one)
            else:
                self._others(out, idx, lab, tt, one)
        return out

    def _constant_velocity(self, out: Pose, sel: slice | np.ndarray, lab: np.ndarray, tt: np.ndarray) -> None:
        """Fill pairs ``sel`` of ``out`` for constant-velocity objects ``lab`` (P,) at times ``tt`` (P,)."""
        out[0][:, sel] = at_constant_rate(self.cv_position, self.cv_velocity, tt, which=lab)
        out[1][sel] = at_constant_rate(self.cv_yaw, self.cv_yaw_rate, tt, which=lab)

    def _tracks(self, out: Pose, sel: slice | np.ndarray, lab: np.ndarray, tt: np.ndarray, one: bool) -> None:
        """Fill pairs ``sel`` of ``out`` for sampled-track objects (``one``: ``lab`` is one label for all)."""
        i, f = track_index(tt, np.take(self.tr_dt, lab), np.take(self.tr_last, lab), np.take(self.tr_imax, lab))
        i += np.take(self.tr_base, lab)
        b = np.take(self.tr_samples, i + 1, axis=1)
        v = lerp(np.take(self.tr_samples, i, axis=1), b, f, out=b)  # (6, P)
        if one:
            w = slice(None) if self.has_waves[lab[0]] else None
            wp = self.waves[:, lab[0] : lab[0] + 1]
        else:
            w = np.flatnonzero(np.take(self.has_waves, lab))
            w = w if w.size else None
            wp = None if w is None else np.take(self.waves, lab[w], axis=1)
        if w is not None:  # ShipMotion.poses: the waves on top of the track
            roll, pitch, heave = wave_angles(wp, tt[w])
            v[5, w] = v[5, w] + roll
            v[4, w] = v[4, w] + pitch
            v[2, w] += heave
        out[0][:, sel] = v[:3]
        out[1][sel] = v[3]
        if out[2] is not None:
            out[2][sel], out[3][sel] = v[4], v[5]

    def _others(self, out: Pose, idx: np.ndarray | None, lab: np.ndarray, tt: np.ndarray, one: bool) -> None:
        """Fill pairs ``idx`` (all if None) of ``out`` by asking each other motion for its poses."""
        position, yaw, pitch, roll = out
        groups = [(int(lab[0]), np.arange(tt.size))] if one else [(m, np.flatnonzero(lab == m)) for m in np.unique(lab).tolist()]
        for m, j in groups:
            pose = self.motions[m].poses(tt[j])
            rows = j if idx is None else idx[j]
            position[:, rows] = pose.position_m.T
            yaw[rows] = pose.yaw_rad
            if pitch is not None:
                pitch[rows], roll[rows] = pose.pitch_rad, pose.roll_rad


def swept_spheres(
    bank: PoseBank, speeds: np.ndarray, mesh_radii: np.ndarray, tmin: float, tmax: float
) -> tuple[np.ndarray, np.ndarray]:
    """Bounding spheres of K moving bodies over ``[tmin, tmax]`` (all bodies at once).

    Each span is cut into k equal parts (more for fast bodies and long spans, at
    most :data:`_MAX_POSE_SAMPLES`) and the pose is sampled at their middles:
    within a part the body origin stays within ``speed * span / (2 k)`` of its
    middle sample.

    Parameters
    ----------
    bank : PoseBank
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
    radius += SPHERE_PAD_M + 1e-6 * (radius + np.abs(centre).max(axis=0))
    return np.ascontiguousarray(centre.T), radius

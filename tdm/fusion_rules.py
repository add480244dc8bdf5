"""The rules that fuse several estimates of one object: Simple Fusion (thesis eq. 3.2) and covariance
intersection (:mod:`tdm.fusion`), with the velocities averaged as course and speed (the speed made non-negative
first) or as east and north velocity (:func:`velocity_frame`), and velocities an AIS track rules out left out
(:func:`without_stray_velocities`)."""

from __future__ import annotations

import numpy as np

from tdm import ekf

__all__ = ["VELOCITY_FRAMES", "apart_covariances", "apart_members", "canonical_states", "consider_covariance",
           "from_cartesian", "fuse", "to_cartesian", "velocity_frame", "without_stray_velocities"]


#: What ``FusionConfig.fuse_velocity`` may say (:func:`velocity_frame`).
VELOCITY_FRAMES = ("polar", "cartesian", "cartesian_without_ais")


def velocity_frame(setting: str, sensors) -> str:
    """The frame :func:`fuse` averages the velocities of estimates from ``sensors`` in, by ``setting``
    (:data:`VELOCITY_FRAMES`): ``cartesian_without_ais`` is ``polar`` where an AIS track is among them (it measures
    the ship's course and speed, so its errors are Gaussian in those, and the course it gives a slow ship holds
    where an east-north average with a radar or LiDAR velocity a few tenths of a m/s off would turn it), else
    ``cartesian``."""
    if setting == "cartesian_without_ais":
        return "polar" if "ais" in sensors else "cartesian"
    return setting


def fuse(xs: np.ndarray, ps: np.ndarray, rule: str = "simple",
         velocity: str = "polar", apart: bool | np.ndarray = False) -> tuple[np.ndarray, np.ndarray]:
    """Fuse K estimates of one object.

    Parameters
    ----------
    xs : (K, 6) float
    ps : (K, 6, 6) float
    rule : {"simple", "ci"}
    velocity : {"polar", "cartesian"}
        Fuse the velocities as course and speed, or as east and north velocity (:func:`to_cartesian`; the
        result turned back to course and speed, :func:`from_cartesian`). Course and speed average the speeds
        of a still object's estimates, each of them the size of its error and so too high, whatever their
        directions; east and north average the errors themselves.
    apart : bool or (K,) bool
        Enter these estimates (all, with True) as their position's marginal and their motion's (course, speed, turn
        rate, size), independent (:func:`apart_covariances`): a difference between their positions and the others'
        does not move the fused velocity through their own position-velocity cross-covariance. False: each
        estimate whole.

    Returns
    -------
    x : (6,) float
    p : (6, 6) float
    """
    if len(xs) == 1:
        return xs[0].copy(), ps[0].copy()
    ps = apart_covariances(ps, apart)
    if velocity == "cartesian":
        ys, qs = to_cartesian(xs, ps)
        infos, q = _weighted_informations(qs, rule)
        y = q @ np.einsum("kij,kj->i", infos, ys)
        x, p = from_cartesian(y, 0.5 * (q + q.T))
        return x, 0.5 * (p + p.T)
    if velocity != "polar":
        raise ValueError(f"unknown velocity frame {velocity!r}")
    xs, ps = canonical_states(xs, ps)
    ref = xs[0, ekf.PSI]
    xs[:, ekf.PSI] = ref + ekf.wrap_pi(xs[:, ekf.PSI] - ref)  # angles relative to one branch
    infos, p = _weighted_informations(ps, rule)
    x = p @ np.einsum("kij,kj->i", infos, xs)
    x[ekf.PSI] = ekf.wrap_pi(x[ekf.PSI])
    return x, 0.5 * (p + p.T)


#: Smallest speed the course's uncertainty is scaled by, turning a state to or from east and north velocity, m/s:
#: a still estimate's course is not known, and its velocity's covariance must stay invertible.
CARTESIAN_SPEED_FLOOR_MPS = 0.05


def to_cartesian(xs: np.ndarray, ps: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Estimates with course and speed (:mod:`tdm.ekf`) turned to east and north velocity.

    ``[e, n, psi, u, r, alpha]`` -> ``[e, n, u sin psi, u cos psi, r, alpha]``, the covariance through the
    Jacobian at the estimate, the course's column scaled by the speed's size, not under
    :data:`CARTESIAN_SPEED_FLOOR_MPS`.

    Parameters
    ----------
    xs : (K, 6) float
    ps : (K, 6, 6) float

    Returns
    -------
    ys : (K, 6) float
    qs : (K, 6, 6) float
    """
    xs, ps = np.asarray(xs, dtype=float), np.asarray(ps, dtype=float)
    psi, u = xs[:, ekf.PSI], xs[:, ekf.U]
    sin, cos = np.sin(psi), np.cos(psi)
    lever = np.copysign(np.maximum(np.abs(u), CARTESIAN_SPEED_FLOOR_MPS), u)
    ys = xs.copy()
    ys[:, ekf.PSI], ys[:, ekf.U] = u * sin, u * cos
    jac = np.broadcast_to(np.eye(ekf.N_STATES), ps.shape).copy()
    jac[:, ekf.PSI, ekf.PSI], jac[:, ekf.PSI, ekf.U] = lever * cos, sin
    jac[:, ekf.U, ekf.PSI], jac[:, ekf.U, ekf.U] = -lever * sin, cos
    return ys, jac @ ps @ jac.transpose(0, 2, 1)


def from_cartesian(y: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """One estimate with east and north velocity (:func:`to_cartesian`) turned back to course and speed (>= 0).

    Parameters
    ----------
    y : (6,) float
    q : (6, 6) float

    Returns
    -------
    x : (6,) float
    p : (6, 6) float
    """
    ve, vn = float(y[ekf.PSI]), float(y[ekf.U])
    speed = float(np.hypot(ve, vn))
    x = np.array(y, dtype=float)
    x[ekf.PSI], x[ekf.U] = ekf.wrap_pi(np.arctan2(ve, vn)), speed
    lever = max(speed, CARTESIAN_SPEED_FLOOR_MPS)
    sin, cos = (ve / speed, vn / speed) if speed > 0.0 else (0.0, 1.0)
    jac = np.eye(ekf.N_STATES)
    jac[ekf.PSI, ekf.PSI], jac[ekf.PSI, ekf.U] = cos / lever, -sin / lever
    jac[ekf.U, ekf.PSI], jac[ekf.U, ekf.U] = sin, cos
    return x, jac @ q @ jac.T


def apart_members(sensors, setting: tuple[str, ...]) -> np.ndarray:
    """(K,) bool: which of the estimates of ``sensors`` (K sensor names, in order) :func:`fuse` takes apart
    (``FusionConfig.fuse_position_apart``, the sensors named in ``setting``)."""
    return np.array([s in setting for s in sensors], dtype=bool)


def apart_covariances(ps: np.ndarray, which: bool | np.ndarray = True) -> np.ndarray:
    """Covariances (K, 6, 6) with the cross-covariance of the position (east, north) and the rest of the state set to
    zero for the estimates ``which`` (True: all; (K,) bool): each as its position's marginal and its motion's,
    independent (:func:`fuse`, ``apart``); ``ps`` itself where none is.

    A per-sensor track's position carries a bias its filter does not model (the side a LiDAR or radar sees, the
    point of a hull its plots paint), and its filter's cross-covariance says how its velocity would move with its
    position's noise, not with that bias: fused as one state, two tracks' positions 10 m apart turn each other's
    velocities by a few tenths of a m/s (busy_open_sea seed 1: a berg's radar track on its face, 10 m from its LiDAR
    track, put the fused east velocity 0.3-0.4 m/s off westward where the LiDAR's erred by under 0.1 and the radar's
    by 0.2-0.3 eastward). An AIS track's position error between reports, by contrast, is mostly its velocity's error
    carried on, which its cross-covariance says: taken apart, a ship at anchor (a report every 3 minutes) lost what the
    radar's velocity tells of its position (harbour_approach 31: fused NEES in its interval 0.818 -> 0.784), so the
    AIS's stays whole (``FusionConfig.fuse_position_apart``).
    """
    which = np.broadcast_to(np.asarray(which, dtype=bool), np.shape(ps)[:1])
    if not which.any():
        return ps
    out = np.array(ps, dtype=float, copy=True)
    out[which, :2, 2:] = 0.0
    out[which, 2:, :2] = 0.0
    return out


def _weighted_informations(ps: np.ndarray, rule: str) -> tuple[np.ndarray, np.ndarray]:
    """(K, 6, 6) information of each estimate as ``rule`` weighs it (``ci``: times ``w_k ~ 1 / tr P_k``), and
    (6, 6) the fused covariance, their sum's inverse."""
    infos = np.linalg.inv(ps)
    if rule == "ci":
        w = 1.0 / np.trace(ps, axis1=1, axis2=2)
        w = w / w.sum()
        infos = infos * w[:, None, None]
    elif rule != "simple":
        raise ValueError(f"unknown fusion rule {rule!r}")
    return infos, np.linalg.inv(infos.sum(axis=0))


def consider_covariance(xs: np.ndarray, ps: np.ndarray, position_var_m2: np.ndarray, rule: str = "simple",
                        shared_var_m2: np.ndarray | None = None, shared: np.ndarray | None = None,
                        velocity: str = "polar", apart: bool | np.ndarray = False) -> np.ndarray:
    """Covariance of the error a fusion (:func:`fuse`) takes over from biases of its estimates' positions.

    Each estimate's position may carry a bias its covariance does not hold (a sensor sees the near side of an
    object: where its centre lies is a slowly changing offset, not noise; a "consider" parameter, as in the
    Schmidt-Kalman filter). The fused state is ``x = sum_k W_k x_k`` with ``W_k = P I_k`` (``I_k`` the k-th
    estimate's information, times its weight for ``ci``), so independent biases ``b_k`` of covariance ``V_k``
    (east, north; ``v_k I`` for a variance ``v_k`` per axis) add ``sum_k W_k[:, :2] V_k W_k[:, :2]^T`` to its
    covariance, and one bias ``b`` of covariance ``C`` shared by the estimates in ``shared`` (the own ship's
    navigation error in every track measured from it, :mod:`tdm.nav_bias`) adds ``S C S^T``, ``S = sum_shared
    W_k[:, :2]``; the state itself is not changed.

    Parameters
    ----------
    xs : (K, 6) float
    ps : (K, 6, 6) float
        The estimates fused, as given to :func:`fuse`.
    position_var_m2 : (K,) or (K, 2, 2) float
        Variance of each estimate's position bias per axis, m^2, or its covariance (east, north), m^2.
    rule : {"simple", "ci"}
    shared_var_m2 : (2, 2) float, optional
        Covariance of the shared bias, m^2; None: none.
    shared : (K,) bool, optional
        Which estimates carry the shared bias; None: all.
    velocity : {"polar", "cartesian"}
    apart : bool or (K,) bool
        As given to :func:`fuse`.

    Returns
    -------
    (6, 6) float
    """
    v = np.asarray(position_var_m2, dtype=float)
    if v.ndim == 1:
        v = v[:, None, None] * np.eye(2)
    mask = np.ones(len(xs), dtype=bool) if shared is None else np.asarray(shared, dtype=bool)
    if len(xs) == 1:
        out = np.zeros((ekf.N_STATES, ekf.N_STATES))
        out[:2, :2] = v[0] + (shared_var_m2 if shared_var_m2 is not None and mask[0] else 0.0)
        return out
    ps = apart_covariances(ps, apart)
    if velocity == "cartesian":
        ys, qs = to_cartesian(xs, ps)
        infos, q = _weighted_informations(qs, rule)
    else:
        _, ps = canonical_states(xs, ps)
        infos, q = _weighted_informations(ps, rule)
    cols = np.einsum("ij,kjl->kil", q, infos[:, :, :2])  # (K, 6, 2): W_k[:, :2]
    out = np.einsum("kab,kia,kjb->ij", v, cols, cols)
    if shared_var_m2 is not None and mask.any():
        s = cols[mask].sum(axis=0)  # (6, 2)
        out = out + s @ np.asarray(shared_var_m2, dtype=float) @ s.T
    out = 0.5 * (out + out.T)
    if velocity == "cartesian":  # the velocity's rows and columns back to course and speed, at the fused velocity
        y = q @ np.einsum("kij,kj->i", infos, ys)
        _, out = from_cartesian(y, out)
    return 0.5 * (out + out.T)


def canonical_states(xs: np.ndarray, ps: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The same estimates with a speed >= 0: ``(psi, u)`` and ``(psi + pi, -u)`` are one motion.

    The trackers' filters let the speed go negative (a track started from two plots has its course either
    way); fused with a track of the other sign, the course and speed would average to nonsense and, through
    their correlation with the position, pull the fused position off both tracks (busy_port: 24 m off an AIS
    and a radar track that agreed within 2 m). Flipping the course by pi and the sign of the speed is exact; in
    the covariance it changes the sign of the speed's cross terms (Jacobian ``diag(1, 1, 1, -1, 1, 1)``).

    Parameters
    ----------
    xs : (K, 6) float
    ps : (K, 6, 6) float

    Returns
    -------
    xs, ps : copies, every speed >= 0
    """
    xs, ps = np.array(xs, dtype=float), np.array(ps, dtype=float)
    flip = xs[:, ekf.U] < 0.0
    if flip.any():
        xs[flip, ekf.U] *= -1.0
        xs[flip, ekf.PSI] = ekf.wrap_pi(xs[flip, ekf.PSI] + np.pi)
        sign = np.ones(ekf.N_STATES)
        sign[ekf.U] = -1.0
        ps[flip] = ps[flip] * sign[None, :, None] * sign[None, None, :]
    return xs, ps


#: Variance given to a velocity left out of a fusion (:func:`without_stray_velocities`), (m/s)^2 and rad^2.
LEFT_OUT_VELOCITY_VAR = 1.0e6


def without_stray_velocities(xs: np.ndarray, ps: np.ndarray, anchor: int, gate_chi2: float) -> np.ndarray:
    """(K, 6, 6) ``ps`` with the velocity of every estimate that the ``anchor`` estimate's velocity rules out left
    out: its course and speed given :data:`LEFT_OUT_VELOCITY_VAR` and no correlation with the rest, so that it adds
    its position and cross-section alone to a fusion.

    An estimate's velocity is ruled out when its east and north velocity (:func:`to_cartesian`) lies more than
    ``gate_chi2`` (chi-square, 2 dof) from the anchor's, by their summed covariances. The anchor is the estimate
    whose velocity is measured (an AIS ship's GNSS course and speed) where the others' is inferred from positions
    of a shape that changes as it is seen (a LiDAR cluster's seen side, a radar echo's fragments).

    Parameters
    ----------
    xs : (K, 6) float
    ps : (K, 6, 6) float
    anchor : int
    gate_chi2 : float

    Returns
    -------
    (K, 6, 6) float
        A copy where any velocity is left out, else ``ps`` itself.
    """
    ys, qs = to_cartesian(xs, ps)
    vel = slice(ekf.PSI, ekf.U + 1)
    d = ys[:, vel] - ys[anchor, vel]
    s = qs[:, vel, vel] + qs[anchor, vel, vel]
    d2 = np.einsum("ki,kij,kj->k", d, np.linalg.inv(s), d)
    stray = d2 > gate_chi2
    stray[anchor] = False
    if not stray.any():
        return ps
    out = np.array(ps, dtype=float)
    for idx in (ekf.PSI, ekf.U):
        out[stray, idx, :] = 0.0
        out[stray, :, idx] = 0.0
        out[stray, idx, idx] = LEFT_OUT_VELOCITY_VAR
    return out

"""The thesis's tracked-object model as an extended Kalman filter (docs/reference.md section 5).

State ``x = [east_m, north_m, course_rad, speed_mps, turn_rate_radps, cross_section_m2]`` in the
TDM's local ENU frame (thesis eq. 3.4 without the k_lon/k_lat constants)::

    east'  = u sin(psi)        north' = u cos(psi)        psi' = r
    u'     = w_u               r'     = w_r               alpha' = w_alpha

``psi`` is the course over ground in radians clockwise from north (the direction the position
moves); speed and turn rate are driven by white noise (the slowly varying terms of the thesis,
random-walk limit of its Gauss-Markov processes). Discretisation: the position advances along
the mid-interval course (second order in ``r dt``), with the matching analytic Jacobian. The
process noise is the continuous white noise of the model integrated through the linearised
dynamics over the interval (Van Loan 1978, "Computing integrals involving the matrix
exponential", IEEE TAC 23(3)): speed and turn-rate noise grow the course and position
uncertainty between updates (a 10 s gap in AIS reports: 6.7 m^2 along track from the speed noise
alone, where integrating each state's own noise gave 0.5 m^2).
The covariance update is the Joseph form (Fossen 2011), which stays symmetric and positive
semi-definite under rounding.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

N_STATES = 6
E, N, PSI, U, R, ALPHA = range(N_STATES)
_EYE = np.eye(N_STATES)
_TWO_PI = 2 * np.pi
#: Entries (row, column) of the process noise that can be non-zero, in the order process_covariance forms them.
_Q_ROWS, _Q_COLS = np.array([(E, E), (N, N), (E, N), (E, PSI), (N, PSI), (E, U), (N, U), (E, R), (N, R), (PSI, R),
                             (PSI, PSI), (U, U), (R, R), (ALPHA, ALPHA)]).T


@dataclass(frozen=True)
class ProcessNoise:
    """White-noise intensities of the motion model (engineering defaults, unverified).

    Attributes
    ----------
    position_m2_per_s : float
        Unmodelled position motion (waves, model error), m^2/s.
    course_rad2_per_s : float
        Unmodelled course change, rad^2/s.
    speed_m2_per_s3 : float
        Speed random walk, (m/s)^2/s: 0.02 lets a ship change speed by about 0.5 m/s in 10 s.
    turn_rate_rad2_per_s3 : float
        Turn-rate random walk, (rad/s)^2/s: 1e-4 lets the turn rate reach 1.8 deg/s (one sigma) in
        10 s, as a ship turning at a waypoint does (tuned on the Table 3.2 run: 1e-6 lagged the turns).
    cross_section_m4_per_s : float
        Cross-section drift, m^4/s (aspect changes).
    """

    position_m2_per_s: float = 0.05
    course_rad2_per_s: float = 1e-4
    speed_m2_per_s3: float = 0.02
    turn_rate_rad2_per_s3: float = 1e-4
    cross_section_m4_per_s: float = 20.0


def wrap_pi(angle_rad):
    """Angle(s) wrapped into [-pi, pi)."""
    if isinstance(angle_rad, float) and math.isfinite(angle_rad):  # one angle: Python's float modulo is np.mod's
        return np.float64((angle_rad + math.pi) % _TWO_PI - math.pi)
    return np.mod(np.asarray(angle_rad) + np.pi, 2 * np.pi) - np.pi


def transition(x: np.ndarray, dt_s: float) -> tuple[np.ndarray, np.ndarray]:
    """Propagate one state over ``dt_s``: the predicted state (6,) and the Jacobian F (6, 6)."""
    e, n, psi, u, r, alpha = x.tolist()
    dt = float(dt_s)
    if not math.isfinite(psi + u + r + dt):
        return _transition_array(x, dt_s)
    # the same operations, in the same order, as _transition_array on Python floats (math.sin and math.cos
    # are numpy's, bit for bit: tests/tdm/test_ekf.py)
    mid = psi + 0.5 * r * dt
    s, c = math.sin(mid), math.cos(mid)
    out = np.array([e + dt * u * s, n + dt * u * c, (psi + r * dt + math.pi) % _TWO_PI - math.pi, u, r, alpha])
    f = _EYE.copy()
    f[E, PSI], f[E, U], f[E, R] = dt * u * c, dt * s, 0.5 * dt * dt * u * c
    f[N, PSI], f[N, U], f[N, R] = -dt * u * s, dt * c, -0.5 * dt * dt * u * s
    f[PSI, R] = dt
    return out, f


def _transition_array(x: np.ndarray, dt_s: float) -> tuple[np.ndarray, np.ndarray]:
    """:func:`transition` in numpy operations (the reference; used for non-finite states)."""
    psi, u, r = x[PSI], x[U], x[R]
    mid = psi + 0.5 * r * dt_s
    s, c = np.sin(mid), np.cos(mid)
    out = x.copy()
    out[E] += dt_s * u * s
    out[N] += dt_s * u * c
    out[PSI] = wrap_pi(psi + r * dt_s)
    f = np.eye(N_STATES)
    f[E, PSI], f[E, U], f[E, R] = dt_s * u * c, dt_s * s, 0.5 * dt_s * dt_s * u * c
    f[N, PSI], f[N, U], f[N, R] = -dt_s * u * s, dt_s * c, -0.5 * dt_s * dt_s * u * s
    f[PSI, R] = dt_s
    return out, f


def continuous_dynamics(x: np.ndarray) -> np.ndarray:
    """The model's continuous Jacobian A (6, 6) = d(x')/dx at state ``x`` (x' = A x about it)."""
    psi, u = x[PSI], x[U]
    a = np.zeros((N_STATES, N_STATES))
    a[E, PSI], a[E, U] = u * np.cos(psi), np.sin(psi)
    a[N, PSI], a[N, U] = -u * np.sin(psi), np.cos(psi)
    a[PSI, R] = 1.0
    return a


def noise_density(q: ProcessNoise) -> np.ndarray:
    """Continuous white-noise spectral density Qc (6, 6) of the model (diagonal)."""
    return np.diag([q.position_m2_per_s, q.position_m2_per_s, q.course_rad2_per_s, q.speed_m2_per_s3,
                    q.turn_rate_rad2_per_s3, q.cross_section_m4_per_s])


def process_covariance(x: np.ndarray, dt_s: float, q: ProcessNoise) -> np.ndarray:
    """Discrete process noise Q (6, 6) of state ``x`` over ``dt_s``: int_0^dt e^(A s) Qc e^(A s)^T ds.

    The linearised dynamics are nilpotent (A^3 = 0: turn rate drives course, course and speed
    drive position), so e^(A s) = I + A s + A^2 s^2 / 2 and the integral is a polynomial in dt,
    evaluated exactly here; it equals Van Loan's matrix-exponential form (tests/tdm/test_ekf.py).

    The entries are formed one by one from the few non-zero ones of A (Python floats: the same
    roundings as :func:`_process_covariance_array`, the matrix form, which tests/tdm/test_ekf.py checks
    bit for bit); the one product with two terms per entry goes through the same matrix product as there.
    """
    dt = abs(float(dt_s))
    psi, u = float(x[PSI]), float(x[U])
    if not math.isfinite(psi + u + dt):
        return _process_covariance_array(x, dt_s, q)
    q_pos, q_psi, q_u, q_r, q_alpha = (q.position_m2_per_s, q.course_rad2_per_s, q.speed_m2_per_s3,
                                       q.turn_rate_rad2_per_s3, q.cross_section_m4_per_s)
    dt2, dt3, dt4, dt5 = dt**2, dt**3, dt**4, dt**5
    # A's non-zero entries (A[PSI, R] = 1); A^2's are A2[E, R] = a_ep, A2[N, R] = a_np
    a_ep, a_eu, a_np, a_nu = u * math.cos(psi), math.sin(psi), -u * math.sin(psi), math.cos(psi)
    aq_ep, aq_eu, aq_np, aq_nu = a_ep * q_psi, a_eu * q_u, a_np * q_psi, a_nu * q_u  # A Qc
    a2q_er, a2q_nr = a_ep * q_r, a_np * q_r  # A^2 Qc
    # 2 A Qc A^T: its east/north block sums two products (fused multiply-adds in BLAS: kept a matrix product)
    (m_ee, m_en), (m_ne, m_nn) = _two_term_block(2.0 * aq_ep, 2.0 * aq_eu, 2.0 * aq_np, 2.0 * aq_nu,
                                                 a_ep, a_eu, a_np, a_nu)
    en = 0.5 * ((0.0 + m_en * dt3 / 6.0 + a2q_er * a_np * dt5 / 20.0) + (0.0 + m_ne * dt3 / 6.0 + a2q_nr * a_ep * dt5 / 20.0))
    # the terms of the polynomial, summed in the matrix form's order; 0.5 (out + out^T) leaves these as they are
    # (symmetric bit for bit), but for east/north
    values = [q_pos * dt + m_ee * dt3 / 6.0 + a2q_er * a_ep * dt5 / 20.0,  # (E, E)
              q_pos * dt + m_nn * dt3 / 6.0 + a2q_nr * a_np * dt5 / 20.0,  # (N, N)
              en,  # (E, N)
              0.0 + aq_ep * dt2 / 2.0 + a2q_er * dt4 / 8.0, 0.0 + aq_np * dt2 / 2.0 + a2q_nr * dt4 / 8.0,  # (E|N, PSI)
              0.0 + aq_eu * dt2 / 2.0, 0.0 + aq_nu * dt2 / 2.0,  # (E|N, U)
              0.0 + a2q_er * dt3 / 6.0, 0.0 + a2q_nr * dt3 / 6.0,  # (E|N, R)
              0.0 + q_r * dt2 / 2.0,  # (PSI, R)
              q_psi * dt + 2.0 * q_r * dt3 / 6.0, q_u * dt, q_r * dt, q_alpha * dt]  # diagonal
    out = np.zeros((N_STATES, N_STATES))
    out[_Q_ROWS, _Q_COLS] = values
    out[_Q_COLS, _Q_ROWS] = values
    return out


def _two_term_block(b_ep: float, b_eu: float, b_np: float, b_nu: float,
                    a_ep: float, a_eu: float, a_np: float, a_nu: float) -> list[list[float]]:
    """East/north block (2, 2) of ``B @ A.T`` for (6, 6) matrices whose east and north rows hold only
    the given course (``_ep``, ``_np``) and speed (``_eu``, ``_nu``) entries: BLAS's product of the
    matrix form, with the same padding, so that BLAS runs the same kernel, with the same order of fused
    multiply-adds, as in :func:`_process_covariance_array`."""
    b, a = np.zeros((N_STATES, N_STATES)), np.zeros((N_STATES, N_STATES))
    b[E, PSI], b[E, U], b[N, PSI], b[N, U] = b_ep, b_eu, b_np, b_nu
    a[E, PSI], a[E, U], a[N, PSI], a[N, U] = a_ep, a_eu, a_np, a_nu
    return (b @ a.T)[:2, :2].tolist()


def _process_covariance_array(x: np.ndarray, dt_s: float, q: ProcessNoise) -> np.ndarray:
    """:func:`process_covariance` as matrix products (the reference; used for non-finite states)."""
    dt = abs(dt_s)
    a, qc = continuous_dynamics(x), noise_density(q)
    a2 = a @ a
    aq, a2q = a @ qc, a2 @ qc
    out = (qc * dt + (aq + aq.T) * dt**2 / 2.0 + (a2q + a2q.T + 2.0 * aq @ a.T) * dt**3 / 6.0
           + (a2q @ a.T + a @ a2q.T) * dt**4 / 8.0 + a2q @ a2.T * dt**5 / 20.0)
    return 0.5 * (out + out.T)


def predict(x: np.ndarray, p: np.ndarray, dt_s: float, q: ProcessNoise) -> tuple[np.ndarray, np.ndarray]:
    """EKF prediction of state (6,) and covariance (6, 6) over ``dt_s`` seconds."""
    if dt_s == 0.0:
        return x.copy(), p.copy()
    x_new, f = transition(x, dt_s)
    p_new = f @ p @ f.T + process_covariance(x, dt_s, q)
    return x_new, 0.5 * (p_new + p_new.T)


def predict_many(xs: np.ndarray, ps: np.ndarray, dts_s: list[float], q: ProcessNoise
                 ) -> tuple[np.ndarray, np.ndarray]:
    """:func:`predict` of K states at once, bit for bit (tests/tdm/test_ekf.py).

    Elementwise the same operations as :func:`transition` and :func:`process_covariance` (numpy's sine,
    cosine and modulo are Python's; the powers of the interval taken in Python, as there), the matrix
    products batched (BLAS per matrix, as one by one). A zero interval or a non-finite state is
    predicted one by one.

    Parameters
    ----------
    xs : (K, 6) float
    ps : (K, 6, 6) float
    dts_s : list of K float
        Intervals, s.
    q : ProcessNoise

    Returns
    -------
    xs : (K, 6) float
    ps : (K, 6, 6) float
    """
    x, p = np.asarray(xs, dtype=float), np.asarray(ps, dtype=float)
    dt = np.array(dts_s, dtype=float)
    psi, u, r = x[:, PSI], x[:, U], x[:, R]
    with np.errstate(all="ignore"):  # non-finite states are redone one by one below
        mid = psi + 0.5 * r * dt
        s, c = np.sin(mid), np.cos(mid)
        x_new = x.copy()
        x_new[:, E] = x[:, E] + dt * u * s
        x_new[:, N] = x[:, N] + dt * u * c
        x_new[:, PSI] = (psi + r * dt + math.pi) % _TWO_PI - math.pi
        f = np.repeat(_EYE[None], len(x), axis=0)
        f[:, E, PSI], f[:, E, U], f[:, E, R] = dt * u * c, dt * s, 0.5 * dt * dt * u * c
        f[:, N, PSI], f[:, N, U], f[:, N, R] = -dt * u * s, dt * c, -0.5 * dt * dt * u * s
        f[:, PSI, R] = dt
        p_new = f @ p @ f.transpose(0, 2, 1) + _process_covariances(psi, u, np.abs(dt), q)
        p_new = 0.5 * (p_new + p_new.transpose(0, 2, 1))
    redo = (dt == 0.0) | ~np.isfinite(psi + u + r + dt)
    for k in np.nonzero(redo)[0]:
        x_new[k], p_new[k] = predict(x[k], p[k], dts_s[k], q)
    return x_new, p_new


def _process_covariances(psi: np.ndarray, u: np.ndarray, dt: np.ndarray, q: ProcessNoise) -> np.ndarray:
    """:func:`process_covariance` (K, 6, 6) of K courses and speeds (K,) over |intervals| (K,) s, elementwise
    the same operations."""
    q_pos, q_psi, q_u, q_r, q_alpha = (q.position_m2_per_s, q.course_rad2_per_s, q.speed_m2_per_s3,
                                       q.turn_rate_rad2_per_s3, q.cross_section_m4_per_s)
    dt_list = dt.tolist()
    dt2, dt3, dt4, dt5 = (np.array([d**k for d in dt_list]) for k in (2, 3, 4, 5))
    a_ep, a_eu, a_np, a_nu = u * np.cos(psi), np.sin(psi), -u * np.sin(psi), np.cos(psi)
    aq_ep, aq_eu, aq_np, aq_nu = a_ep * q_psi, a_eu * q_u, a_np * q_psi, a_nu * q_u
    a2q_er, a2q_nr = a_ep * q_r, a_np * q_r
    b, a = np.zeros((len(dt), N_STATES, N_STATES)), np.zeros((len(dt), N_STATES, N_STATES))
    b[:, E, PSI], b[:, E, U], b[:, N, PSI], b[:, N, U] = 2.0 * aq_ep, 2.0 * aq_eu, 2.0 * aq_np, 2.0 * aq_nu
    a[:, E, PSI], a[:, E, U], a[:, N, PSI], a[:, N, U] = a_ep, a_eu, a_np, a_nu
    m = b @ a.transpose(0, 2, 1)
    m_ee, m_en, m_ne, m_nn = m[:, E, E], m[:, E, N], m[:, N, E], m[:, N, N]
    en = 0.5 * ((0.0 + m_en * dt3 / 6.0 + a2q_er * a_np * dt5 / 20.0) + (0.0 + m_ne * dt3 / 6.0 + a2q_nr * a_ep * dt5 / 20.0))
    values = [q_pos * dt + m_ee * dt3 / 6.0 + a2q_er * a_ep * dt5 / 20.0,
              q_pos * dt + m_nn * dt3 / 6.0 + a2q_nr * a_np * dt5 / 20.0,
              en,
              0.0 + aq_ep * dt2 / 2.0 + a2q_er * dt4 / 8.0, 0.0 + aq_np * dt2 / 2.0 + a2q_nr * dt4 / 8.0,
              0.0 + aq_eu * dt2 / 2.0, 0.0 + aq_nu * dt2 / 2.0,
              0.0 + a2q_er * dt3 / 6.0, 0.0 + a2q_nr * dt3 / 6.0,
              0.0 + q_r * dt2 / 2.0,
              q_psi * dt + 2.0 * q_r * dt3 / 6.0, q_u * dt, q_r * dt, q_alpha * dt]
    stacked = np.stack(values, axis=1)
    out = np.zeros((len(dt), N_STATES, N_STATES))
    out[:, _Q_ROWS, _Q_COLS] = stacked
    out[:, _Q_COLS, _Q_ROWS] = stacked
    return out


def velocity_en(x: np.ndarray) -> np.ndarray:
    """Velocity (..., 2) east, north in m/s of states (..., 6): speed along the course."""
    if isinstance(x, np.ndarray) and x.shape == (N_STATES,):  # one state: Python floats, the same roundings
        psi, u = float(x[PSI]), float(x[U])
        if math.isfinite(psi):
            return np.array([u * math.sin(psi), u * math.cos(psi)])
    x = np.asarray(x, dtype=float)
    return x[..., U, None] * np.stack([np.sin(x[..., PSI]), np.cos(x[..., PSI])], axis=-1)


def predict_mean(x: np.ndarray, dt_s: np.ndarray) -> np.ndarray:
    """Predicted states (..., 6) of states (..., 6) over times (...,) s (no covariance; vectorised)."""
    if isinstance(x, np.ndarray) and x.shape == (N_STATES,) and isinstance(dt_s, float):
        e, n, psi, u, r, alpha = x.tolist()
        dt = float(dt_s)
        if math.isfinite(psi + r + dt):  # one state: Python floats, the same roundings as below
            mid = psi + 0.5 * r * dt
            return np.array([e + dt * u * math.sin(mid), n + dt * u * math.cos(mid),
                             (psi + r * dt + math.pi) % _TWO_PI - math.pi, u, r, alpha])
    x = np.asarray(x, dtype=float)
    dt = np.asarray(dt_s, dtype=float)
    mid = x[..., PSI] + 0.5 * x[..., R] * dt
    out = np.array(np.broadcast_to(x, np.broadcast_shapes(x.shape, dt.shape + (N_STATES,))))
    out[..., E] = x[..., E] + dt * x[..., U] * np.sin(mid)
    out[..., N] = x[..., N] + dt * x[..., U] * np.cos(mid)
    out[..., PSI] = wrap_pi(x[..., PSI] + x[..., R] * dt)
    return out


def update(x: np.ndarray, p: np.ndarray, z: np.ndarray, h: np.ndarray, r: np.ndarray,
           angle_rows: tuple[int, ...] = ()) -> tuple[np.ndarray, np.ndarray, float]:
    """Joseph-form Kalman update with a linear measurement ``z = H x + v``.

    Parameters
    ----------
    x : (6,) float
    p : (6, 6) float
    z : (M,) float
        Measurement.
    h : (M, 6) float
        Measurement matrix.
    r : (M, M) float
        Measurement covariance.
    angle_rows : tuple of int
        Rows of ``z`` that are angles in radians: their residuals are wrapped.

    Returns
    -------
    x : (6,) float
    p : (6, 6) float
    nis : float
        Normalised innovation squared of this update.
    """
    y = z - h @ x
    for row in angle_rows:
        y[row] = wrap_pi(y[row])
    s = h @ p @ h.T + r
    s_inv = np.linalg.inv(s)
    k = p @ h.T @ s_inv
    x_new = x + k @ y
    x_new[PSI] = wrap_pi(x_new[PSI])
    i_kh = _EYE - k @ h
    p_new = i_kh @ p @ i_kh.T + k @ r @ k.T
    return x_new, 0.5 * (p_new + p_new.T), float(y @ s_inv @ y)


#: Position and cross-section measurement of LiDAR clusters and radar plots.
H_POSITION_SIZE = np.zeros((3, N_STATES))
H_POSITION_SIZE[0, E] = H_POSITION_SIZE[1, N] = H_POSITION_SIZE[2, ALPHA] = 1.0


def h_rows(*states: int) -> np.ndarray:
    """(M, 6) measurement matrix that picks the given states."""
    out = np.zeros((len(states), N_STATES))
    out[np.arange(len(states)), list(states)] = 1.0
    return out

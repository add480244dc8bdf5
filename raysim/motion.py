"""Motion of bodies: stationary, constant velocity, waypoint tracks, trajectories, waves.

Every motion answers for an array of times (each sensor ray asks for its own
instant). All motions implement :class:`Motion`.
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np

from raysim.pose import Poses


@runtime_checkable
class Motion(Protocol):
    """What the scene and the sensors need to know about a moving body."""

    max_speed_mps: float
    """Upper bound of the speed of the body origin (translation incl. heave), m/s."""

    def poses(self, t_s: np.ndarray) -> Poses:
        """Poses at the (N,) times ``t_s`` (seconds since scenario start)."""
        ...

    def velocity_mps(self, t_s: np.ndarray) -> np.ndarray:
        """(N, 3) ENU velocity of the body origin, m/s."""
        ...

    def yaw_rate_rps(self, t_s: np.ndarray) -> np.ndarray:
        """(N,) yaw rate, rad/s, counter-clockwise positive."""
        ...


class Stationary:
    """A body that never moves.

    Parameters
    ----------
    position_m : (3,) float
        ENU position of the body origin, metres.
    yaw_rad : float
        ENU yaw, radians.
    """

    max_speed_mps = 0.0

    def __init__(self, position_m, yaw_rad: float = 0.0):
        self.position_m = np.asarray(position_m, dtype=float).reshape(3)
        self.yaw_rad = float(yaw_rad)

    def poses(self, t_s: np.ndarray) -> Poses:
        n = np.shape(t_s)[0] if np.ndim(t_s) else 1
        zeros = np.zeros(n)
        return Poses(np.broadcast_to(self.position_m, (n, 3)).copy(), zeros + self.yaw_rad, zeros, zeros.copy())

    def velocity_mps(self, t_s: np.ndarray) -> np.ndarray:
        return np.zeros((np.shape(t_s)[0] if np.ndim(t_s) else 1, 3))

    def yaw_rate_rps(self, t_s: np.ndarray) -> np.ndarray:
        return np.zeros(np.shape(t_s)[0] if np.ndim(t_s) else 1)


class ConstantVelocity:
    """A body moving in a straight line at constant velocity, optionally yawing at a constant rate.

    Parameters
    ----------
    position_m : (3,) float
        ENU position at t = 0, metres.
    velocity_mps : (3,) float
        ENU velocity, m/s.
    yaw_rad : float
        ENU yaw at t = 0, radians.
    yaw_rate_rps : float
        Constant yaw rate, rad/s.
    """

    def __init__(self, position_m, velocity_mps, yaw_rad: float = 0.0, yaw_rate_rps: float = 0.0):
        self.position_m = np.asarray(position_m, dtype=float).reshape(3)
        self.velocity = np.asarray(velocity_mps, dtype=float).reshape(3)
        self.yaw_rad = float(yaw_rad)
        self.yaw_rate = float(yaw_rate_rps)
        self.max_speed_mps = float(np.linalg.norm(self.velocity))

    def poses(self, t_s: np.ndarray) -> Poses:
        t = np.atleast_1d(np.asarray(t_s, dtype=float))
        zeros = np.zeros(t.shape[0])
        position = at_constant_rate(self.position_m, self.velocity, t[:, None])
        return Poses(position, at_constant_rate(self.yaw_rad, self.yaw_rate, t), zeros, zeros.copy())

    def velocity_mps(self, t_s: np.ndarray) -> np.ndarray:
        return np.broadcast_to(self.velocity, (np.atleast_1d(t_s).shape[0], 3)).copy()

    def yaw_rate_rps(self, t_s: np.ndarray) -> np.ndarray:
        return np.full(np.atleast_1d(t_s).shape[0], self.yaw_rate)


# --------------------------------------------------------------------------- sampled tracks

#: Time step of precomputed tracks, s. Poses between samples are interpolated
#: linearly (position, unwrapped yaw); 0.05 s keeps the interpolation error of a
#: turning 30 kn ship below 1 mm.
TRACK_DT_S = 0.05


class SampledTrack:
    """A planar track sampled on a uniform time grid, interpolated for any times.

    Parameters
    ----------
    dt_s : float
        Grid step, s; sample k is at ``k * dt_s``.
    x_m, y_m : (K,) float
        ENU position, metres.
    yaw_rad : (K,) float
        Continuous (unwrapped) ENU yaw, radians.
    speed_mps : (K,) float, optional
        Speed along the heading; default: from finite differences of the positions.
    yaw_rate_rps : (K,) float, optional
        Yaw rate; default: finite differences of yaw.
    roll_rad, pitch_rad, z_m : (K,) float, optional
        FLU roll and pitch and heave, if the track carries them (trajectory files).

    Times before 0 or after the last sample hold the end poses.
    """

    def __init__(self, dt_s, x_m, y_m, yaw_rad, speed_mps=None, yaw_rate_rps=None, roll_rad=None, pitch_rad=None, z_m=None):
        self.dt_s = float(dt_s)
        self.x = np.asarray(x_m, dtype=float)
        self.y = np.asarray(y_m, dtype=float)
        self.yaw = np.asarray(yaw_rad, dtype=float)
        n = self.x.shape[0]
        self.z = np.zeros(n) if z_m is None else np.asarray(z_m, dtype=float)
        self.roll = np.zeros(n) if roll_rad is None else np.asarray(roll_rad, dtype=float)
        self.pitch = np.zeros(n) if pitch_rad is None else np.asarray(pitch_rad, dtype=float)
        if speed_mps is None:
            vx = np.gradient(self.x, self.dt_s) if n > 1 else np.zeros(n)
            vy = np.gradient(self.y, self.dt_s) if n > 1 else np.zeros(n)
            self.vx, self.vy = vx, vy
        else:
            speed = np.asarray(speed_mps, dtype=float)
            self.vx, self.vy = speed * np.cos(self.yaw), speed * np.sin(self.yaw)
        self.vz = np.gradient(self.z, self.dt_s) if n > 1 else np.zeros(n)
        self.yaw_rate = (np.gradient(self.yaw, self.dt_s) if n > 1 else np.zeros(n)) if yaw_rate_rps is None else np.asarray(yaw_rate_rps, dtype=float)
        self.max_speed_mps = float(np.sqrt(self.vx**2 + self.vy**2 + self.vz**2).max()) * 1.001 + 1e-9
        self.duration_s = (n - 1) * self.dt_s

    def _index(self, t_s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        n = self.x.shape[0]
        return track_index(np.atleast_1d(np.asarray(t_s, dtype=float)), self.dt_s, n - 1, max(n - 2, 0))

    def _lerp(self, a: np.ndarray, i: np.ndarray, f: np.ndarray) -> np.ndarray:
        if a.shape[0] == 1:
            return np.full(i.shape[0], a[0])
        return lerp(a[i], a[i + 1], f)

    def poses(self, t_s: np.ndarray) -> Poses:
        i, f = self._index(t_s)
        position = np.stack([self._lerp(self.x, i, f), self._lerp(self.y, i, f), self._lerp(self.z, i, f)], axis=1)
        return Poses(position, self._lerp(self.yaw, i, f), self._lerp(self.pitch, i, f), self._lerp(self.roll, i, f))

    def velocity_mps(self, t_s: np.ndarray) -> np.ndarray:
        i, f = self._index(t_s)
        return np.stack([self._lerp(self.vx, i, f), self._lerp(self.vy, i, f), self._lerp(self.vz, i, f)], axis=1)

    def yaw_rate_rps(self, t_s: np.ndarray) -> np.ndarray:
        i, f = self._index(t_s)
        return self._lerp(self.yaw_rate, i, f)


def _wrap_pi(a):
    return (np.asarray(a) + np.pi) % (2 * np.pi) - np.pi


def wheel_over_distance_m(turn_rad: float, speed_mps: float, time_constant_s: float) -> float:
    """Distance before a waypoint at which a first-order heading response must start.

    With the heading ``h(t) = turn * (1 - exp(-t / T))`` after the switch (leg along +x),
    the ship's path approaches a straight line parallel to the next leg; starting the
    turn this far before the waypoint makes that line the next leg itself.

    Parameters
    ----------
    turn_rad : float
        Signed course change, radians, in (-pi, pi].
    speed_mps, time_constant_s : float
        Ship speed and heading time constant.
    """
    if abs(turn_rad) < 1e-9 or speed_mps <= 0:
        return 0.0
    u = np.linspace(0.0, 40.0, 8001)
    h = turn_rad * (1.0 - np.exp(-u))
    ox = speed_mps * time_constant_s * np.trapezoid(np.cos(h) - np.cos(turn_rad), u)
    oy = speed_mps * time_constant_s * np.trapezoid(np.sin(h) - np.sin(turn_rad), u)
    if abs(np.sin(turn_rad)) < 1e-6:
        return float("inf")
    return float(ox - oy * np.cos(turn_rad) / np.sin(turn_rad))


def waypoint_track(
    waypoints_m: np.ndarray,
    speed_mps: float,
    duration_s: float,
    heading_time_constant_s: float,
    at_end: str = "continue",
    heading_rad: float | None = None,
    dt_s: float = TRACK_DT_S,
) -> SampledTrack:
    """A ship on waypoints at constant speed with a first-order heading response in turns.

    The heading obeys ``dh/dt = (c - h) / T`` with ``c`` the course of the active
    leg; the switch to the next leg happens at the wheel-over point
    (:func:`wheel_over_distance_m`), so the ship settles onto each leg instead of
    overshooting it. The track is integrated once on a ``dt_s`` grid (heading
    exact, position with the mid-step heading), covering ``duration_s`` plus 10 s.

    Parameters
    ----------
    waypoints_m : (K, 2) float
        Waypoints in local metres (x east, y north).
    speed_mps : float
        Constant speed; 0 (or a single waypoint) gives a ship lying still at the first waypoint.
    duration_s : float
        Time to cover, s.
    heading_time_constant_s : float
        T, s.
    at_end : {"continue", "stop", "loop"}
        Behaviour after the last waypoint.
    heading_rad : float, optional
        ENU yaw of a ship lying still (default: first leg's course, or 0).
    """
    wp = np.asarray(waypoints_m, dtype=float).reshape(-1, 2)
    n_steps = int(np.ceil((duration_s + 10.0) / dt_s)) + 1
    if speed_mps <= 0 or wp.shape[0] == 1:
        return _still_track(wp, heading_rad, dt_s)
    legs = [(wp[i], wp[i + 1]) for i in range(wp.shape[0] - 1)]
    if at_end == "loop":
        legs.append((wp[-1], wp[0]))
    T = float(heading_time_constant_s)
    U = float(speed_mps)
    xs, ys, hs, rs, us = [np.array([wp[0, 0]])], [np.array([wp[0, 1]])], [], [], []
    p = wp[0].copy()
    h = float(np.arctan2(legs[0][1][1] - legs[0][0][1], legs[0][1][0] - legs[0][0][0]))
    hs.append(np.array([h]))
    rs.append(np.array([0.0]))
    us.append(np.array([U]))
    steps_done = 0
    leg_index = 0
    while steps_done < n_steps - 1:
        a, b = legs[leg_index % len(legs)]
        length = float(np.hypot(*(b - a)))
        along_unit = (b - a) / length
        course = h + float(_wrap_pi(np.arctan2(along_unit[1], along_unit[0]) - h))
        is_last = leg_index == len(legs) - 1 and at_end != "loop"
        switch_at = _switch_at_m(legs, leg_index, is_last, at_end, length, along_unit, U, T)
        remaining = n_steps - 1 - steps_done
        window = min(remaining, int(np.ceil(((max(length, 1.0) + U * T) / U + 5 * T) / dt_s)) + 2)
        heading, px, py = _steer(p, h, course, U, T, dt_s, window)
        along = (px - a[0]) * along_unit[0] + (py - a[1]) * along_unit[1]
        reached = np.nonzero(along >= switch_at)[0]
        k = int(reached[0]) + 1 if reached.size else window
        if is_last and at_end == "stop" and reached.size:
            xs.append(px[:k]), ys.append(py[:k]), hs.append(heading[:k]), rs.append((course - heading[:k]) / T), us.append(np.full(k, U))
            steps_done += k
            rest = n_steps - 1 - steps_done
            if rest > 0:
                xs.append(np.full(rest, px[k - 1])), ys.append(np.full(rest, py[k - 1]))
                hs.append(np.full(rest, heading[k - 1])), rs.append(np.zeros(rest)), us.append(np.zeros(rest))
                steps_done += rest
            break
        xs.append(px[:k]), ys.append(py[:k]), hs.append(heading[:k]), rs.append((course - heading[:k]) / T), us.append(np.full(k, U))
        steps_done += k
        p = np.array([px[k - 1], py[k - 1]])
        h = float(heading[k - 1])
        if reached.size:
            leg_index += 1
    cat = np.concatenate
    return SampledTrack(dt_s, cat(xs), cat(ys), cat(hs), speed_mps=cat(us), yaw_rate_rps=cat(rs))


def _still_track(wp: np.ndarray, heading_rad: float | None, dt_s: float) -> SampledTrack:
    """A ship lying still at the first waypoint, heading ``heading_rad`` (default: the first leg's course, or 0)."""
    if heading_rad is None:
        heading_rad = float(np.arctan2(*(wp[1] - wp[0])[::-1])) if wp.shape[0] > 1 else 0.0
    ones = np.ones(1)
    return SampledTrack(dt_s, wp[0, 0] * ones, wp[0, 1] * ones, heading_rad * ones, speed_mps=0 * ones, yaw_rate_rps=0 * ones)


def _switch_at_m(legs: list, leg_index: int, is_last: bool, at_end: str, length: float, along_unit: np.ndarray,
                 speed_mps: float, time_constant_s: float) -> float:
    """Distance along the active leg at which the ship turns onto the next: the wheel-over point.

    On the last leg: its end for ``stop``, never for ``continue``.
    """
    if is_last:
        return length if at_end == "stop" else np.inf
    na, nb = legs[(leg_index + 1) % len(legs)]
    next_unit = (nb - na) / np.hypot(*(nb - na))
    turn = float(_wrap_pi(np.arctan2(next_unit[1], next_unit[0]) - np.arctan2(along_unit[1], along_unit[0])))
    next_length = float(np.hypot(*(nb - na)))
    return length - min(max(wheel_over_distance_m(turn, speed_mps, time_constant_s), 0.0), length, next_length)


def _steer(p: np.ndarray, h0: float, course: float, speed_mps: float, time_constant_s: float, dt_s: float,
           window: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``window`` steps from position ``p`` and heading ``h0`` towards ``course``: headings (exact) and
    positions (x, y; each step at its mid-step heading)."""
    j = np.arange(1, window + 1)
    heading = course + (h0 - course) * np.exp(-j * dt_s / time_constant_s)
    mid = course + (h0 - course) * np.exp(-(j - 0.5) * dt_s / time_constant_s)
    px = p[0] + speed_mps * dt_s * np.cumsum(np.cos(mid))
    py = p[1] + speed_mps * dt_s * np.cumsum(np.sin(mid))
    return heading, px, py


# --------------------------------------------------------------------------- waves and bodies


class WaveMotion:
    """Wave-induced roll, pitch and heave: one sinusoid each, with seeded phases.

    Parameters
    ----------
    roll_amplitude_deg, pitch_amplitude_deg : float
        Amplitudes, degrees (marine convention: pitch positive bow up).
    heave_amplitude_m : float
        Heave amplitude, metres.
    roll_period_s, pitch_period_s, heave_period_s : float
        Periods, s.
    rng : numpy.random.Generator
        Draws the three phases (the own ship's named stream).
    """

    def __init__(self, roll_amplitude_deg, roll_period_s, pitch_amplitude_deg, pitch_period_s, heave_amplitude_m, heave_period_s, rng):
        self.roll = (np.radians(roll_amplitude_deg), 2 * np.pi / roll_period_s)
        self.pitch = (np.radians(pitch_amplitude_deg), 2 * np.pi / pitch_period_s)
        self.heave = (float(heave_amplitude_m), 2 * np.pi / heave_period_s)
        self.phases = rng.uniform(0.0, 2 * np.pi, size=3)
        self.max_heave_speed_mps = self.heave[0] * self.heave[1]
        #: (9,) amplitude, angular frequency (rad/s) and phase (rad) of roll, pitch (marine) and heave
        self.params = np.array([*self.roll, self.phases[0], *self.pitch, self.phases[1], *self.heave, self.phases[2]])

    def angles(self, t_s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(roll_rad FLU, pitch_rad FLU, heave_m), each (N,)."""
        return wave_angles(self.params, np.atleast_1d(np.asarray(t_s, dtype=float)))

    def heave_rate_mps(self, t_s: np.ndarray) -> np.ndarray:
        t = np.atleast_1d(np.asarray(t_s, dtype=float))
        return self.heave[0] * self.heave[1] * np.cos(self.heave[1] * t + self.phases[2])


class ShipMotion:
    """A planar track plus wave-induced roll, pitch and heave."""

    def __init__(self, track: SampledTrack, waves: WaveMotion | None = None):
        self.track = track
        self.waves = waves
        self.max_speed_mps = track.max_speed_mps + (waves.max_heave_speed_mps if waves else 0.0)

    def poses(self, t_s: np.ndarray) -> Poses:
        base = self.track.poses(t_s)
        if self.waves is None:
            return base
        roll, pitch, heave = self.waves.angles(t_s)
        position = base.position_m.copy()
        position[:, 2] += heave
        return Poses(position, base.yaw_rad, base.pitch_rad + pitch, base.roll_rad + roll)

    def velocity_mps(self, t_s: np.ndarray) -> np.ndarray:
        v = self.track.velocity_mps(t_s)
        if self.waves is not None:
            v[:, 2] += self.waves.heave_rate_mps(t_s)
        return v

    def yaw_rate_rps(self, t_s: np.ndarray) -> np.ndarray:
        return self.track.yaw_rate_rps(t_s)


# --------------------------------------------------------------------------- vectorised kernels
# The arithmetic of the motions, for one body or for many at once (one parameter
# set per time): the motions below use these, and so does the ray engine's pose
# bank (raysim.scene.poses), which evaluates all bodies of a kind in one pass.


def at_constant_rate(x0, rate, t_s, which=None):
    """``x0 + rate t``: a position (metres, rate in m/s) or a yaw (radians, rate in rad/s) at times ``t_s``.

    Parameters
    ----------
    x0, rate : float or array
        Value at t = 0 and its rate of change. Without ``which``: one body's, shaped to
        broadcast with ``t_s`` ((3,) positions against (N, 1) times). With ``which``:
        tables of K bodies, (K,) or (3, K), the body in the last axis.
    t_s : array
        Times, seconds.
    which : (N,) int, optional
        The body of each time (a column of the tables).

    Returns
    -------
    array
        The broadcast shape ((N,) or (3, N) with ``which``), float64.
    """
    v = (rate if which is None else np.take(rate, which, axis=-1)) * t_s
    v += x0 if which is None else np.take(x0, which, axis=-1)
    return v


def track_index(t_s: np.ndarray, dt_s, last, i_max) -> tuple[np.ndarray, np.ndarray]:
    """Sample index and fraction of times on uniform grids (times outside hold the end samples).

    Parameters
    ----------
    t_s : (N,) float64
        Times, seconds.
    dt_s : float or (N,) float64
        Grid step, seconds.
    last : int or (N,) float
        Index of the last sample (``n - 1``).
    i_max : int or (N,) int64
        Largest left index of an interval (``max(n - 2, 0)``).

    Returns
    -------
    i : (N,) int64
        Left sample of each time's interval.
    f : (N,) float64
        Fraction in [0, 1] (may reach 1 at the last sample).
    """
    u = np.clip(t_s / dt_s, 0.0, last)
    i = np.minimum(u.astype(np.int64), i_max)
    return i, u - i


def lerp(a: np.ndarray, b: np.ndarray, f: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
    """Linear interpolation ``a + (b - a) f`` (``b - a`` of the result's shape; ``f`` broadcast).

    ``out`` (may be ``b``) receives the result; a new array if None.
    """
    v = np.subtract(b, a, out=out)
    v *= f
    v += a
    return v


def wave_angles(params: np.ndarray, t_s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Wave-induced roll, pitch and heave: one sinusoid each.

    Parameters
    ----------
    params : (9,) or (9, N) float64
        Amplitude, angular frequency (rad/s) and phase (rad) of roll (radians), pitch
        (radians, marine: positive bow up) and heave (metres), as :attr:`WaveMotion.params`.
    t_s : (N,) float64
        Times, seconds.

    Returns
    -------
    roll_rad, pitch_rad, heave_m : (N,) float64
        FLU roll and pitch (the marine pitch's sign flipped), heave.
    """
    roll = params[0] * np.sin(params[1] * t_s + params[2])
    pitch_marine = params[3] * np.sin(params[4] * t_s + params[5])
    heave = params[6] * np.sin(params[7] * t_s + params[8])
    return roll, -pitch_marine, heave

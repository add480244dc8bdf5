"""Own-ship navigation solution: the true motion plus GNSS/INS errors (docs/physics.md "Own-ship navigation").

The solution is defined on the uniform navigation grid ``t_k = k / rate_hz``, k = 0 .. floor(duration
x rate_hz), the times of ``ownship.jsonl``. Errors (``sensors.nav``, all standard deviations):

- position east and north: white noise ``position_noise_m`` plus a first-order Gauss-Markov bias
  of stationary sd ``position_bias_m`` and time constant ``position_bias_time_constant_s``, per axis;
  ``x``, ``y``, ``lat``, ``lon`` carry them; ``z`` stays the true heave;
- velocity east and north: white noise ``velocity_noise_mps`` per axis (COG and SOG follow from it);
- heading: white noise ``heading_noise_deg`` plus a Gauss-Markov bias ``heading_bias_deg``,
  ``heading_bias_time_constant_s``;
- roll and pitch: white noise ``attitude_noise_deg`` each.

The bias is discretised exactly on the grid (step ``dt = 1 / rate_hz``)::

    b[k] = exp(-dt/T) b[k-1] + sd sqrt(1 - exp(-2 dt/T)) n[k],   n ~ N(0, 1)

starting in its stationary distribution (``b[-1] ~ N(0, sd^2)``), so its variance is ``sd^2`` at
every sample and its autocorrelation ``exp(-|lag| / T)``. The recursion runs in
``scipy.signal.lfilter`` chunk by chunk, carrying the filter state; the normal deviates are drawn
sample-major from the named streams ``nav.position``, ``nav.velocity``, ``nav.heading`` and
``nav.attitude``. The errors therefore do not depend on the chunk size (a 24 h run at 50 Hz is
generated in chunks with memory that stays flat), and a chunked run equals one made in one go.
With every error parameter 0 the solution is exactly the true motion.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import TYPE_CHECKING, Iterator

import numpy as np
from scipy.signal import lfilter

from raysim.pose import heading_deg_from_yaw
from raysim.random_streams import stream
from raysim.recording.jsonl import COG_MIN_SPEED_MPS, course_and_speed
from raysim.scenario import Nav

if TYPE_CHECKING:
    from raysim.world import World

__all__ = ["NavErrors", "NavErrorModel", "grid_size", "navigation", "navigation_chunks", "nmea_indices"]


def grid_size(duration_s: float, rate_hz: float) -> int:
    """Number of samples ``k / rate_hz``, k = 0 .. floor(duration_s x rate_hz), of the navigation grid."""
    return int(np.floor(duration_s * rate_hz + 1e-9)) + 1


def nmea_indices(duration_s: float, rate_hz: float, nmea_rate_hz: float) -> np.ndarray:
    """Indices into the navigation grid of the NMEA epochs.

    Epoch j is the grid sample nearest to ``j / nmea_rate_hz`` (exactly that time when ``rate_hz``
    is a multiple of ``nmea_rate_hz``, as with the defaults 50 and 1 Hz); an NMEA rate above the
    navigation rate gives every grid sample once.

    Parameters
    ----------
    duration_s : float
        Scenario duration, s.
    rate_hz, nmea_rate_hz : float
        Navigation and NMEA rates, Hz.

    Returns
    -------
    (J,) int64
        Increasing, unique indices in ``[0, grid_size(duration_s, rate_hz))``.
    """
    n = grid_size(duration_s, rate_hz)
    epochs = np.arange(grid_size(duration_s, nmea_rate_hz), dtype=np.float64)
    k = np.rint(epochs * rate_hz / nmea_rate_hz).astype(np.int64)
    return np.unique(np.minimum(k, n - 1))


@dataclass(frozen=True)
class NavErrors:
    """Navigation errors at M grid samples (all (M,) float64).

    Attributes
    ----------
    east_m, north_m : (M,) float64
        Position error (white + bias), m.
    velocity_east_mps, velocity_north_mps : (M,) float64
        Velocity error, m/s.
    heading_deg : (M,) float64
        Heading error (white + bias), deg.
    roll_deg, pitch_deg : (M,) float64
        Attitude errors, deg.
    """

    east_m: np.ndarray
    north_m: np.ndarray
    velocity_east_mps: np.ndarray
    velocity_north_mps: np.ndarray
    heading_deg: np.ndarray
    roll_deg: np.ndarray
    pitch_deg: np.ndarray

    def take(self, index: np.ndarray) -> "NavErrors":
        """The errors at the samples ``index`` (M',) of this chunk."""
        return NavErrors(*(getattr(self, f.name)[index] for f in fields(self)))


class _GaussMarkov:
    """First-order Gauss-Markov biases on a uniform grid, generated chunk after chunk.

    Parameters
    ----------
    sd : float
        Stationary standard deviation (any unit).
    tau_s : float
        Time constant, s (> 0).
    dt_s : float
        Grid step, s.
    initial : (A,) float
        Standard normal deviates giving ``b[-1] = sd * initial`` for each of A axes.
    """

    def __init__(self, sd: float, tau_s: float, dt_s: float, initial: np.ndarray):
        self.decay = float(np.exp(-dt_s / tau_s))
        self.gain = float(sd * np.sqrt(-np.expm1(-2.0 * dt_s / tau_s)))
        # lfilter's state for y[k] = decay y[k-1] + x[k] is decay * y[k-1]
        self.state = (self.decay * sd * np.asarray(initial, dtype=float))[None, :]

    def next(self, n: np.ndarray) -> np.ndarray:
        """Biases (M, A) for the standard normal driving deviates ``n`` (M, A) of the next M samples."""
        if n.shape[0] == 0:
            return np.zeros(n.shape)
        b, self.state = lfilter([1.0], [1.0, -self.decay], self.gain * n, axis=0, zi=self.state)
        return b


class NavErrorModel:
    """The navigation errors of ``sensors.nav``, sample after sample along the navigation grid.

    Parameters
    ----------
    cfg : Nav
        ``scenario.sensors.nav``.
    seed : int
        The scenario seed.

    Notes
    -----
    Successive :meth:`next` calls continue the same processes: ``next(a)`` then ``next(b)`` gives
    exactly ``next(a + b)``.
    """

    def __init__(self, cfg: Nav, seed: int):
        self.cfg = cfg
        dt_s = 1.0 / cfg.rate_hz
        self._position = stream(seed, "nav.position")
        self._velocity = stream(seed, "nav.velocity")
        self._heading = stream(seed, "nav.heading")
        self._attitude = stream(seed, "nav.attitude")
        self._position_bias = _GaussMarkov(cfg.position_bias_m, cfg.position_bias_time_constant_s, dt_s,
                                           self._position.standard_normal(2))
        self._heading_bias = _GaussMarkov(cfg.heading_bias_deg, cfg.heading_bias_time_constant_s, dt_s,
                                          self._heading.standard_normal(1))

    def next(self, m: int) -> NavErrors:
        """Errors of the next ``m`` grid samples."""
        cfg = self.cfg
        position = self._position.standard_normal((m, 4))  # white east, north; bias drive east, north
        velocity = self._velocity.standard_normal((m, 2))
        heading = self._heading.standard_normal((m, 2))  # white; bias drive
        attitude = self._attitude.standard_normal((m, 2))  # roll, pitch
        position_error = cfg.position_noise_m * position[:, :2] + self._position_bias.next(position[:, 2:])
        heading_error = cfg.heading_noise_deg * heading[:, 0] + self._heading_bias.next(heading[:, 1:])[:, 0]
        velocity_error = cfg.velocity_noise_mps * velocity
        attitude_error = cfg.attitude_noise_deg * attitude
        return NavErrors(position_error[:, 0], position_error[:, 1], velocity_error[:, 0], velocity_error[:, 1],
                         heading_error, attitude_error[:, 0], attitude_error[:, 1])


def navigation(world: "World", t_s: np.ndarray, errors: NavErrors) -> dict[str, np.ndarray]:
    """The navigation solution: the own ship's true motion at ``t_s`` plus ``errors``.

    Parameters
    ----------
    world : raysim.world.World
    t_s : (M,) float
        Times since the scenario start, s.
    errors : NavErrors
        Errors at those times (M samples).

    Returns
    -------
    dict of (M,) float64
        The ``ownship.jsonl`` columns: ``lat``, ``lon`` (deg), ``x``, ``y`` (noisy, m), ``z`` (true
        heave, m), ``heading_deg`` in [0, 360), ``roll_deg`` (starboard down positive),
        ``pitch_deg`` (bow up positive), ``cog_deg`` in [0, 360), ``sog_mps``.
    """
    motion = world.own_ship.motion
    poses = motion.poses(t_s)
    x_m = poses.position_m[:, 0] + errors.east_m
    y_m = poses.position_m[:, 1] + errors.north_m
    lat_deg, lon_deg = world.frame.to_geodetic(x_m, y_m)
    heading_deg = np.mod(heading_deg_from_yaw(poses.yaw_rad) + errors.heading_deg, 360.0)
    velocity_mps = motion.velocity_mps(t_s).copy()
    velocity_mps[:, 0] += errors.velocity_east_mps
    velocity_mps[:, 1] += errors.velocity_north_mps
    cog_deg, sog_mps = course_and_speed(velocity_mps, poses.yaw_rad)
    still = sog_mps < COG_MIN_SPEED_MPS
    cog_deg[still] = heading_deg[still]  # below it COG is undefined: report the measured heading
    return dict(lat=lat_deg, lon=lon_deg, x=x_m, y=y_m, z=poses.position_m[:, 2], heading_deg=heading_deg,
                roll_deg=np.degrees(poses.roll_rad) + errors.roll_deg,
                pitch_deg=-np.degrees(poses.pitch_rad) + errors.pitch_deg,  # FLU pitch is bow down positive
                cog_deg=cog_deg, sog_mps=sog_mps)


def navigation_chunks(world: "World", chunk_samples: int, indices: np.ndarray | None = None
                      ) -> Iterator[tuple[np.ndarray, dict[str, np.ndarray]]]:
    """The navigation solution over the whole grid, chunk by chunk.

    Parameters
    ----------
    world : raysim.world.World
    chunk_samples : int
        Grid samples per chunk (the results do not depend on it).
    indices : (J,) int, optional
        Increasing grid indices to report (e.g. :func:`nmea_indices`); default every sample. The
        errors are generated for every grid sample either way, so a subset has exactly the values
        of the full solution at those samples.

    Yields
    ------
    t_s : (M,) float64
        Times ``k / rate_hz`` of the chunk's reported samples, s.
    columns : dict of (M,) float64
        :func:`navigation` at those times. Chunks without a reported sample are skipped.
    """
    scenario = world.scenario
    cfg = scenario.sensors.nav
    n = grid_size(scenario.duration_s, cfg.rate_hz)
    model = NavErrorModel(cfg, scenario.seed)
    step = max(1, int(chunk_samples))
    for start in range(0, n, step):
        stop = min(n, start + step)
        errors = model.next(stop - start)
        if indices is None:
            k = np.arange(start, stop)
        else:
            k = indices[np.searchsorted(indices, start):np.searchsorted(indices, stop)]
            if k.size == 0:
                continue
            errors = errors.take(k - start)
        t_s = k / cfg.rate_hz
        yield t_s, navigation(world, t_s, errors)

"""The AIS's tracker: one EKF per MMSI, created by its first report and updated with each report's
position, course, speed and rate of turn (the thesis's AIS noise model, docs/reference.md section 4)."""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field, replace

import numpy as np

from groundfloor.ais import HELD_MAX_SOG_KN, HELD_REPORT_INTERVAL_S, NAV_STATUS_AT_ANCHOR, NAV_STATUS_MOORED
from groundfloor.units import KNOT_MPS
from tdm import ekf
from tdm.detections import AisReport, AisStatic
from tdm.tracker import INIT_TURN_RATE_SIGMA_DEG_S, Track

SECONDS_PER_MINUTE = 60.0
#: An AIS course over ground is used only above this speed over ground, m/s (0.6 kn: below it the COG
#: of a drifting ship is noise).
AIS_COG_MIN_SOG_MPS = 0.3
#: Fastest SOG of a ship at anchor or moored that reports every 3 minutes, m/s (3 kn, ITU-R M.1371-5 Table 1).
HELD_MAX_SOG_MPS = HELD_MAX_SOG_KN * KNOT_MPS


@dataclass(frozen=True)
class AisTrackerConfig:
    """AIS tracking parameters.

    The measurement noise is the thesis's AIS noise model (docs/reference.md section 4 / the
    thesis's ``AIS_*`` parameters): position variance 5 + 0.5 m^2 (white + bias), COG 1 + 0.5
    deg^2, SOG 0.5 + 0.1 kn^2, ROT 2000 + 500 (deg/min)^2. These are what the TDM assumes of any
    transponder; they are not read from the recording.

    Attributes
    ----------
    position_var_m2 : float
        Variance of a reported position per axis, m^2.
    cog_var_deg2 : float
        Variance of a reported COG, deg^2 (used above :data:`AIS_COG_MIN_SOG_MPS`).
    sog_var_kn2 : float
        Variance of a reported SOG, kn^2.
    rot_var_deg2_per_min2 : float
        Variance of a reported rate of turn, (deg/min)^2.
    coast_s : float
        A track whose last report is older than this is dropped, s (and a report after it starts a new one).
    anchored_speed_sigma_mps, moored_speed_sigma_mps : float or None
        A Class A ship reporting itself at anchor (status 1) or moored (status 5), at 3 kn or less, holds its
        position: its speed is taken as 0 with this standard deviation, m/s (> 0), fused with the reported SOG
        as a second measurement of the speed (without a SOG, 0 with this deviation), its COG is not used, and
        till its next report its speed wanders by this much over a reporting interval of such a ship (3
        minutes, ITU-R M.1371-5 Table 1), not as one under way does (the process noise's ``speed_m2_per_s3``:
        0.5 m/s in 10 s). Such a ship's transponder reads the GNSS's noise as its SOG (the thesis's: 0.77 kn
        sd); dead-reckoned at a reported 0.6-1.3 kn it drifted 50-120 m between reports (harbour_approach's
        anchored tanker, busy_port 31's moored coaster: held-out runs, docs/tdm.md "Tracking"). 0.1 m/s (0.2
        kn) at anchor, where a ship swings about its anchor at a few tenths of a knot; 0.01 m/s moored, where
        it moves by its lines' and fenders' slack, about a metre. Fitted to no scenario, but the moored figure
        and the held motion noise were chosen after a held-out run showed the first form's NEES (docs/tdm.md).
        A report of more than 3 kn is of a ship under way, whatever its status (the fastest a ship at anchor
        or moored reporting every 3 minutes goes, ITU-R M.1371-5). The first report under way of a held ship
        starts its track's state again from that report alone (its id kept). None: the status is not used.
    process : ekf.ProcessNoise
        Motion noise of a ship under way.
    """

    position_var_m2: float = 5.5
    cog_var_deg2: float = 1.5
    sog_var_kn2: float = 0.6
    rot_var_deg2_per_min2: float = 2500.0
    coast_s: float = 200.0
    anchored_speed_sigma_mps: float | None = 0.1
    moored_speed_sigma_mps: float | None = 0.01
    process: ekf.ProcessNoise = field(default_factory=ekf.ProcessNoise)

    def __post_init__(self):
        for name in ("anchored_speed_sigma_mps", "moored_speed_sigma_mps"):
            sigma_mps = getattr(self, name)
            if sigma_mps is not None and not sigma_mps > 0.0:
                raise ValueError(f"{name} must be > 0 m/s or None, not {sigma_mps!r}")

    def held_speed_sigma_mps(self, nav_status: int, sog_mps: float = float("nan")) -> float | None:
        """The speed's standard deviation of a ship that holds its position.

        Parameters
        ----------
        nav_status : int
            The report's navigational status (ITU-R M.1371-5; 15: not defined).
        sog_mps : float
            The report's SOG, m/s (NaN: not available).

        Returns
        -------
        float or None
            m/s; None when the ship is not held: its status is neither at anchor nor moored, that status's figure
            is None, or it reports more than :data:`HELD_MAX_SOG_MPS` (under way whatever its status says:
            statuses are set by hand and left behind).
        """
        if sog_mps > HELD_MAX_SOG_MPS:
            return None
        return {NAV_STATUS_AT_ANCHOR: self.anchored_speed_sigma_mps,
                NAV_STATUS_MOORED: self.moored_speed_sigma_mps}.get(nav_status)


def _speed_measurement(sog_mps: float, sog_var_mps2: float,
                       held_sigma_mps: float | None) -> tuple[float, float] | None:
    """The speed measurement of one report.

    Parameters
    ----------
    sog_mps : float
        The reported SOG, m/s (NaN: not available).
    sog_var_mps2 : float
        Its variance, (m/s)^2.
    held_sigma_mps : float or None
        For a ship holding its position, the standard deviation of its speed about 0, m/s; None otherwise.

    Returns
    -------
    tuple of float or None
        (speed m/s, variance (m/s)^2): the SOG; for a held ship, the SOG fused with a speed of 0 +- ``held_sigma_mps``
        (the product of the two Gaussians, as two measurements of the speed in one update would give), or 0 +-
        ``held_sigma_mps`` without a SOG. None: no speed measured.
    """
    if held_sigma_mps is None:
        return (float(sog_mps), sog_var_mps2) if np.isfinite(sog_mps) else None
    held_var = held_sigma_mps**2
    if not np.isfinite(sog_mps):
        return 0.0, held_var
    return float(sog_mps) * held_var / (held_var + sog_var_mps2), held_var * sog_var_mps2 / (held_var + sog_var_mps2)


#: Prior variances of an AIS track's states that its first report does not measure: position
#: (always measured), course pi^2 (unknown), speed (5 m/s)^2, turn rate (3 deg/s)^2, cross-section
#: (1000 m^2)^2.
AIS_PRIOR_VAR = (1e6, 1e6, np.pi**2, 25.0, np.radians(INIT_TURN_RATE_SIGMA_DEG_S) ** 2, 1e6)


class AisTracker:
    """One EKF per MMSI, updated with position, COG, SOG and ROT of each report."""

    def __init__(self, config: AisTrackerConfig):
        self.config = config
        #: The motion noise of a ship holding its position, by status: its speed wanders by its speed's standard
        #: deviation over one reporting interval of a ship at anchor or moored (3 minutes).
        self._held_process: dict[int, ekf.ProcessNoise] = {}
        for status in (NAV_STATUS_AT_ANCHOR, NAV_STATUS_MOORED):
            sigma_mps = config.held_speed_sigma_mps(status)
            if sigma_mps is not None:
                self._held_process[status] = replace(config.process,
                                                     speed_m2_per_s3=sigma_mps**2 / HELD_REPORT_INTERVAL_S)
        self.tracks: dict[int, Track] = {}
        self.static: dict[int, AisStatic] = {}
        self._ids = itertools.count(1)
        #: MMSIs whose track's position is its hull's centre (a report moved there by its reference point,
        #: :mod:`tdm.frontend.ais_reference`), not its transponder's antenna.
        self._centred: set[int] = set()

    def confirmed_tracks(self) -> list[Track]:
        """Every live AIS track (an AIS track is confirmed by its first report)."""
        return list(self.tracks.values())

    def process(self, report: AisReport) -> None:
        """Update (or start) the track of the report's MMSI."""
        held_sigma_mps = self.config.held_speed_sigma_mps(report.nav_status, report.sog_mps)
        rows, z, var, angle_rows = self._measurement(report, held_sigma_mps)
        noise = self.config.process if held_sigma_mps is None else self._held_process[report.nav_status]
        t = float(report.time_s)
        track = self.tracks.get(report.mmsi)
        if track is None or t - track.updated_s > self.config.coast_s:
            self.tracks[report.mmsi] = self._start(report, rows, z, var, noise)
            self._centred.discard(report.mmsi)
        else:
            self._centre(track, report)
            self._update(track, report, rows, z, var, angle_rows, held_sigma_mps, noise)
        if report.centre_offset_m is not None:
            self._centred.add(report.mmsi)

    def _centre(self, track: Track, report: AisReport) -> None:
        """The first report moved to its hull's centre moves the track there too: its reports so far were of the
        antenna (sent before the static data that place it), and the filter would take the step for motion."""
        if report.centre_offset_m is not None and report.mmsi not in self._centred:
            track.x = track.x.copy()
            track.x[[ekf.E, ekf.N]] += report.centre_offset_m

    def _update(self, track: Track, report: AisReport, rows: list[int], z: list[float], var: list[float],
                angle_rows: tuple[int, ...], held_sigma_mps: float | None, noise: ekf.ProcessNoise) -> None:
        """A live track updated with its report's measured states."""
        t = float(report.time_s)
        if held_sigma_mps is None and track.process is not noise:
            # a held ship got under way at some time since its last report: its state starts again from this
            # report, as a new track's would (its id kept); nothing of its held speed carries over
            track.x, track.p = self._first_state(report, rows, z, var)
        else:
            x, p = track.predicted(t)
            h = ekf.h_rows(*rows)
            track.x, track.p, _ = ekf.update(x, p, np.array(z, dtype=float), h, np.diag(var), angle_rows)
        track.t_s = track.updated_s = t
        track.n_updates += 1
        track.process = noise

    def _measurement(self, report: AisReport,
                     held_sigma_mps: float | None) -> tuple[list[int], list[float], list[float], tuple[int, ...]]:
        """The report's measured states: their rows, values and variances, and the angle rows (COG); with
        ``held_sigma_mps``, the ship holds its position (:meth:`AisTrackerConfig.held_speed_sigma_mps`)."""
        cfg = self.config
        position_var_m2 = cfg.position_var_m2 + report.position_extra_var_m2  # a reference point not placed
        rows, z, var = [ekf.E, ekf.N], [report.position_m[0], report.position_m[1]], [position_var_m2] * 2
        angle_rows: tuple[int, ...] = ()
        moving = np.isfinite(report.sog_mps) and report.sog_mps > AIS_COG_MIN_SOG_MPS and held_sigma_mps is None
        if np.isfinite(report.cog_deg) and moving:
            angle_rows = (len(rows),)
            rows.append(ekf.PSI)
            z.append(np.radians(report.cog_deg))
            var.append(np.radians(1.0) ** 2 * cfg.cog_var_deg2)
        speed = _speed_measurement(report.sog_mps, cfg.sog_var_kn2 * KNOT_MPS**2, held_sigma_mps)
        if speed is not None:
            rows.append(ekf.U)
            z.append(speed[0])
            var.append(speed[1])
        if np.isfinite(report.rot_deg_per_min):
            rows.append(ekf.R)
            z.append(np.radians(report.rot_deg_per_min) / SECONDS_PER_MINUTE)
            var.append(cfg.rot_var_deg2_per_min2 * (np.radians(1.0) / SECONDS_PER_MINUTE) ** 2)
        return rows, z, var, angle_rows

    def _start(self, report: AisReport, rows: list[int], z: list[float], var: list[float],
               noise: ekf.ProcessNoise) -> Track:
        """A track from its first report: the measured states at their values and variances.

        States the report does not carry start at the broad prior :data:`AIS_PRIOR_VAR` (course
        unknown, speed and turn rate about 0, cross-section from the static data when known).
        """
        x, p = self._first_state(report, rows, z, var)
        t = float(report.time_s)
        return Track(next(self._ids), "ais", x, p, t, t, t, confirmed=True, n_updates=1, mmsi=report.mmsi,
                     process=noise)

    def _first_state(self, report: AisReport, rows: list[int], z: list[float],
                     var: list[float]) -> tuple[np.ndarray, np.ndarray]:
        """State (6,) and covariance (6, 6) from one report alone: the measured states at their values and
        variances, the others at :data:`AIS_PRIOR_VAR` (cross-section from the static data when known)."""
        x = np.zeros(ekf.N_STATES)
        p = np.diag(AIS_PRIOR_VAR)
        x[rows] = z
        p[rows, rows] = var
        static = self.static.get(report.mmsi)
        if static is not None and np.isfinite(static.length_m * static.beam_m):
            x[ekf.ALPHA] = static.length_m * static.beam_m
        return x, p

    def set_static(self, static: dict[int, AisStatic]) -> None:
        """Add static data (name, type, dimensions) by MMSI; later entries replace earlier ones."""
        self.static.update(static)

    def expire(self, t_s: float) -> None:
        """Drop tracks whose last report is older than ``coast_s``."""
        self.tracks = {m: tr for m, tr in self.tracks.items() if t_s - tr.updated_s <= self.config.coast_s}

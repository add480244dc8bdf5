"""The AIS's tracker: one EKF per MMSI, created by its first report and updated with each report's
position, course, speed and rate of turn (the thesis's AIS noise model, docs/reference.md section 4)."""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field

import numpy as np

from groundfloor.units import KNOT_MPS
from tdm import ekf
from tdm.detections import AisReport, AisStatic
from tdm.tracker import INIT_TURN_RATE_SIGMA_DEG_S, Track

SECONDS_PER_MINUTE = 60.0
#: An AIS course over ground is used only above this speed over ground, m/s (0.6 kn: below it the COG
#: of a drifting ship is noise).
AIS_COG_MIN_SOG_MPS = 0.3


@dataclass(frozen=True)
class AisTrackerConfig:
    """AIS tracking parameters.

    The measurement noise is the thesis's AIS noise model (docs/reference.md section 4 / the
    thesis's ``AIS_*`` parameters): position variance 5 + 0.5 m^2 (white + bias), COG 1 + 0.5
    deg^2, SOG 0.5 + 0.1 kn^2, ROT 2000 + 500 (deg/min)^2. These are what the TDM assumes of any
    transponder; they are not read from the recording.
    """

    position_var_m2: float = 5.5
    cog_var_deg2: float = 1.5
    sog_var_kn2: float = 0.6
    rot_var_deg2_per_min2: float = 2500.0
    coast_s: float = 200.0
    process: ekf.ProcessNoise = field(default_factory=ekf.ProcessNoise)


#: Prior variances of an AIS track's states that its first report does not measure: position
#: (always measured), course pi^2 (unknown), speed (5 m/s)^2, turn rate (3 deg/s)^2, cross-section
#: (1000 m^2)^2.
AIS_PRIOR_VAR = (1e6, 1e6, np.pi**2, 25.0, np.radians(INIT_TURN_RATE_SIGMA_DEG_S) ** 2, 1e6)


class AisTracker:
    """One EKF per MMSI, updated with position, COG, SOG and ROT of each report."""

    def __init__(self, config: AisTrackerConfig):
        self.config = config
        self.tracks: dict[int, Track] = {}
        self.static: dict[int, AisStatic] = {}
        self._ids = itertools.count(1)

    def confirmed_tracks(self) -> list[Track]:
        return list(self.tracks.values())

    def process(self, report: AisReport) -> None:
        """Update (or start) the track of the report's MMSI."""
        cfg = self.config
        rows, z, var = [ekf.E, ekf.N], [report.position_m[0], report.position_m[1]], [cfg.position_var_m2] * 2
        angle_rows: tuple[int, ...] = ()
        moving = np.isfinite(report.sog_mps) and report.sog_mps > AIS_COG_MIN_SOG_MPS
        if np.isfinite(report.cog_deg) and moving:
            angle_rows = (len(rows),)
            rows.append(ekf.PSI)
            z.append(np.radians(report.cog_deg))
            var.append(np.radians(1.0) ** 2 * cfg.cog_var_deg2)
        if np.isfinite(report.sog_mps):
            rows.append(ekf.U)
            z.append(report.sog_mps)
            var.append(cfg.sog_var_kn2 * KNOT_MPS**2)
        if np.isfinite(report.rot_deg_per_min):
            rows.append(ekf.R)
            z.append(np.radians(report.rot_deg_per_min) / SECONDS_PER_MINUTE)
            var.append(cfg.rot_var_deg2_per_min2 * (np.radians(1.0) / SECONDS_PER_MINUTE) ** 2)
        t = float(report.time_s)
        track = self.tracks.get(report.mmsi)
        if track is None or t - track.updated_s > cfg.coast_s:
            self.tracks[report.mmsi] = self._start(report, rows, z, var)
            return
        x, p = track.predicted(t)
        h = ekf.h_rows(*rows)
        track.x, track.p, _ = ekf.update(x, p, np.array(z, dtype=float), h, np.diag(var), angle_rows)
        track.t_s = track.updated_s = t
        track.n_updates += 1

    def _start(self, report: AisReport, rows: list[int], z: list[float], var: list[float]) -> Track:
        """A track from its first report: the measured states at their values and variances.

        States the report does not carry start at the broad prior :data:`AIS_PRIOR_VAR` (course
        unknown, speed and turn rate about 0, cross-section from the static data when known).
        """
        x = np.zeros(ekf.N_STATES)
        p = np.diag(AIS_PRIOR_VAR)
        x[rows] = z
        p[rows, rows] = var
        static = self.static.get(report.mmsi)
        if static is not None and np.isfinite(static.length_m * static.beam_m):
            x[ekf.ALPHA] = static.length_m * static.beam_m
        t = float(report.time_s)
        return Track(next(self._ids), "ais", x, p, t, t, t, confirmed=True, n_updates=1, mmsi=report.mmsi,
                     process=self.config.process)

    def set_static(self, static: dict[int, AisStatic]) -> None:
        self.static.update(static)

    def expire(self, t_s: float) -> None:
        """Drop tracks whose last report is older than ``coast_s``."""
        self.tracks = {m: tr for m, tr in self.tracks.items() if t_s - tr.updated_s <= self.config.coast_s}

"""Mutual radar interference: another radar's pulses in our receiver, and the interference rejection.

Timing (all vectorised over the pulses of a revolution):

- The other radar fires at ``t_k = phi + k / prf`` (``phi`` uniform in one period, stream
  ``radar.interference.<j>``: the sets are not synchronised).
- Our receiver repeats its sweep every ``T_rep`` (:data:`OWN_SWEEP_REPETITION_S`, the 1 ms FMCW sweep
  of REF 3.1, back to back from t = 0) and maps the first ``2 range_m / c`` of each sweep onto the range
  scale. A pulse arriving at ``t_k`` shows at the apparent range ``c/2 ((t_k) mod T_rep)`` on the spoke
  being swept at ``t_k``, if that is within the range scale.
- Because the two repetition periods are not commensurate, the apparent range walks by
  ``c/2 ((1/prf) mod T_rep)`` (wrapped to +-T_rep/2) from one pulse to the next: with nearly equal
  rates the dots line up into the curved spiral arcs real sets show; otherwise they scatter. This is
  the classic mechanism (Bole, Wall and Norris, "Radar and ARPA Manual", 3rd ed., Butterworth-Heinemann
  2014, section 3.9, "Radar interference").
- Each pulse fills ``max(1, round(c tau / 2 / dr))`` samples (its length ``tau`` in range).

Level per pulse: ``level_db + G_other(its antenna azimuth - bearing to us) + G_own(our antenna azimuth -
bearing to it)``, both ONE-WAY power patterns (the pulse crosses the path once): a Gaussian main lobe
with the -3 dB width, floored by the sidelobe envelope of IEC 60936-1 (shipborne radar, -23 dB within
10 deg of the beam axis, -30 dB beyond; unverified figures, see docs/radar.md). The bright arcs come
when the other radar's main beam sweeps over us, through our sidelobes on many spokes.

Interference rejection (:func:`reject`): sweep-to-sweep correlation on the video (Bole, Wall and Norris,
section 3.9): a sample is kept at the lowest level among itself and its correlated neighbours on the
adjacent spokes, so echoes present on consecutive spokes (every target: the beam spans tens of spokes)
stay and the dots, which move in range from spoke to spoke, go.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from raysim.random_streams import stream
from raysim.sensors import radar_physics as phys

#: Our sweep repetition interval, s: the FMCW sweep of REF 3.1 (1 ms), back to back.
OWN_SWEEP_REPETITION_S = phys.SWEEP_S
#: One-way sidelobe envelope, dB re. the main beam: within / beyond SIDELOBE_NEAR_DEG of the axis
#: (IEC 60936-1 shipborne radar antenna requirements; unverified).
SIDELOBE_NEAR_DB, SIDELOBE_FAR_DB, SIDELOBE_NEAR_DEG = -23.0, -30.0, 10.0
DEG_PER_TURN = 360.0
SECONDS_PER_MINUTE = 60.0
US = 1e-6
#: Interference-rejection settings: (neighbour spokes that must hold the echo, range tolerance in samples).
#: low: either neighbour within +-1 sample; medium: both within +-1; high: both at the same sample.
REJECTION = {"low": ("either", 1), "medium": ("both", 1), "high": ("both", 0)}  # tolerance 0 or 1 only


def one_way_pattern_db(offset_deg: np.ndarray, beam_deg: float) -> np.ndarray:
    """One-way power pattern, dB (peak 0): Gaussian main lobe floored by the IEC sidelobe envelope.

    Parameters
    ----------
    offset_deg : array
        Angle from the beam axis, deg (any sign, any turn).
    beam_deg : float
        -3 dB width, deg.
    """
    off = np.abs((np.asarray(offset_deg, dtype=float) + 180.0) % DEG_PER_TURN - 180.0)
    envelope = np.where(off <= SIDELOBE_NEAR_DEG, SIDELOBE_NEAR_DB, SIDELOBE_FAR_DB)
    return np.maximum(phys.one_way_gain_db(off, beam_deg), envelope)


@dataclass(frozen=True)
class Interferer:
    """One other radar in the local frame (from a scenario's ``sensors.radar.interference`` item)."""

    east_m: float
    north_m: float
    prf_hz: float
    rpm: float
    level_db: float
    beam_az_deg: float
    pulse_length_us: float
    azimuth0_deg: float
    phase_s: float


class Interference:
    """The interference of a list of other radars on our sweeps.

    Parameters
    ----------
    configs : sequence
        The scenario's ``sensors.radar.interference`` items.
    frame : LocalFrame
        Converts their [lat, lon] to the local frame.
    seed : int
        Scenario seed (the pulse phases: streams ``radar.interference.<j>``).
    range_scale_m, dr_m : float
        Our range scale and sample spacing, m.
    samples : int
    own_beam_az_deg : float
        Our -3 dB azimuth width, deg.
    own_pattern : object, optional
        Our antenna (:mod:`raysim.sensors.radar_beam`): if it has sidelobes (not the Gaussian beam), our
        one-way gain is ``|horizontal_voltage|^2`` of it; otherwise :func:`one_way_pattern_db`.
    """

    def __init__(self, configs, frame, seed: int, range_scale_m: float, dr_m: float, samples: int,
                 own_beam_az_deg: float, own_pattern=None):
        items = []
        for j, c in enumerate(configs):
            east, north = (float(np.asarray(v).reshape(-1)[0]) for v in frame.to_local(c.position[0], c.position[1]))
            phase = float(stream(seed, f"radar.interference.{j}").uniform(0.0, 1.0 / c.prf_hz))
            items.append(Interferer(east, north, c.prf_hz, c.rpm, c.level_db, c.beam_az_deg, c.pulse_length_us,
                                    c.azimuth0_deg, phase))
        self.items = tuple(items)
        self.dr = dr_m
        self.samples = samples
        self.listen_s = 2.0 * (range_scale_m + 0.5 * dr_m) / phys.C_MPS
        self.own_beam_az_deg = own_beam_az_deg
        gaussian = own_pattern is None or type(own_pattern).__name__ == "GaussianPattern"
        self.own_pattern = None if gaussian else own_pattern

    def own_gain_db(self, offset_deg: np.ndarray) -> np.ndarray:
        """Our one-way power gain, dB (peak 0), at azimuth offsets from our beam axis, deg."""
        if self.own_pattern is None:
            return one_way_pattern_db(offset_deg, self.own_beam_az_deg)
        v = self.own_pattern.horizontal_voltage(np.asarray(offset_deg, dtype=float))
        return 10.0 * np.log10(np.maximum(np.abs(v) ** 2, 1e-30))

    def pulses(self, it: Interferer, t_s: np.ndarray, pos_m: np.ndarray, bearing_deg: np.ndarray):
        """The pulses of ``it`` seen in one revolution: (spoke, first sample, samples long, SNR linear).

        ``t_s`` (S,) spoke times (uniform spacing), ``pos_m`` (S, >=2) antenna east/north, ``bearing_deg``
        (S,) compass bearing of each spoke.
        """
        S = t_s.size
        ts = float(t_s[1] - t_s[0]) if S > 1 else 1.0
        period = 1.0 / it.prf_hz
        k0 = math.ceil((t_s[0] - it.phase_s) / period)
        k1 = math.floor((t_s[0] + S * ts - it.phase_s) / period - 1e-12)
        t_k = it.phase_s + np.arange(k0, k1 + 1, dtype=np.float64) * period
        delay = np.mod(t_k, OWN_SWEEP_REPETITION_S)
        keep = delay < self.listen_s
        t_k, delay = t_k[keep], delay[keep]
        spoke = np.clip(np.floor((t_k - t_s[0]) / ts).astype(np.int64), 0, S - 1)
        first = np.rint(delay * (0.5 * phys.C_MPS) / self.dr).astype(np.int64)
        # bearings: from the other radar to us and back, compass deg
        de, dn = pos_m[spoke, 0] - it.east_m, pos_m[spoke, 1] - it.north_m
        to_us = np.degrees(np.arctan2(de, dn))
        its_az = it.azimuth0_deg + DEG_PER_TURN * it.rpm / SECONDS_PER_MINUTE * t_k
        level_db = (it.level_db + one_way_pattern_db(its_az - to_us, it.beam_az_deg)
                    + self.own_gain_db(bearing_deg[spoke] - (to_us + 180.0)))
        width = max(1, int(round(it.pulse_length_us * US * 0.5 * phys.C_MPS / self.dr)))
        return spoke, first, width, phys.undb(level_db)

    @property
    def active(self) -> bool:
        return bool(self.items)

    def add_to(self, total: np.ndarray, t_s: np.ndarray, pos_m: np.ndarray, bearing_deg: np.ndarray) -> None:
        """Add every interferer's pulses of one revolution to ``total`` (S, N), SNR linear, in place."""
        S, N = total.shape
        flat_total = total.reshape(-1)
        for it in self.items:  # a few other radars; each is vectorised over its pulses
            spoke, first, width, power = self.pulses(it, t_s, pos_m, bearing_deg)
            sample = first[:, None] + np.arange(width)[None, :]
            ok = sample < N
            flat = (spoke[:, None] * N + sample)[ok]
            np.add.at(flat_total, flat, np.broadcast_to(power[:, None], sample.shape)[ok].astype(total.dtype))


def reject(echo: np.ndarray, setting: str) -> np.ndarray:
    """Interference rejection on the (S, N) video: sweep-to-sweep correlation over adjacent spokes.

    Each sample becomes the lowest of its own level and its neighbours' (the neighbours' levels first
    taken as their maximum over +-tolerance samples in range): ``low`` keeps an echo found on EITHER
    adjacent spoke within +-1 sample, ``medium`` needs BOTH within +-1 sample, ``high`` needs both at the
    same sample. ``off`` returns ``echo`` unchanged. Spokes wrap around the revolution.
    """
    if setting == "off":
        return echo
    need, tol = REJECTION[setting]
    near = echo
    if tol:  # the +-1 sample maximum along range (two shifted maxima: cheaper than a filter)
        near = echo.copy()
        np.maximum(near[:, 1:], echo[:, :-1], out=near[:, 1:])
        np.maximum(near[:, :-1], echo[:, 1:], out=near[:, :-1])
    prev, nxt = np.roll(near, 1, axis=0), np.roll(near, -1, axis=0)
    other = np.maximum(prev, nxt) if need == "either" else np.minimum(prev, nxt)
    return np.minimum(echo, other)


__all__ = ["Interference", "Interferer", "OWN_SWEEP_REPETITION_S", "one_way_pattern_db", "reject"]

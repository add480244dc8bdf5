"""Radar receiver per model: range impulse response (FFT range sidelobes, pulse smear) and saturation.

Models (scenario ``sensors.radar.model``, :data:`RECEIVER_MODELS`):

- ``broadband-4g`` / ``broadband-3g``: FMCW. Range comes from an FFT of the beat signal over one
  sweep; a point target's range response is the spectrum of the sweep's amplitude window,
  centred on the target's beat frequency (A. G. Stove, "Linear FMCW radar techniques",
  IEE Proc. F 139(5), 343-350, 1992). Navico does not publish its window: a Hann window is an
  engineering choice (unverified). Its spectrum (F. J. Harris, "On the use of windows for harmonic
  analysis with the discrete Fourier transform", Proc. IEEE 66(1), 51-83, 1978): -3 dB width
  1.44 bins, first sidelobe -31.5 dB, sidelobes falling 18 dB/octave. Far from the peak a skirt
  from the sweep's phase noise and nonlinearity (Stove 1992) is modelled as an incoherent floor
  ``F / (1 + (u / u0)^2)`` re. the peak power (F = -65 dB, u0 = 10 FFT bins: unverified).
- ``magnetron``: a pulse set. The echo is the transmitted pulse (a rectangle of ``c tau / 2`` in range)
  through the IF filter, taken as Gaussian with a 3 dB bandwidth ``B = 1.2 / tau`` (the near-optimum
  ``B tau`` of a rectangular pulse: M. I. Skolnik, *Introduction to Radar Systems*, 3rd ed., 2001,
  section 5.2; unverified page). Pulse length by range scale from the Simrad Argus radar operator
  manual (pulse-length table, "Normal" power: 0.07 us up to 3 NM, 0.25 us to 12 NM, 0.80 us beyond);
  the Argus is a 12/25 kW ship's set, used here for a generic magnetron set. The log amplifier's
  recovery tail after a strong echo is not modelled (no source found).

Saturation (:func:`saturate`): the receiver's output power is limited by Rapp's limiter
(C. Rapp, "Effects of HPA-nonlinearity on 4-DPSK/OFDM-signal for a digital sound broadcasting
system", Proc. 2nd European Conf. on Satellite Communications, ESA SP-332, 1991)
``A / (1 + (A / A_sat)^(2p))^(1/(2p))`` in amplitude, ``P / (1 + (P / P_sat)^p)^(1/p)`` in power, with
``p = 3`` (a knee close to an ADC's hard clip: 1 dB below ``P_sat`` at ``P_sat``; unverified), at
``saturation_db`` over the noise: FMCW 70 dB (ADC full scale
minus the FFT's processing gain; unverified), magnetron 80 dB (the log amplifier's dynamic range;
unverified: Alred & Reiss, "An anti-clutter radar receiver", J. IEE III 95(38), 1948, report a
log receiver compressing up to 100 dB over the noise). Blooming on the video is then the range
response's skirt: an 80 dB echo's sidelobes and floor stay over the first video level
(9.6 dB) for tens of metres, a 30 dB echo's only over its main lobe. Harmonic ghosts and
small-signal suppression of a clipped FMCW ADC are not modelled.

Output samples lie ``dR = range_scale / (N - 1)`` apart, not on FFT bins. A target's position
inside its sample is unknown (the renderer rounds it to the nearest sample), so each kernel
value is the RMS of the continuous response over that sample's cell (the response averaged over
a uniformly distributed sub-sample offset; a plain point sample at ``dR`` = one FFT bin would
fall on every null of the window spectrum), with the sign of the response at the cell centre,
normalised to 1 at the centre.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq
from scipy.signal import fftconvolve

from raysim.sensors.radar_physics import C_MPS

M_PER_NM = 1852.0
#: Sub-samples per output cell for the RMS over the cell (odd: one at the centre).
CELL_SUBSAMPLES = 15
#: Smoothness of Rapp's limiter (power exponent; amplitude exponent 2 p), unverified.
RAPP_P = 3.0
#: Fraction of P_sat below which the limiter is the identity to float32 precision ((1e-3)^3 / 3 << 6e-8).
LIMITER_ACTIVE = 1e-3
#: The kernels reach until the response (main part plus floor) is this far below the peak, dB.
KERNEL_DEPTH_DB = 100.0


def hann_response(u) -> np.ndarray:
    """Voltage spectrum of a Hann window, peak 1, at ``u`` FFT bins from the tone (Harris 1978).

    ``H(u) = sinc(u) + (sinc(u - 1) + sinc(u + 1)) / 2 = sinc(u) / (1 - u^2)``: the continuous-time
    (many-sample) form of the windowed DFT's Dirichlet kernel, real with alternating sidelobes.

    Parameters
    ----------
    u : array_like of float
        Offset from the tone, FFT bins (``c / (2 B)`` of range each).

    Returns
    -------
    np.ndarray of float64, same shape as ``u``
    """
    u = np.asarray(u, dtype=float)
    return np.sinc(u) + 0.5 * (np.sinc(u - 1.0) + np.sinc(u + 1.0))


#: -3 dB (power) full width of the Hann response, FFT bins (Harris 1978: 1.44).
HANN_3DB_WIDTH_BINS = 2.0 * brentq(lambda u: hann_response(u) ** 2 - 0.5, 0.1, 1.0)


@dataclass(frozen=True)
class ReceiverModel:
    """Receiver parameters of one radar model (sources in the module docstring).

    Attributes
    ----------
    waveform : str
        ``"fmcw"`` or ``"pulse"``.
    window : str
        FMCW range window (``"hann"``); ``""`` for pulse sets.
    floor_db : float
        FMCW far skirt (phase noise, sweep nonlinearity) re. the peak power, dB; -inf for none.
    floor_width_bins : float
        FFT bins from the peak where the skirt has fallen 3 dB (Lorentzian corner ``u0``).
    saturation_db : float
        Output power limit over the noise, dB.
    pulse_by_range : tuple of (float, float)
        Pulse sets: ``(largest range scale m, pulse length s)``, ascending; the last entry covers
        every larger scale.
    if_bandwidth_tau : float
        Pulse sets: IF 3 dB bandwidth times pulse length.
    """

    waveform: str
    window: str = ""
    floor_db: float = -math.inf
    floor_width_bins: float = 10.0
    saturation_db: float = 70.0
    pulse_by_range: tuple[tuple[float, float], ...] = ()
    if_bandwidth_tau: float = 1.2

    def pulse_length_s(self, range_scale_m: float) -> float:
        """Pulse length at a range scale, s (pulse sets)."""
        for max_range_m, tau_s in self.pulse_by_range:
            if range_scale_m <= max_range_m * (1.0 + 1e-9):
                return tau_s
        return self.pulse_by_range[-1][1]


_BROADBAND = ReceiverModel("fmcw", window="hann", floor_db=-65.0, floor_width_bins=10.0, saturation_db=70.0)
#: The receiver of each ``sensors.radar.model`` (3G and 4G share one set of figures: none is published).
RECEIVER_MODELS: dict[str, ReceiverModel] = {
    "broadband-4g": _BROADBAND,
    "broadband-3g": _BROADBAND,
    "magnetron": ReceiverModel("pulse", saturation_db=80.0,
                               pulse_by_range=((3 * M_PER_NM, 0.07e-6), (12 * M_PER_NM, 0.25e-6),
                                               (math.inf, 0.80e-6))),
}


def fft_bin_m(range_resolution_m: float) -> float:
    """FMCW FFT bin in range, ``c / (2 B)``, m, such that the Hann response's -3 dB width is ``range_resolution_m``."""
    return range_resolution_m / HANN_3DB_WIDTH_BINS


def _pulse_response(x_m: np.ndarray, tau_s: float, bandwidth_tau: float) -> np.ndarray:
    """Voltage response of a rectangular pulse (``c tau / 2`` in range) through a Gaussian IF filter.

    The filter's power response ``exp(-4 ln 2 f^2 / B^2)`` has the impulse response
    ``exp(-pi^2 B^2 t^2 / (2 ln 2))``, a Gaussian of standard deviation ``sqrt(ln 2) / (pi B)`` in time,
    ``c sqrt(ln 2) / (2 pi B)`` in range; convolved with the rectangle it gives a difference of erfs.
    """
    from scipy.special import erf

    half_m = C_MPS * tau_s / 4.0
    sigma_m = C_MPS * math.sqrt(math.log(2.0)) / (2.0 * math.pi * bandwidth_tau / tau_s)
    s = math.sqrt(2.0) * sigma_m
    return 0.5 * (erf((x_m + half_m) / s) - erf((x_m - half_m) / s))


def _continuous(rx: ReceiverModel, range_resolution_m: float, range_scale_m: float):
    """The model's continuous voltage response (of range offset, m, peak about 1) and its half-extent, m."""
    if rx.waveform == "fmcw":
        bin_m = fft_bin_m(range_resolution_m)
        # Hann sidelobe envelope ~ 1 / (pi u^3): deep enough at u = (10^(depth/20) / pi)^(1/3)
        u_main = (10.0 ** (KERNEL_DEPTH_DB / 20.0) / math.pi) ** (1.0 / 3.0)
        u_floor = 0.0
        if np.isfinite(rx.floor_db):
            u_floor = rx.floor_width_bins * math.sqrt(max(10.0 ** ((rx.floor_db + KERNEL_DEPTH_DB) / 10.0) - 1.0, 0.0))
        return (lambda x: hann_response(x / bin_m)), max(u_main, u_floor) * bin_m
    tau_s = rx.pulse_length_s(range_scale_m)
    sigma_m = C_MPS * tau_s * math.sqrt(math.log(2.0)) / (2.0 * math.pi * rx.if_bandwidth_tau)
    half = C_MPS * tau_s / 4.0 + sigma_m * math.sqrt(2.0 * KERNEL_DEPTH_DB / 20.0 * math.log(10.0)) + 1.0
    return (lambda x: _pulse_response(x, tau_s, rx.if_bandwidth_tau)), half


def _cell_rms(fn, offsets_m: np.ndarray, dr_m: float) -> np.ndarray:
    """RMS of ``fn`` over cells of width ``dr_m`` centred at ``offsets_m``, with the sign of ``fn`` at the centre."""
    sub = (np.arange(CELL_SUBSAMPLES) - CELL_SUBSAMPLES // 2) / CELL_SUBSAMPLES * dr_m
    values = fn(offsets_m[:, None] + sub[None, :])
    rms = np.sqrt(np.mean(values * values, axis=1))
    return np.where(values[:, CELL_SUBSAMPLES // 2] < 0.0, -rms, rms)


def _half_samples(half_m: float, dr_m: float, max_half_samples: int | None) -> int:
    h = int(math.ceil(half_m / dr_m)) + 1
    return min(h, max_half_samples) if max_half_samples is not None else h


def range_response(model: str, dr_m: float, range_resolution_m: float, range_scale_m: float = M_PER_NM,
                   max_half_samples: int | None = None) -> np.ndarray:
    """Range impulse response (voltage, coherent part) of a model at the output sample spacing.

    Parameters
    ----------
    model : str
        A key of :data:`RECEIVER_MODELS`.
    dr_m : float
        Output sample spacing, m (``range_scale / (N - 1)``).
    range_resolution_m : float
        FMCW: the -3 dB (power) width of the response, m. Unused by pulse sets (``c tau / 2``).
    range_scale_m : float
        Range scale, m (selects the pulse length of pulse sets).
    max_half_samples : int, optional
        Cap on the half-length (the spoke's sample count is enough).

    Returns
    -------
    (2 H + 1,) float64
        Centred (index H is the target's own sample), 1 there; real: the FMCW window spectrum's
        sidelobes alternate in sign. Convolve complex amplitudes with it.
    """
    rx = RECEIVER_MODELS[model]
    fn, half_m = _continuous(rx, range_resolution_m, range_scale_m)
    h = _half_samples(half_m, dr_m, max_half_samples)
    kernel = _cell_rms(fn, np.arange(-h, h + 1) * dr_m, dr_m)
    return kernel / kernel[h]


def range_floor(model: str, dr_m: float, range_resolution_m: float, range_scale_m: float = M_PER_NM,
                max_half_samples: int | None = None) -> np.ndarray:
    """Incoherent skirt (power, re. the peak power) of a model, the same length as :func:`range_response`.

    FMCW: ``10^(F/10) / (1 + (u / u0)^2)`` at ``u`` FFT bins, averaged over each cell; zeros for pulse sets.

    Returns
    -------
    (2 H + 1,) float64
    """
    rx = RECEIVER_MODELS[model]
    _, half_m = _continuous(rx, range_resolution_m, range_scale_m)
    h = _half_samples(half_m, dr_m, max_half_samples)
    if rx.waveform != "fmcw" or not np.isfinite(rx.floor_db):
        return np.zeros(2 * h + 1)
    u0_m = rx.floor_width_bins * fft_bin_m(range_resolution_m)
    skirt = _cell_rms(lambda x: np.sqrt(10.0 ** (rx.floor_db / 10.0) / (1.0 + (x / u0_m) ** 2)),
                      np.arange(-h, h + 1) * dr_m, dr_m)
    return skirt * skirt


def convolve_range(amplitude: np.ndarray, kernel: np.ndarray, floor: np.ndarray | None = None) -> np.ndarray:
    """Echo power along range: ``|a * h|^2 + |a|^2 * f`` per spoke (convolutions along axis 1, 'same' size).

    Only the rows (spokes) holding an echo are transformed (FFT convolution).

    Parameters
    ----------
    amplitude : (S, N) complex or float
        Echo voltage per (spoke, sample), ``|a|^2`` = power re. noise.
    kernel : (2 H + 1,) float
        :func:`range_response`.
    floor : (2 H + 1,) float, optional
        :func:`range_floor`.

    Returns
    -------
    (S, N) float32
        Power re. noise.
    """
    power = np.zeros(amplitude.shape, dtype=np.float32)
    rows = np.flatnonzero(np.any(amplitude != 0, axis=1))
    if rows.size == 0:
        return power
    a = amplitude[rows]
    n = a.shape[1]
    h = kernel.size // 2
    v = fftconvolve(a, kernel[None, :], axes=1)[:, h: h + n]
    p = np.abs(v) ** 2
    if floor is not None and np.any(floor > 0):
        p += np.maximum(fftconvolve(np.abs(a) ** 2, floor[None, :], axes=1)[:, h: h + n], 0.0)
    power[rows] = p
    return power


def apply_range_response(amplitude: np.ndarray, model: str, dr_m: float, range_resolution_m: float,
                         range_scale_m: float) -> np.ndarray:
    """:func:`convolve_range` with the model's :func:`range_response` and :func:`range_floor`.

    Parameters
    ----------
    amplitude : (S, N) complex
        Echo voltage per (spoke, sample), ``|a|^2`` = power re. noise.
    model, dr_m, range_resolution_m, range_scale_m
        As :func:`range_response`.

    Returns
    -------
    (S, N) float32
        Power re. noise.
    """
    n = amplitude.shape[1]
    kw = dict(range_scale_m=range_scale_m, max_half_samples=n)
    return convolve_range(amplitude, range_response(model, dr_m, range_resolution_m, **kw),
                          range_floor(model, dr_m, range_resolution_m, **kw))


def saturate(power: np.ndarray, saturation_db: float, p: float = RAPP_P, out: np.ndarray | None = None) -> np.ndarray:
    """Receiver limiter (Rapp 1991): ``P / (1 + (P / P_sat)^p)^(1/p)``, ``P_sat = 10^(saturation_db / 10)``.

    Monotonic; the identity far below ``P_sat`` (relative error ``(P / P_sat)^p / p``); never above ``P_sat``,
    ``P_sat 2^(-1/p)`` at ``P = P_sat``.

    Parameters
    ----------
    power : (S, N) float32
        Linear power re. noise.
    saturation_db : float
        Limit over the noise, dB.
    p : float
        Smoothness (the larger, the harder the knee).
    out : (S, N) float32, optional
        Where to write (may be ``power`` itself); by default a new array.

    Returns
    -------
    (S, N) float32
    """
    if out is None:
        out = np.array(power, dtype=np.float32)  # a copy
    elif out is not power:
        out[...] = power
    # below LIMITER_ACTIVE x P_sat the gain differs from 1 by less than float32's resolution: only the rest is
    # computed, in float64 (r^p overflows float32, and its rounding would break monotonicity near P_sat)
    p_sat = 10.0 ** (saturation_db / 10.0)
    strong = np.flatnonzero(out.reshape(-1) > np.float32(LIMITER_ACTIVE * p_sat))
    if strong.size:
        x = out.reshape(-1)[strong].astype(np.float64)
        out.reshape(-1)[strong] = x * np.power(1.0 + np.power(x / p_sat, p), -1.0 / p)
    return out


__all__ = ["HANN_3DB_WIDTH_BINS", "RECEIVER_MODELS", "ReceiverModel", "apply_range_response", "convolve_range",
           "fft_bin_m", "hann_response", "range_floor", "range_response", "saturate"]

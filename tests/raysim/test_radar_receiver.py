"""Radar receiver (issue 19): range response per model, saturation, blooming on fixed video levels."""

import math

import numpy as np
import pytest

from raysim.sensors import radar_physics as phys
from raysim.sensors import radar_receiver as rr

C = phys.C_MPS
RES_M = 2.5  # REF 3.3 range resolution
FINE_DR_M = 0.02  # fine sampling: the cell RMS is then the continuous response


def _width_m(kernel: np.ndarray, dr_m: float, level: float) -> float:
    """Full width of the main lobe where |kernel| >= level (contiguous around the centre), m."""
    h = kernel.size // 2
    above = np.abs(kernel) >= level
    right = np.argmin(above[h:])  # first sample below the level
    left = np.argmin(above[h::-1])
    # linear interpolation of the crossings
    def cross(i_in, i_out):
        a, b = abs(kernel[i_in]), abs(kernel[i_out])
        return (a - level) / (a - b)
    return (right - 1 + cross(h + right - 1, h + right) + left - 1 + cross(h - left + 1, h - left)) * dr_m


def test_hann_window_spectrum_matches_harris():
    # Harris 1978, table 1: Hann 3 dB bandwidth 1.44 bins; 6 dB bandwidth 2.00 bins; first null at 2 bins
    assert rr.HANN_3DB_WIDTH_BINS == pytest.approx(1.44, abs=0.005)
    assert rr.hann_response(1.0) == pytest.approx(0.5)
    assert abs(rr.hann_response(2.0)) < 1e-12


def test_fmcw_response_width_is_the_range_resolution():
    k = rr.range_response("broadband-4g", FINE_DR_M, RES_M)
    assert k[k.size // 2] == 1.0
    assert _width_m(k, FINE_DR_M, 2**-0.5) == pytest.approx(RES_M, rel=0.05)
    # a different resolution scales it
    k5 = rr.range_response("broadband-4g", FINE_DR_M, 5.0)
    assert _width_m(k5, FINE_DR_M, 2**-0.5) == pytest.approx(5.0, rel=0.05)


def test_fmcw_first_sidelobe_and_falloff_are_hann():
    k = rr.range_response("broadband-3g", FINE_DR_M, RES_M)
    h = k.size // 2
    u = (np.arange(k.size) - h) * FINE_DR_M / rr.fft_bin_m(RES_M)
    p_db = 20 * np.log10(np.abs(k) + 1e-300)
    first = (u > 2.0) & (u < 3.0)
    assert p_db[first].max() == pytest.approx(-31.5, abs=1.0)
    assert k[first][np.argmax(p_db[first])] < 0  # sidelobes alternate: the first is negative
    # 18 dB/octave: sidelobe peaks near u = 4.5 and 9.5 (one octave apart, roughly) differ by about 18 dB
    near = lambda lo, hi: p_db[(u > lo) & (u < hi)].max()
    drop = near(4.0, 5.0) - near(8.5, 9.5)  # u ratio 2.1 = 1.07 octaves
    assert drop == pytest.approx(18.0 * math.log2(9.0 / 4.5), abs=2.0)


def test_fmcw_floor_level_and_shape():
    rx = rr.RECEIVER_MODELS["broadband-4g"]
    f = rr.range_floor("broadband-4g", FINE_DR_M, RES_M)
    h = f.size // 2
    assert 10 * np.log10(f[h]) == pytest.approx(rx.floor_db, abs=0.05)
    u0 = int(round(rx.floor_width_bins * rr.fft_bin_m(RES_M) / FINE_DR_M))
    assert 10 * np.log10(f[h + u0]) == pytest.approx(rx.floor_db - 3.01, abs=0.05)  # Lorentzian corner
    # far out, the coherent sidelobes are below the floor: the floor dominates the skirt
    k = rr.range_response("broadband-4g", FINE_DR_M, RES_M)
    assert k[h + 3 * u0] ** 2 < f[h + 3 * u0]
    # the kernel reaches until the whole response is 100 dB down
    assert f[0] + k[0] ** 2 < 10 ** (-rr.KERNEL_DEPTH_DB / 10) * 1.05
    assert np.all(rr.range_floor("magnetron", FINE_DR_M, RES_M) == 0.0)


@pytest.mark.parametrize("range_scale_m, tau_s", [(926.0, 0.07e-6), (5556.0, 0.07e-6), (11112.0, 0.25e-6),
                                                  (44448.0, 0.80e-6)])
def test_magnetron_response_is_the_pulse_length(range_scale_m, tau_s):
    rx = rr.RECEIVER_MODELS["magnetron"]
    assert rx.pulse_length_s(range_scale_m) == tau_s  # the Simrad Argus table
    k = rr.range_response("magnetron", 0.05, RES_M, range_scale_m)
    # half amplitude (-6 dB) at the rectangle's edges: width c tau / 2
    assert _width_m(k, 0.05, 0.5) == pytest.approx(C * tau_s / 2.0, rel=0.05)
    assert np.all(k >= 0.0) and np.all(np.diff(k[k.size // 2:]) <= 1e-12)  # no range sidelobes


def test_kernel_at_the_output_spacing_does_not_fall_on_the_nulls():
    # dR = one FFT bin: point samples would hit every null of the Hann spectrum; the cell RMS keeps the skirt
    dr = rr.fft_bin_m(RES_M)
    k = rr.range_response("broadband-4g", dr, RES_M)
    h = k.size // 2
    assert k[h] == 1.0 and np.all(np.abs(k[h + 2: h + 6]) > 1e-3)


def test_saturation_is_monotonic_identity_below_and_limited_above():
    p_db = np.linspace(-20.0, 120.0, 1401, dtype=np.float32)
    p = (10.0 ** (p_db / 10.0)).astype(np.float32)
    out = rr.saturate(p[None, :], 70.0)[0]
    assert out.dtype == np.float32
    assert np.all(np.diff(out) >= 0.0)
    below = p_db <= 40.0
    assert np.allclose(out[below], p[below], rtol=1e-3)
    assert out.max() <= np.float32(1e7) * (1 + 1e-6)
    assert 10 * np.log10(out[p_db >= 90.0]).min() == pytest.approx(70.0, abs=0.01)
    # Rapp's knee: 1 dB compression at P_sat (p = 3: 2^(-1/3)), 0.045 dB at 5 dB below it
    assert 10 * np.log10(rr.saturate(np.float32([1e7]), 70.0)[0]) == pytest.approx(70.0 - 10 * np.log10(2) / 3, abs=0.01)
    assert 10 * np.log10(rr.saturate(np.float32([10 ** 6.5]), 70.0)[0]) == pytest.approx(
        65.0 - 10 * np.log10(1 + 10 ** -1.5) / 3, abs=0.005)
    assert 10 * np.log10(rr.saturate(np.float32([10 ** 6.5]), 70.0)[0]) < 64.96
    assert np.isfinite(rr.saturate(np.float32([3e38]), 70.0)).all()


def _video_extent_m(level_db: float, model: str, dr_m: float, n: int = 1024) -> float:
    a = np.zeros((1, n), np.complex64)
    a[0, n // 2] = 10 ** (level_db / 20)
    power = rr.apply_range_response(a, model, dr_m, RES_M, dr_m * (n - 1))
    power = rr.saturate(power, rr.RECEIVER_MODELS[model].saturation_db)
    v = phys.quantise(10 * np.log10(np.maximum(power, 1e-30)), 6.6, 3.0)[0]
    idx = np.flatnonzero(v >= 1)
    return (idx.max() - idx.min() + 1) * dr_m


def test_strong_fmcw_echo_blooms_along_range():
    dr = 1852.0 / 1023
    strong, weak = _video_extent_m(80.0, "broadband-4g", dr), _video_extent_m(30.0, "broadband-4g", dr)
    assert strong > 3.0 * weak
    assert weak < 3 * RES_M  # a 30 dB echo paints about its resolution
    # the magnetron's pulse has no FFT sidelobes: its 80 dB echo is only its pulse, smeared
    assert _video_extent_m(80.0, "magnetron", dr) < 2.0 * _video_extent_m(30.0, "magnetron", dr)


def test_convolution_is_coherent_and_only_on_rows_with_echoes():
    n, dr = 256, 1.0
    k = rr.range_response("broadband-4g", dr, RES_M)
    a = np.zeros((3, n), np.complex128)
    a[1, 100] = 1.0
    a[1, 101] = -1.0  # two echoes in antiphase one sample apart partly cancel
    a[2, 100] = 1.0
    p = rr.convolve_range(a, k)
    assert np.all(p[0] == 0.0)
    assert p[2, 100] == pytest.approx(1.0, rel=1e-6)
    assert p[1, 100] == pytest.approx((1.0 - k[k.size // 2 + 1]) ** 2, rel=1e-4)
    assert p[1].max() < 1.0

"""The radar's fast paths against plain dense references: the beam over spokes and the range skirt (issue 23)."""

from __future__ import annotations

import numpy as np
import pytest

from raysim.sensors import radar_targets
from tests.raysim.test_radar_targets import SAMPLES, SPOKES, renderer


@pytest.fixture(scope="module")
def radar(tmp_path_factory):
    return renderer(tmp_path_factory.mktemp("fast"), "fast")


def _echo_cells(rng: np.random.Generator, rows_count: int, per_row: int, amplitude: float):
    """Random spokes (R,), increasing flat cells in their (R, N) array and complex64 values of ``amplitude``."""
    rows = np.sort(rng.choice(SPOKES, rows_count, replace=False))
    cells = np.unique(np.concatenate([r * SAMPLES + rng.choice(np.arange(20, SAMPLES - 20), per_row, replace=False)
                                      for r in range(rows_count)]))
    phase = rng.uniform(0.0, 2.0 * np.pi, cells.size)
    values = (amplitude * rng.uniform(0.5, 1.0, cells.size) * np.exp(1j * phase)).astype(np.complex64)
    return rows, cells, values


def _dense_beam_power(radar, rows, cells, values) -> np.ndarray:
    """(S, N) |range response * two-way voltage beam over spokes|^2, dense, complex128 (no skirt)."""
    field = np.zeros((SPOKES, SAMPLES), complex)
    field[rows[cells // SAMPLES], cells % SAMPLES] = values
    half = radar.range_kernel.size // 2
    field = np.stack([np.convolve(row, radar.range_kernel)[half: half + SAMPLES] for row in field])
    beam = np.fft.ifft(np.fft.fft(field, axis=0) * radar.az_kernel_f[:, None], axis=0)
    return np.abs(beam) ** 2


@pytest.mark.parametrize("rows_count", [3, 40])
def test_beam_over_spokes_equals_the_dense_correlation(radar, rows_count):
    rng = np.random.default_rng(rows_count)
    rows, cells, values = _echo_cells(rng, rows_count, 4, 30.0)  # 30 dB: no skirt over INVISIBLE_SNR
    power = radar.targets._beam(rows, cells, values)
    expected = _dense_beam_power(radar, rows, cells, values)
    assert power.shape == (SPOKES, SAMPLES) and power.dtype == np.float32
    np.testing.assert_allclose(power, expected, rtol=1e-3, atol=1e-4 * expected.max())


@pytest.mark.parametrize("rows_count", [10, 200])  # the matrix product (<= 64 spokes) and the FFT over all spokes
def test_range_skirt_over_spokes_equals_the_dense_circular_sum(radar, rows_count):
    rng = np.random.default_rng(100 + rows_count)
    rows, cells, values = _echo_cells(rng, rows_count, 2, 1e4)  # 80 dB echoes: their skirt shows
    spread = radar.targets._skirt(rows, cells, values)
    assert spread is not None
    blocks, spokes = spread
    assert (spokes is None) == (rows_count > radar_targets.SKIRT_MATMUL_MAX_SPOKES)
    # the dense reference: every echo row's blocks (the range part, shared), then sum_s P[(i - s) % S] skirt[s]
    power = np.zeros((rows_count, SAMPLES), np.float32)
    power[cells // SAMPLES, cells % SAMPLES] = np.abs(values.astype(complex)) ** 2
    per_row = radar.range_skirt(power)
    offsets = (np.arange(SPOKES)[:, None] - rows[None, :]) % SPOKES
    expected = radar.az_power_pattern.astype(float)[offsets] @ per_row.astype(float)  # (S, B)
    got = np.zeros_like(expected)
    got[slice(None) if spokes is None else spokes] = blocks
    assert blocks.dtype == np.float32 and blocks.flags.c_contiguous
    assert expected.max() > 100 * radar_targets.INVISIBLE_SNR
    # the matrix product leaves out the spokes where even the strongest skirt stays under INVISIBLE_SNR (by design)
    np.testing.assert_allclose(got, expected, rtol=1e-3, atol=radar_targets.INVISIBLE_SNR)

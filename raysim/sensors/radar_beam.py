"""The radar's point-spread: the antenna pattern over spokes and the range impulse response along range.

:func:`antenna_pattern` and :func:`range_kernel` build, from a renderer's :class:`RadarParams`, the two
kernels the coherent target sum (:mod:`raysim.sensors.radar_targets`) is convolved with.
"""

from __future__ import annotations

import math

import numpy as np


__all__ = ["GaussianPattern", "antenna_pattern", "range_kernel"]

#: The coherent range response is cut where its power stays under this fraction of the peak (-80 dB).
KERNEL_CUT = 1e-8


class GaussianPattern:
    """A sidelobe-free Gaussian beam (the model before issue 19; kept for comparison).

    One-way power ``exp(-4 ln2 theta^2 / theta3^2)``, so the one-way voltage is its square root.
    """

    def __init__(self, beam_az_deg: float, beam_el_deg: float):
        self.beam_az_deg, self.beam_el_deg = beam_az_deg, beam_el_deg

    @staticmethod
    def _voltage(theta_deg, width_deg: float) -> np.ndarray:
        t = np.asarray(theta_deg, dtype=float)
        return np.exp(-2.0 * math.log(2.0) * t * t / (width_deg * width_deg))

    def horizontal_voltage(self, theta_deg) -> np.ndarray:
        """One-way voltage (complex, peak 1) at azimuth offsets, deg."""
        t = (np.asarray(theta_deg, dtype=float) + 180.0) % 360.0 - 180.0
        return self._voltage(t, self.beam_az_deg).astype(complex)

    def vertical_voltage(self, el_deg) -> np.ndarray:
        """One-way voltage (peak 1) at elevations in the antenna frame, deg."""
        return self._voltage(el_deg, self.beam_el_deg)

    def spoke_kernel(self, spokes: int) -> np.ndarray:
        """(S,) complex two-way voltage at circular spoke offsets 0..S-1."""
        j = np.arange(spokes)
        theta = np.where(j > spokes // 2, j - spokes, j) * (360.0 / spokes)
        return self.horizontal_voltage(theta) ** 2


def antenna_pattern(params, seed: int):
    """The antenna of ``params`` (:class:`raysim.sensors.radar.RadarParams`): aperture pattern or Gaussian."""
    if getattr(params, "sidelobe_db", None) is None:
        return GaussianPattern(params.beam_az_deg, params.beam_el_deg)
    from raysim.sensors.radar_antenna import AntennaPattern

    return AntennaPattern(params.beam_az_deg, params.beam_el_deg, params.sidelobe_db, seed, params.f_ghz)


def range_kernel(params, dr_m: float, range_scale_m: float, samples: int) -> tuple[np.ndarray, np.ndarray | None]:
    """The range impulse response of ``params.model`` at the sample spacing ``dr_m``.

    Returns
    -------
    coherent : (L,) float64
        Voltage response (peak 1, centred, odd length; :func:`raysim.sensors.radar_receiver.range_response`),
        cut where its power stays under ``KERNEL_CUT`` of the peak.
    skirt : (M,) float64 or None
        Incoherent power skirt (phase noise, sweep nonlinearity; :func:`raysim.sensors.radar_receiver.range_floor`),
        None if the model has none.
    """
    from raysim.sensors import radar_receiver

    kw = dict(range_scale_m=range_scale_m, max_half_samples=samples)
    coherent = radar_receiver.range_response(params.model, dr_m, params.range_resolution_m, **kw)
    skirt = radar_receiver.range_floor(params.model, dr_m, params.range_resolution_m, **kw)
    half = coherent.size // 2
    strong = np.flatnonzero(coherent**2 >= KERNEL_CUT)
    reach = int(np.max(np.abs(strong - half))) if strong.size else 0
    coherent = coherent[half - reach: half + reach + 1]
    return coherent, (skirt if np.any(skirt > 0) else None)


def convolve_rows_sparse(rows: np.ndarray, kernel: np.ndarray, nonzero: np.ndarray | None = None) -> np.ndarray:
    """Convolve each row of a sparse (M, N) array with a centred odd kernel (``'same'`` size, zeros beyond the ends).

    The target field of a revolution holds a few thousand non-zero cells in some 500 x 1024: spreading each
    non-zero cell over the kernel's taps costs (cells x taps) instead of an FFT of every row.

    Parameters
    ----------
    rows : (M, N) float or complex
        The array (mostly zeros).
    kernel : (L,) float
        Centred kernel, L odd.
    nonzero : (Q,) int, optional
        Flat indices of the cells that may be non-zero (found by a scan when not given).

    Returns
    -------
    (M, N) array of the type of ``rows``
        ``out[m, n] = sum_k rows[m, n - k] kernel[k + L // 2]``, k from -L // 2 to L // 2.
    """
    flat = np.flatnonzero(rows) if nonzero is None else np.asarray(nonzero)
    return convolve_cells(rows.reshape(-1)[flat], flat, rows.shape, kernel)


def convolve_cells(values: np.ndarray, flat: np.ndarray, shape: tuple[int, int], kernel: np.ndarray) -> np.ndarray:
    """:func:`convolve_rows_sparse` of the (M, N) array that holds ``values`` at the flat indices ``flat``, else 0.

    Parameters
    ----------
    values : (Q,) float or complex
        The non-zero cells' values.
    flat : (Q,) int
        Their flat indices in the (M, N) array (distinct).
    shape : (int, int)
        M, N.
    kernel : (L,) float
        Centred kernel, L odd.

    Returns
    -------
    (M, N) array of the type of ``values``
    """
    m, n = shape
    cells, out_values = convolve_cells_compact(values, flat, shape, kernel)
    out = np.zeros(m * n, out_values.dtype)
    out[cells] = out_values
    return out.reshape(m, n)


def convolve_cells_compact(values: np.ndarray, flat: np.ndarray, shape: tuple[int, int],
                           kernel: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`convolve_cells` on the cells it reaches only: no dense (M, N) array is formed.

    A coast paints on every spoke, so M is all spokes while the cells reached are a few per cent of (M, N): the
    dense output's zeros would cost more than the sums. Each reached cell's sum is taken over its contributions in
    the same order and in float64 as a dense ``np.bincount`` would, so the values equal :func:`convolve_cells`'s
    bit for bit. Parameters as :func:`convolve_cells`.

    Returns
    -------
    cells : (P,) int64
        Increasing flat indices of the cells some tap reaches (a reached cell may sum to zero).
    out_values : (P,) of the type of ``values``
        The convolution at ``cells``.
    """
    n = shape[1]
    half = kernel.size // 2
    cols = flat % n
    row_start = flat - cols
    # each cell reaches the run [lo, hi] of its row; the runs start and end in increasing order (flat increases),
    # so their union is, run by run, the cells past the previous run's end: first .. hi
    lo = np.maximum(flat - half, row_start)
    hi = np.minimum(flat + half, row_start + n - 1)
    first = np.maximum(lo, np.r_[-1, hi[:-1]] + 1)
    count = np.maximum(hi - first + 1, 0)
    before = np.cumsum(count) - count  # reached cells before ``first``: every cell lo .. hi is reached, so the
    # slot of cell c of run q is before_q + (c - first_q)
    cells = np.repeat(first - before, count) + np.arange(int(count.sum()))
    taps = np.arange(-half, half + 1)
    target = cols[:, None] + taps[None, :]  # (Q, L) column each tap lands on
    inside = (target >= 0) & (target < n)
    slot = (flat - first + before)[:, None] + taps[None, :]
    slot = slot[inside]
    parts = (values.real, values.imag) if np.iscomplexobj(values) else (values,)
    # float64 products and sums, taken in the order a dense ``np.bincount`` over (Q, L) takes them
    sums = [np.bincount(slot, weights=(part[:, None] * kernel[None, :])[inside], minlength=cells.size)
            for part in parts]
    out_values = np.empty(cells.size, values.dtype)
    if len(sums) == 2:
        out_values.real, out_values.imag = sums
    else:
        out_values[:] = sums[0]
    return cells, out_values


def block_kernel(kernel: np.ndarray | None, block: int) -> np.ndarray | None:
    """A centred odd kernel on blocks of ``block`` samples: the mean of its taps over each block offset.

    The response at any sample of block ``b`` to unit power anywhere in block ``b0`` is taken as the mean of
    ``kernel`` over the offsets ``(b - b0) block + (-block/2 .. block/2)``; right for a kernel that changes little
    over a block (the range skirt's Lorentzian pedestal).

    Parameters
    ----------
    kernel : (2 H + 1,) float or None
    block : int
        Samples per block.

    Returns
    -------
    (2 J + 1,) float32 or None
        J = ceil(H / block) blocks each way; None if ``kernel`` is None.
    """
    if kernel is None:
        return None
    half = kernel.size // 2
    reach = -(-half // block)
    padded = np.zeros(2 * reach * block + block)
    start = reach * block + block // 2 - half
    padded[start: start + kernel.size] = kernel
    return padded.reshape(2 * reach + 1, block).mean(axis=1).astype(np.float32)

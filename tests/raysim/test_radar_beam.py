"""The sparse range convolution of radar echo cells (raysim.sensors.radar_beam)."""
import numpy as np
import pytest

from raysim.sensors.radar_beam import convolve_cells, convolve_cells_compact


def _dense_bincount(values: np.ndarray, flat: np.ndarray, shape: tuple[int, int], kernel: np.ndarray) -> np.ndarray:
    """The dense (M, N) sum over every cell and tap by one ``np.bincount`` (the form the renderer used before)."""
    m, n = shape
    half = kernel.size // 2
    taps = np.arange(-half, half + 1)
    target = (flat % n)[:, None] + taps[None, :]
    inside = (target >= 0) & (target < n)
    where = (flat[:, None] + taps[None, :])[inside]
    spread = (values[:, None] * kernel[None, :])[inside]
    out = np.empty(m * n, values.dtype)
    out.real = np.bincount(where, weights=spread.real, minlength=m * n)
    out.imag = np.bincount(where, weights=spread.imag, minlength=m * n)
    return out.reshape(m, n)


def _sparse_field(rng: np.random.Generator, shape: tuple[int, int], count: int) -> tuple[np.ndarray, np.ndarray]:
    """``count`` random cells of an (M, N) array, with runs along rows like a coast's, complex64 values."""
    m, n = shape
    flat = np.unique(np.concatenate([rng.choice(m * n, count, replace=False),
                                     np.arange(m) * n + n // 2, np.arange(m) * n + n // 2 + 1, [0, m * n - 1]]))
    values = (rng.normal(size=flat.size) + 1j * rng.normal(size=flat.size)).astype(np.complex64)
    return flat, values


@pytest.mark.parametrize("shape, count, taps", [((40, 30), 50, 7), ((7, 5), 20, 9), ((64, 256), 600, 25), ((1, 3), 1, 1)])
def test_compact_convolution_equals_each_row_convolved(shape, count, taps):
    rng = np.random.default_rng(taps)
    flat, values = _sparse_field(rng, shape, min(count, shape[0] * shape[1] - 2))
    kernel = rng.normal(size=taps)
    dense = np.zeros(shape, np.complex128)
    dense.flat[flat] = values
    half = taps // 2
    expected = np.stack([np.convolve(row, kernel)[half: half + shape[1]] for row in dense])  # centred, same size
    cells, out = convolve_cells_compact(values, flat, shape, kernel)
    got = np.zeros(shape[0] * shape[1], np.complex64)
    got[cells] = out
    np.testing.assert_allclose(got.reshape(shape), expected, rtol=1e-5, atol=1e-5)
    # the cells are exactly those a tap reaches: within half the kernel of an echo cell, in its row
    reached = np.zeros(shape, bool)
    rows, cols = np.divmod(flat, shape[1])
    for offset in range(-(taps // 2), taps // 2 + 1):
        ok = (cols + offset >= 0) & (cols + offset < shape[1])
        reached[rows[ok], cols[ok] + offset] = True
    np.testing.assert_array_equal(cells, np.flatnonzero(reached))


def test_compact_and_dense_forms_give_the_dense_bincount_bit_for_bit():
    rng = np.random.default_rng(5)
    shape = (300, 512)
    flat, values = _sparse_field(rng, shape, 3000)
    values[::7] = 0
    kernel = rng.normal(size=25)
    reference = _dense_bincount(values, flat, shape, kernel)
    assert convolve_cells(values, flat, shape, kernel).tobytes() == reference.tobytes()
    cells, out = convolve_cells_compact(values, flat, shape, kernel)
    assert out.tobytes() == reference.reshape(-1)[cells].tobytes()
    assert not np.any(np.delete(reference.reshape(-1), cells))

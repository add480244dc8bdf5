"""raysim.sensors.blas_threads: one OpenBLAS thread for a block, the count restored, products unchanged."""

import numpy as np
import pytest

from raysim.sensors.blas_threads import blas_thread_control, single_blas_thread


def test_single_thread_inside_and_previous_count_after():
    control = blas_thread_control()
    if control is None:
        pytest.skip("numpy's BLAS is not a bundled OpenBLAS")
    get, put = control
    before = get()
    put(2)
    try:
        with single_blas_thread():
            assert get() == 1
        assert get() == 2
        with pytest.raises(RuntimeError), single_blas_thread():
            raise RuntimeError("restored on the way out too")
        assert get() == 2
    finally:
        put(before)


def test_products_do_not_depend_on_the_thread_count():
    """The renderers' tall, thin products (foam field, rays) are bit for bit the same on one thread."""
    rng = np.random.default_rng(5)
    local = rng.normal(size=(40_000, 3)).astype(np.float32)
    waves = rng.normal(size=(3, 8)).astype(np.float32)
    d = rng.normal(size=(500, 32, 3))
    r = rng.normal(size=(500, 3, 3))
    control = blas_thread_control()
    if control is not None:
        control[1](2)
    many = (local @ waves, d @ r)
    with single_blas_thread():
        one = (local @ waves, d @ r)
    for a, b in zip(many, one):
        assert a.tobytes() == b.tobytes()

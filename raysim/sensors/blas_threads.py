"""One BLAS thread for the renderers' small matrix products.

Every matrix product of a LiDAR chunk is tall and thin (rays x 3 times 3 x 3, foam points x 3
times 3 x 8): far too small for OpenBLAS's worker threads to pay. On a machine whose cores are
busy (two agents, a TDM, a live receiver), handing such a product to the worker threads costs
milliseconds of waiting where one thread takes a fraction of one: measured on the project's
2-core VM with both cores busy (2026-11-27), a (27000, 3) x (3, 8) float32 product (the foam
field of one LiDAR revolution, :meth:`raysim.sea.FoamField.is_foam`) took 8.0 ms with the default
two threads and 0.18 ms with one. The products' values do not depend on the
thread count (OpenBLAS splits the output rows and columns among threads, never the summation),
so outputs stay byte-identical.

:func:`single_blas_thread` sets numpy's OpenBLAS to one thread for a block and restores the
previous count; where numpy's BLAS is not an OpenBLAS it finds (another BLAS, a build without
``numpy.libs``), it does nothing.
"""

from __future__ import annotations

import ctypes
import glob
import os
from contextlib import contextmanager
from typing import Callable, Iterator

import numpy as np

__all__ = ["single_blas_thread", "blas_thread_control"]

#: Symbol names of the thread-count functions: scipy-openblas (numpy's wheels) first, then plain OpenBLAS.
_SYMBOLS = (("scipy_openblas_get_num_threads64_", "scipy_openblas_set_num_threads64_"),
            ("scipy_openblas_get_num_threads", "scipy_openblas_set_num_threads"),
            ("openblas_get_num_threads64_", "openblas_set_num_threads64_"),
            ("openblas_get_num_threads", "openblas_set_num_threads"))

_control: tuple[Callable[[], int], Callable[[int], None]] | None | bool = False


def blas_thread_control() -> tuple[Callable[[], int], Callable[[int], None]] | None:
    """(get, set) of numpy's OpenBLAS thread count, or None if not found (looked up once).

    Returns
    -------
    tuple of callables or None
        ``get() -> int`` and ``set(n: int)``; None where numpy's wheel bundles no OpenBLAS.
    """
    global _control
    if _control is False:
        _control = None
        libs = sorted(glob.glob(os.path.join(os.path.dirname(np.__file__) + ".libs", "*openblas*.so*")))
        for path in libs:
            try:
                lib = ctypes.CDLL(path)  # already loaded by numpy: the same handle
            except OSError:
                continue
            for get_name, set_name in _SYMBOLS:
                if hasattr(lib, get_name) and hasattr(lib, set_name):
                    get, put = getattr(lib, get_name), getattr(lib, set_name)
                    get.restype, get.argtypes = ctypes.c_int, []
                    put.restype, put.argtypes = None, [ctypes.c_int]
                    _control = (get, put)
                    break
            if _control is not None:
                break
    return _control


@contextmanager
def single_blas_thread() -> Iterator[None]:
    """Run the block with numpy's OpenBLAS on one thread; the previous count is restored after."""
    control = blas_thread_control()
    if control is None:
        yield
        return
    get, put = control
    previous = int(get())
    if previous == 1:
        yield
        return
    put(1)
    try:
        yield
    finally:
        put(previous)

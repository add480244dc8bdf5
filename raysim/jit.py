"""Compiled kernels: numba where a chain of numpy passes costs more than the work it does.

A LiDAR revolution is about 69,000 rays; numpy spends most of its time on such a chunk
walking arrays between small operations (a batched 3 x 3 product per firing, gathers,
temporaries). A kernel compiled with numba does the same arithmetic in one pass per ray.

Every kernel has the numpy code it replaces beside it, and the tests run both
(``tests/raysim/test_jit.py`` and the kernels' own tests). The compiled path is used when
numba imports and the environment variable ``RAYSIM_JIT`` is not ``0``; :data:`ENABLED` is
read at each call, so a test can switch it. Kernels are cached on disk (numba's
``cache=True``, beside the module), so only the first run of a fresh checkout compiles them.
"""

from __future__ import annotations

import os
from typing import Callable

try:  # numba is a dependency (pyproject.toml); a platform without its wheel keeps the numpy path
    import numba
except ImportError:  # pragma: no cover - every supported platform has numba wheels
    numba = None

#: Use the compiled kernels (numba importable and ``RAYSIM_JIT`` not "0").
ENABLED = numba is not None and os.environ.get("RAYSIM_JIT", "1") != "0"


def kernel(function: Callable) -> Callable:
    """Compile ``function`` with numba (no Python objects, no fast-math, GIL released, cached on disk).

    Without numba the function is returned as it is (callers check :data:`ENABLED` first and
    use their numpy path). No fast-math: the kernels keep IEEE arithmetic in the order written,
    so that they give the numpy path's values wherever the operations are the same.
    """
    if numba is None:  # pragma: no cover
        return function
    return numba.njit(cache=True, nogil=True, error_model="numpy")(function)


__all__ = ["ENABLED", "kernel"]

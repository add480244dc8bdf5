"""The ``.npy`` header text numpy writes, parsed without numpy's Python parser.

``np.lib.format`` writes a format 1.0 header as ``{'descr': '<f4', 'fortran_order': False, 'shape': (3,), }``
padded with spaces to a newline; numpy's reader parses it with ``ast.literal_eval``, the larger part of
reading a small array. Both the TDM's sweep reader (:mod:`tdm.recording.npz`) and raysim's own one-pass
reader (:func:`raysim.recording.npz.read_npz`) parse that text here; any other text gives None and goes
to numpy's parser.
"""

from __future__ import annotations

import re

import numpy as np

__all__ = ["NPY_PREFIX_BYTES", "numpy_header_text"]

#: Magic (6), version (2) and header length (2) before a format 1.0 header's text.
NPY_PREFIX_BYTES = 10
_NUMPY_HEADER_TEXT = re.compile(rb"\{'descr': '([<>|=]?[biufc]\d{1,2})', 'fortran_order': (True|False), "
                                rb"'shape': \(((?:\d+, )*\d+,?|)\), \} *\n")


def numpy_header_text(data: bytes, start: int, end: int) -> tuple[tuple[int, ...], bool, np.dtype] | None:
    """(shape, fortran order, dtype) of the header text ``data[start:end]`` if numpy wrote it, else None."""
    text = _NUMPY_HEADER_TEXT.fullmatch(data, start, end)
    if text is None:
        return None
    shape = tuple(int(n) for n in text.group(3).split(b",") if n.strip())
    return shape, text.group(2) == b"True", np.dtype(text.group(1).decode("ascii"))

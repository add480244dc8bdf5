"""Radar CFAR along range (module docstring of :mod:`tdm.frontend.radar`, steps 1-2).

Video levels to linear power, the training-cell windows and the CFAR decision of every candidate
cell of a sweep. The CA and OS multipliers (:func:`ca_alpha`, :func:`os_alpha`) are the
configuration's (:mod:`tdm.frontend.radar_config`), importable from here too.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from tdm.frontend.radar_config import RadarFrontEndConfig, ca_alpha, os_alpha  # noqa: F401 (names kept here)

__all__ = ["VIDEO_LEVELS", "ca_alpha", "cfar_mask", "os_alpha", "training_table", "video_power", "video_power_table"]

#: Levels of the 4-bit video (docs/reference.md section 3 table: "1024 samples, 4 bits each (0..15)").
VIDEO_LEVELS = 16


#: Cells per chunk of the CFAR's training-cell gathers (bounded memory: chunk x N values).
_CHUNK_CELLS = 1 << 16
#: A video level reads as the power at the centre of its bin: its lower edge plus half a step.
LEVEL_CENTRE_STEPS = 0.5
#: Power of level 0 (everything below the first level), units of the mean noise: the noise mean
#: itself, the zero-noise floor (module docstring of :mod:`tdm.frontend.radar`, step 1).
FLOOR_POWER = 1.0
#: The high bit of one byte: a level plus ``128 - L`` sets it exactly when the level is >= L.
_BYTE_HIGH_BIT = 128
#: Bytes (4-bit levels, one a byte) in one 64-bit word.
_BYTES_PER_WORD = 8


@lru_cache(maxsize=8)
def video_power_table(threshold_db: float, step_db: float) -> np.ndarray:
    """(16,) float32 power of each video level, units of the mean noise (module docstring, step 1)."""
    v = np.arange(VIDEO_LEVELS, dtype=float)
    p = 10.0 ** ((threshold_db + step_db * (v - LEVEL_CENTRE_STEPS)) / 10.0)
    p[0] = FLOOR_POWER
    table = p.astype(np.float32)
    table.setflags(write=False)
    return table


def video_power(echo: np.ndarray, config: RadarFrontEndConfig) -> np.ndarray:
    """Linear power of echo values, float32, units of the mean noise.

    Parameters
    ----------
    echo : array
        Integer video levels 0..15 (mapped by :func:`video_power_table`) or floating-point linear
        power (returned as float32).
    config : RadarFrontEndConfig
    """
    echo = np.asarray(echo)
    if np.issubdtype(echo.dtype, np.integer):
        return video_power_table(config.video_threshold_db, config.video_step_db)[np.clip(echo, 0, VIDEO_LEVELS - 1)]
    return echo.astype(np.float32, copy=False)


@lru_cache(maxsize=32)
def training_table(n_samples: int, first_valid: int, n_training: int, n_guard: int) -> np.ndarray:
    """(n_samples, N) int64 training-cell sample indices of every CUT, ascending.

    The N nearest samples farther than ``n_guard`` from the CUT inside ``[first_valid, n_samples)``:
    N/2 each side in the interior, sliding inwards near either end.
    """
    if n_samples - first_valid < n_training + 2 * n_guard + 1:
        raise ValueError(f"{n_samples - first_valid} valid samples cannot hold {n_training} training cells "
                         f"and 2 x {n_guard} guard cells")
    d = np.arange(n_guard + 1, n_guard + n_training + 1)
    ext = np.stack([d, -d], axis=1).ravel()  # +(G+1), -(G+1), +(G+2), ... nearest first
    idx = np.arange(n_samples)[:, None] + ext[None, :]
    valid = (idx >= first_valid) & (idx < n_samples)
    order = np.argsort(~valid, axis=1, kind="stable")[:, :n_training]
    table = np.sort(np.take_along_axis(idx, order, axis=1), axis=1)
    table.setflags(write=False)
    return table


def _first_valid_sample(range_m: np.ndarray | None, blanking_m: float) -> int:
    """Index of the first sample at or beyond the blanking range (0 without ranges)."""
    if range_m is None or blanking_m <= 0:
        return 0
    return int(np.searchsorted(np.asarray(range_m, dtype=float), blanking_m, side="left"))


def _lowest_candidate_level(config: RadarFrontEndConfig) -> int:
    """Lowest video level that can pass CFAR: its power must exceed alpha x the floor (level 0)."""
    table = video_power_table(config.video_threshold_db, config.video_step_db)
    return max(int(config.min_echo_level), int(np.searchsorted(table, config.alpha * table[0], side="right")))


@lru_cache(maxsize=16)
def _os_blocking_level(alpha: float, threshold_db: float, step_db: float) -> np.ndarray:
    """(16,) per CUT level: the lowest level L with ``alpha P(L) >= P(CUT)`` (16 if none).

    OS-CFAR on video passes a CUT exactly when fewer than ``N - k + 1`` training cells reach it.
    """
    table = video_power_table(threshold_db, step_db).astype(np.float64)
    blocking = np.searchsorted(alpha * table, table, side="left")  # first L with alpha P(L) >= P(cut)
    out = blocking.astype(np.uint8)
    out.setflags(write=False)
    return out


def _training_values(source: np.ndarray, rows: np.ndarray, cols: np.ndarray, config: RadarFrontEndConfig,
                     first: int) -> np.ndarray:
    """(M, N) training values of the CUTs (rows, cols) read from ``source`` (S, N_samples)."""
    n_samples = source.shape[1]
    half, guard = config.training_cells // 2, config.guard_cells
    interior = (cols - guard - half >= first) & (cols + guard + half < n_samples)
    out = np.empty((rows.size, config.training_cells), dtype=source.dtype)
    if interior.any():
        windows = sliding_window_view(source, half, axis=1)  # windows[r, j] = source[r, j:j + half]
        r, c = rows[interior], cols[interior]
        out[interior, :half] = windows[r, c - guard - half]
        out[interior, half:] = windows[r, c + guard + 1]
    edge = ~interior
    if edge.any():
        table = training_table(n_samples, first, config.training_cells, guard)
        out[edge] = source[rows[edge, None], table[cols[edge]]]
    return out


#: One in every byte of a 64-bit word: a byte value times it fills every byte (byte-parallel counting).
_BYTE_ONES = np.uint64(0x0101010101010101)
#: Above this fraction of non-zero words, :func:`_nonzero_flat` reads every byte (on blocks of 256 x 1024
#: cells the word path took 0.5-0.9 of the time at 4-10 % non-zero words, 1.0 at 12 %, 1.8-2.8 at 70 %).
_DENSE_WORD_FRACTION = 0.1
#: Bits in one 64-bit word (bit planes).
_BITS_PER_WORD = 64
#: A blocking level's CUTs are counted on its bit plane when they number at least this fraction of the
#: cells (a plane reads every cell once; on a 2048 x 1024 sweep packing one took 0.1-0.2 ms and counting
#: 77 000 CUTs on it 0.6 ms, on the bytes about 3.5 ms).
_BIT_PLANE_MIN_FRACTION = 1.0 / 128
#: Cells per chunk of the byte-parallel count (bounded temporaries that stay in cache: chunk x 8 bytes each).
_WORD_CHUNK_CELLS = 1 << 15


def _aligned_words(levels: np.ndarray) -> np.ndarray:
    """(ceil(S N / 8),) uint64: the flat uint8 array's bytes, eight a word, word q holding bytes 8q .. 8q + 7.

    A view of ``levels`` when it is C-contiguous, 8-byte aligned and a whole number of words long,
    else a zero-padded copy.
    """
    flat = levels.reshape(-1)
    if (levels.flags.c_contiguous and flat.size % _BYTES_PER_WORD == 0
            and flat.ctypes.data % _BYTES_PER_WORD == 0):
        return flat.view(np.uint64)
    words = np.zeros(-(-flat.size // _BYTES_PER_WORD), dtype=np.uint64)
    words.view(np.uint8)[:flat.size] = flat
    return words


def _nonzero_flat(levels: np.ndarray) -> np.ndarray:
    """(M,) int64 ascending flat indices of the non-zero cells of a uint8 array (``np.flatnonzero``).

    On a sparse sweep, faster through the 64-bit words (:func:`_aligned_words`): only the bytes of
    the non-zero words are looked at. Past ``_DENSE_WORD_FRACTION`` of non-zero words, plain
    ``np.flatnonzero``.
    """
    words = _aligned_words(levels)
    nonzero_words = np.flatnonzero(words != 0)  # on booleans: np.nonzero's fast path, 3-5 times faster
    if nonzero_words.size > _DENSE_WORD_FRACTION * words.size:
        return np.flatnonzero(levels.reshape(-1) != 0)
    byte = np.flatnonzero(words[nonzero_words].view(np.uint8) != 0)
    return (nonzero_words[byte >> 3] << 3) | (byte & (_BYTES_PER_WORD - 1))


@lru_cache(maxsize=16)
def _span_masks(half: int, guard: int) -> np.ndarray:
    """(W, 8) uint64 masks of a CUT's training cells in the words its span covers.

    The span of a CUT at flat position f is bytes ``f - G - N/2 .. f + G + N/2``; it starts at byte
    r = (f - G - N/2) mod 8 of its first word and covers W words. Entry [k, r] has the high bit of
    every byte of word k that holds a training cell (the N/2 bytes either end of the span).
    """
    span = 2 * (guard + half) + 1
    n_words = (_BYTES_PER_WORD - 1 + span - 1) // _BYTES_PER_WORD + 1
    training = np.r_[0:half, span - half:span]
    masks = np.zeros((_BYTES_PER_WORD, n_words * _BYTES_PER_WORD), dtype=np.uint8)
    for r in range(_BYTES_PER_WORD):
        masks[r, r + training] = _BYTE_HIGH_BIT
    out = np.ascontiguousarray(masks.view(np.uint64).T)  # bytes -> words the way the echo's words read them
    out.setflags(write=False)
    return out


def _count_on_words(words: np.ndarray, flat: np.ndarray, blocking: np.ndarray, half: int, guard: int) -> np.ndarray:
    """(M,) int64: how many training cells of each interior CUT reach its blocking level L.

    ``words`` is :func:`_aligned_words` of the video levels (0..15), ``flat`` (M,) the CUTs' flat
    indices (every training cell on the CUT's spoke), ``blocking`` (M,) uint8 each CUT's L
    (:func:`_os_blocking_level`), ``half`` N/2 and ``guard`` G.

    Byte-parallel: a level b (0..15) plus 128 - L sets the byte's high bit exactly when b >= L, and
    the sum stays under 256, so no carry crosses bytes. The training bytes' high bits
    (:func:`_span_masks`) of up to 8 words, shifted 0..7 bits apart, land on distinct bits, so one
    ``np.bitwise_count`` counts them all.
    """
    masks = _span_masks(half, guard)
    count = np.empty(flat.size, dtype=np.int64)
    for lo in range(0, flat.size, _WORD_CHUNK_CELLS):
        start = flat[lo:lo + _WORD_CHUNK_CELLS] - (guard + half)
        word, offset = start >> 3, start & (_BYTES_PER_WORD - 1)
        add = (np.uint64(_BYTE_HIGH_BIT) - blocking[lo:lo + _WORD_CHUNK_CELLS].astype(np.uint64)) * _BYTE_ONES
        total = np.zeros(start.size, dtype=np.int64)
        acc = np.zeros(start.size, dtype=np.uint64)
        for k in range(masks.shape[0]):
            shift = k % _BYTES_PER_WORD
            if k and not shift:
                total += np.bitwise_count(acc)
                acc[:] = 0
            index = word + k
            if k == masks.shape[0] - 1:  # past the span's last word for some offsets (its mask is 0 there)
                np.minimum(index, words.size - 1, out=index)
            x = words[index]
            x += add
            x &= masks[k][offset]
            if shift:
                x >>= np.uint64(shift)
            acc |= x
        total += np.bitwise_count(acc)
        count[lo:lo + _WORD_CHUNK_CELLS] = total
    return count


def _count_training_at_least(levels: np.ndarray, flat: np.ndarray, blocking: np.ndarray, half: int,
                             guard: int) -> np.ndarray:
    """(M,) int64: how many training cells of each interior CUT reach its blocking level L.

    Parameters
    ----------
    levels : (S, N) uint8
        Video levels 0..15.
    flat : (M,) int64
        The CUTs' flat indices; every training cell lies on the CUT's spoke.
    blocking : (M,) uint8
        Each CUT's L (:func:`_os_blocking_level`).
    half, guard : int
        N/2 training and G guard cells a side.

    The CUTs of a level L shared by at least ``_BIT_PLANE_MIN_FRACTION`` of the cells of ``levels`` (on
    a sea sweep, most CUTs share L = 1) are counted on the bit plane ``levels >= L``
    (:func:`_count_on_bit_plane`), the others on the bytes (:func:`_count_on_words`).
    """
    count = np.empty(flat.size, dtype=np.int64)
    on_words = np.ones(flat.size, dtype=bool)
    flat_levels = levels.reshape(-1)
    if 2 * (guard + half) + 1 <= _BITS_PER_WORD:
        per_level = np.bincount(blocking, minlength=VIDEO_LEVELS + 1)
        for level in np.flatnonzero(per_level >= _BIT_PLANE_MIN_FRACTION * flat_levels.size):
            cuts = np.flatnonzero(blocking == level)
            count[cuts] = _count_on_bit_plane(_bit_plane(flat_levels, int(level)), flat[cuts], half, guard)
            on_words[cuts] = False
    rest = np.flatnonzero(on_words)
    if rest.size:
        count[rest] = _count_on_words(_aligned_words(levels), flat[rest], blocking[rest], half, guard)
    return count


def _bit_plane(flat_levels: np.ndarray, level: int) -> np.ndarray:
    """(ceil(M / 64) + 1,) little-endian uint64: bit j of word w is ``flat_levels[64 w + j] >= level``
    (a word of zeros after the last)."""
    plane = np.zeros(-(-flat_levels.size // _BITS_PER_WORD) + 1, dtype=np.dtype("<u8"))
    bits = np.packbits(flat_levels if level == 1 else flat_levels >= level, bitorder="little")  # 1: non-zero
    plane.view(np.uint8)[:bits.size] = bits
    return plane


def _count_on_bit_plane(plane: np.ndarray, flat: np.ndarray, half: int, guard: int) -> np.ndarray:
    """(M,) int64: set bits among the training cells of the CUTs ``flat`` on a :func:`_bit_plane`.

    A CUT's span of ``2 (G + N/2) + 1 <= 64`` cells from bit s lies in words s // 64 and s // 64 + 1:
    shifted together (the second by ``64 - s mod 64`` in two steps, no shift of 64), masked to the
    training cells and counted by ``np.bitwise_count``.
    """
    span = 2 * (guard + half) + 1
    mask = np.uint64(((1 << half) - 1) | (((1 << half) - 1) << (span - half)))
    start = flat - (guard + half)
    word = start >> 6
    offset = (start & (_BITS_PER_WORD - 1)).astype(np.uint64)
    x = plane[word] >> offset
    x |= (plane[word + 1] << (np.uint64(_BITS_PER_WORD - 1) - offset)) << np.uint64(1)
    x &= mask
    return np.bitwise_count(x).astype(np.int64)


def _os_counts_by_table(levels: np.ndarray, rows: np.ndarray, cols: np.ndarray, blocking: np.ndarray,
                        table: np.ndarray) -> np.ndarray:
    """(M,) int64: how many training cells of each CUT (``rows``, ``cols``) (M,) reach its blocking level.

    ``levels`` (S, N) C-contiguous uint8 video, ``blocking`` (16,) :func:`_os_blocking_level`, ``table``
    (N, N_train) :func:`training_table`; the training values are read by flat index, in chunks.
    """
    flat_levels, n_samples = levels.reshape(-1), levels.shape[1]
    count = np.empty(rows.size, dtype=np.int64)
    for lo in range(0, rows.size, _CHUNK_CELLS):
        r, c = rows[lo:lo + _CHUNK_CELLS].astype(np.int64), cols[lo:lo + _CHUNK_CELLS]
        train = flat_levels[(r * n_samples)[:, None] + table[c]]
        count[lo:lo + _CHUNK_CELLS] = np.count_nonzero(train >= blocking[levels[r, c]][:, None], axis=1)
    return count


def _cfar_cells(echo: np.ndarray, rows: np.ndarray, cols: np.ndarray, config: RadarFrontEndConfig,
                first: int) -> np.ndarray:
    """(M,) bool CFAR decisions for the cells (rows, cols) of ``echo``.

    ``echo`` is uint8 video levels 0..15 or float linear power. OS on video counts the training
    cells at or above the CUT's blocking level (module docstring, step 2): byte-parallel on 64-bit
    words or bit planes for the interior cells (:func:`_count_training_at_least`), else from the
    gathered training values.
    """
    video = np.issubdtype(echo.dtype, np.integer)
    alpha = config.alpha
    out = np.empty(rows.size, dtype=bool)
    n_samples = echo.shape[1]
    half, guard = config.training_cells // 2, config.guard_cells
    todo = np.arange(rows.size)
    if video and config.cfar == "os":
        blocking = _os_blocking_level(alpha, config.video_threshold_db, config.video_step_db)
        need = config.training_cells - config.rank + 1
        interior = (cols - guard - half >= first) & (cols + guard + half < n_samples)
        i = np.flatnonzero(interior)
        flat = rows[i].astype(np.int64) * n_samples + cols[i]
        count = _count_training_at_least(echo, flat, blocking[echo.reshape(-1)[flat]], half, guard)
        out[i] = count < need
        todo = np.flatnonzero(~interior)
        if echo.flags.c_contiguous:  # the cells near the ends
            table = training_table(n_samples, first, config.training_cells, guard)
            out[todo] = _os_counts_by_table(echo, rows[todo], cols[todo], blocking, table) < need
            return out
    power_table = video_power_table(config.video_threshold_db, config.video_step_db)
    for start in range(0, todo.size, _CHUNK_CELLS):
        j = todo[start:start + _CHUNK_CELLS]
        r, c = rows[j], cols[j]
        train = _training_values(echo, r, c, config, first)
        cut = echo[r, c]
        if video and config.cfar == "os":
            out[j] = np.count_nonzero(train >= blocking[cut][:, None], axis=1) < need
            continue
        if video:
            train, cut = power_table[train], power_table[cut]
        if config.cfar == "ca":
            estimate = train.sum(axis=1, dtype=np.float64) / config.training_cells
        else:
            estimate = np.partition(train, config.rank - 1, axis=1)[:, config.rank - 1]
        out[j] = cut > alpha * estimate
    return out


def cfar_mask(echo: np.ndarray, config: RadarFrontEndConfig, range_m: np.ndarray | None = None) -> np.ndarray:
    """CFAR detections along range, every spoke (module docstring, steps 1-2).

    Parameters
    ----------
    echo : (S, N) array
        One sweep: integer video levels 0..15, or float linear power (synthetic tests).
    config : RadarFrontEndConfig
        CFAR kind, Pfa, training / guard cells, OS rank, video mapping, ``min_echo_level``.
    range_m : (N,) float, optional
        Range of each sample, metres; with it, samples nearer than ``config.blanking_m`` hold no
        data (neither CUT nor training cells).

    Returns
    -------
    (S, N) bool
        True where the CUT's power exceeds ``alpha x`` its training estimate: ``mean`` for CA,
        ``X_(k)`` for OS (:attr:`RadarFrontEndConfig.alpha`).
    """
    echo = np.asarray(echo)
    if echo.ndim != 2:
        raise ValueError(f"echo must be 2-D (spokes, samples), not {echo.shape}")
    first = _first_valid_sample(range_m, config.blanking_m)
    training_table(echo.shape[1], first, config.training_cells, config.guard_cells)  # validates the size
    if np.issubdtype(echo.dtype, np.integer):
        echo = np.clip(echo, 0, VIDEO_LEVELS - 1).astype(np.uint8)
        candidate = echo >= _lowest_candidate_level(config)  # levels compare as powers (monotone table)
    else:
        candidate = echo > 0.0
    candidate[:, :first] = False
    rows, cols = np.nonzero(candidate)
    mask = np.zeros(echo.shape, dtype=bool)
    hit = _cfar_cells(echo, rows, cols, config, first)
    mask[rows[hit], cols[hit]] = True
    return mask

"""Radar front end: one polar sweep -> CFAR -> plots -> :class:`~tdm.detections.Detections` in ENU.

Steps (numpy/scipy-vectorised; Python loops only over chunks of cells):

1. Video to power (:func:`video_power`). A sweep holds 4-bit *log* video levels (docs/reference.md
   3.10: ``v = clip(floor((P_dB - floor_dB) / step_dB), 0, 15)``), while the CFAR thresholds assume
   a square-law (linear power) detector. So each level reads as the power at the centre of its bin,
   in units of the mean thermal noise: ``P(v) = 10^((video_threshold_db + video_step_db (v - 1/2))
   / 10)`` for v >= 1. Level 0 holds everything below the first level (mostly thermal noise, most
   cells of a sweep) and reads as the noise mean, ``P(0) = 1``: this is the zero-noise floor. In a
   background of zeros every training estimate is 1 and the threshold is ``alpha``: with the
   defaults (level 1 starts 9.6 dB over the noise mean; OS alpha 9.3 dB) a non-zero cell in a
   zero background passes, so on thermal noise the false-alarm rate is the receiver's own
   first-level crossing probability, ``exp(-10^0.96) = 1.1e-4``, the IMO basis ``Pfa = 1e-4``
   (docs/reference.md section 3 table) the first level is set for. Floating-point input (synthetic tests) is
   linear power as it is, with no floor.

2. CFAR along range (:func:`cfar_mask`), every spoke. The training cells of a cell under test (CUT)
   are the ``training_cells`` (N) nearest samples beyond ``guard_cells`` (G) on either side, N/2 each
   side in the interior; near the first valid sample (after main-bang blanking) or the last one the
   window slides inwards, so every CUT keeps N training cells.

   - CA (cell averaging): ``T = alpha mean(training)``, ``alpha = N (Pfa^(-1/N) - 1)`` (exact on
     exponential noise, docs/reference.md section 5).
   - OS (ordered statistic, Rohling 1983; docs/reference.md section 5: k about 3N/4, robust at clutter edges
     and next to other targets): ``T = alpha X_(k)``, X_(k) the k-th smallest training value, alpha
     from ``Pfa = prod_{i=0}^{k-1} (N - i) / (N - i + alpha)`` (exponential noise). On video levels
     the test needs no sort: ``P(CUT) > alpha P(X_(k))`` holds exactly when fewer than ``N - k + 1``
     training cells reach the lowest level L with ``alpha P(L) >= P(CUT)``, a count.

   Only cells that can pass at all are tested (level >= ``min_echo_level`` and power above
   ``alpha x`` the floor): a few per cent of a sweep. For OS on video with N/2 a multiple of 8 the
   counts are byte-parallel on 64-bit words (eight 4-bit levels compared at once, ``np.bitwise_count``);
   otherwise the training cells are read through ``numpy.lib.stride_tricks.sliding_window_view`` (two
   contiguous halves per CUT) or, near the ends, a precomputed index table.

3. Gap filling along range. An extended target (a ship end-on covers tens of samples) fills the
   training window of its own interior, so CFAR keeps only its edges. A cell joins the detections
   when it lies on a spoke between two detections and every cell from one to the other has a
   level >= ``fill_level``.

4. Plots: connected components of the detections, 8-connected and circular in azimuth (the last
   spoke touches the first), the same partition ``scipy.ndimage.label`` gives once the components
   that touch across the seam are merged (tested); worked out on runs along range and
   ``scipy.sparse.csgraph.connected_components``, which is faster on a sparse sweep.

5. Clutter map (:func:`clutter_map`): one-dimensional CFAR cannot tell sea clutter from targets on
   4-bit video. Sea clutter is mostly below level 1, so its training estimates sit on the floor,
   while its K-distributed spikes (docs/reference.md 3.8) cross the first levels in patches the size of a
   beam and a wave. A plot is kept only if its peak *beam-integrated* power
   (:func:`beam_integrated_power`: the spokes of about half a beam averaged, which lowers the sea's
   spoke-to-spoke speckle and not a target's steady echo) exceeds the local clutter level by
   ``clutter_margin_db``. The local clutter level is a high quantile of block maxima over an annulus
   of blocks about the peak (a spatial clutter map; targets fill few blocks of it).

6. Kept plots also need ``min_plot_cells <= n <= max_plot_cells`` cells, ``min_plot_spokes``
   spokes, and a centroid outside a box about the own ship (hull length/beam + margin). Range and
   bearing of a plot are the power-weighted centroid (bearing as a circular mean, relative to the
   bow); it goes to ENU with the pose at its centre spoke: the heading recorded on that spoke, roll
   and pitch from the own-ship track at the spoke's time, the mount. The fan beam at antenna
   azimuth a meets a target near the horizon along the direction in the beam plane that is
   horizontal in the world (exact for any roll and pitch). Slant range is taken as horizontal
   range (error ``h^2 / (2 r)``: 0.16 m at 50 m for a 4 m antenna).

7. Size and covariance: see :func:`radar_detections`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view
from scipy import ndimage
from scipy.optimize import brentq
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from tdm.detections import Detections
from tdm.frames import Mount, OwnshipTrack

__all__ = ["RadarFrontEndConfig", "beam_integrated_power", "ca_alpha", "cfar_mask", "clutter_map", "fill_gaps",
           "label_plots", "mount_from_scenario", "os_alpha", "radar_detections", "training_table", "video_power",
           "video_power_table"]

#: Levels of the 4-bit video (docs/reference.md section 3 table: "1024 samples, 4 bits each (0..15)").
VIDEO_LEVELS = 16


#: Cells per chunk of the CFAR's training-cell gathers (bounded memory: chunk x N values).
_CHUNK_CELLS = 1 << 16


@dataclass(frozen=True)
class RadarFrontEndConfig:
    """Parameters of the radar front end, with their defaults and sources.

    Attributes
    ----------
    cfar : str
        ``"os"`` (ordered statistic, default: robust at clutter edges and next to other targets,
        docs/reference.md section 5) or ``"ca"`` (cell averaging).
    pfa : float
        Design false-alarm probability per cell on exponential noise. Default 1e-4, the IMO
        detection basis (docs/reference.md section 3 table).
    training_cells : int
        N, training cells per CUT in all (N/2 each side in the interior). Default 32 (29 m each side
        at 1.81 m samples: longer than a sea-clutter patch, docs/reference.md 3.8).
    guard_cells : int
        G, guard cells each side of the CUT, not trained on. Default 4 (7 m: the 2.5 m range
        point-spread of docs/reference.md 3.3 with margin).
    os_rank : int or None
        k of OS-CFAR (1-based). None: ``round(3 N / 4)`` (docs/reference.md section 5).
    min_echo_level : int
        Lowest video level a detection may have. Default 1 (anything over the receiver's floor).
    fill_level : int
        Lowest level of the cells that fill a gap between two detections on a spoke (step 3);
        0 turns filling off. Default 1.
    video_threshold_db : float
        Power where video level 1 starts, dB over the mean thermal noise. Default 9.6 dB, the level
        noise alone crosses with probability 1e-4 (``10 log10(-ln 1e-4)``; the IMO Pfa,
        docs/reference.md section 3 table); a receiver sets its floor so (docs/reference.md 3.10). Unverified for a
        real set, whose gain control moves it.
    video_step_db : float
        dB per video level (log video, docs/reference.md 3.10). Default 3 dB (16 levels over 45 dB;
        unverified for a real set).
    integration_spokes : int
        Spokes averaged for the seed test (step 5). Default 16 (2.8 deg, about half the 5.2 deg
        beam, within which a target's two-way echo stays within 2 dB of its peak).
    clutter_block_spokes, clutter_block_samples : int
        Clutter-map block, cells. Defaults 16 x 8 (2.8 deg x 14.5 m: a sea-clutter patch).
    clutter_window_blocks, clutter_guard_blocks : (int, int)
        Clutter-map annulus, blocks (azimuth, range): the window minus its central guard. Defaults
        (65, 5) minus (5, 3): 183 deg x 72 m minus 14 deg x 43 m. Wide in azimuth, so that targets
        fill few of its 310 blocks; narrow in range, to follow the clutter's fall with range and
        the sensitivity-time control's rise near the antenna (docs/reference.md 3.10). On rendered
        sea states 2 and 4 it found more targets at fewer false plots than (33, 9).
    clutter_quantile : float
        Quantile of the annulus's block maxima taken as the local clutter level. Default 0.9
        (robust while targets fill under 10 % of the annulus).
    clutter_margin_db : float
        How far a plot's peak integrated power must exceed the clutter level, dB. Default 10 dB
        (measured on rendered recordings: about 7 false plots per sweep at sea state 4 and under 1
        at sea state 2, with 95 % and 100 % of the objects found; 8.5 dB: 20 and 2 false plots,
        12 dB: 3 and 0.1, with 91 % found at sea state 4).
    min_seed_db : float
        Lowest integrated power of a seed, dB over the mean noise. Default 10 dB (as the margin,
        over a noise-only background).
    min_plot_cells, max_plot_cells : int
        A plot has between these many cells. Defaults 6 (a few samples over a few spokes) and
        100 000 (5 % of a sweep: larger is land or a clutter field, not a target).
    min_plot_spokes : int
        Fewest spokes a plot spans. Default 3 (0.5 deg: the 5.2 deg beam smears even a weak point
        target over several spokes).
    own_ship_length_m, own_ship_beam_m : float
        Own-ship hull, metres (scenario ``own_ship``; defaults: the thesis's Odin, 10.9 x 3.5 m).
    own_ship_margin_m : float
        Margin about the hull inside which plots are the own ship, metres. Default 5 m (two range
        resolutions).
    beam_az_deg : float
        -3 dB one-way horizontal beamwidth, deg. Default 5.2 (docs/reference.md section 3 table).
    range_resolution_m : float
        Physical range resolution (FMCW bandwidth or pulse length, ``c / (2 B)``), metres.
        Default 2.5 (docs/reference.md 3.3: about 2-3 m).
    blanking_m : float
        Main-bang blanking: nearer samples hold no data and are not training cells, metres.
        Default 3 (scenario ``sensors.radar.blanking_m``).
    bearing_sigma_beam_fraction : float
        Standard deviation of a plot's bearing as a fraction of the beamwidth. Default 0.15 (the
        power-weighted centroid of a beam-smeared echo is far better than the beam: measured 0.6-1
        deg, 0.12-0.19 theta3, across the beam on rendered recordings, including the targets' own
        extent).
    extent_sigma_fraction : float
        Standard deviation of the centroid about the target's centre per metre of the target's
        visible extent. Default 0.25. The radar sees the near face, not the centre (the plots of
        rendered icebergs lie 6-9 m short of their centres), so the centre lies up to half the
        target's depth behind its plot; but that offset is a bias that stays from sweep to sweep,
        and the trackers treat the covariance as white noise: with 0.5 (median NEES about the
        truth centres 0.5-1.5) the plots' real scatter (about 2 m on the Table 3.2 vessel) was
        reported as 10 m and the radar tracks lagged every turn; 0.25 halves their heading error
        (benchmarks/results/thesis_table32.md).
    range_scale_m, spokes, samples : float, int, int or None
        The sweep geometry the configuration is for (scenario ``sensors.radar``); when set,
        :func:`radar_detections` checks each sweep against it.
    """

    cfar: str = "os"
    pfa: float = 1e-4
    training_cells: int = 32
    guard_cells: int = 4
    os_rank: int | None = None
    min_echo_level: int = 1
    fill_level: int = 1
    video_threshold_db: float = 9.6
    video_step_db: float = 3.0
    integration_spokes: int = 16
    clutter_block_spokes: int = 16
    clutter_block_samples: int = 8
    clutter_window_blocks: tuple[int, int] = (65, 5)
    clutter_guard_blocks: tuple[int, int] = (5, 3)
    clutter_quantile: float = 0.9
    clutter_margin_db: float = 10.0
    min_seed_db: float = 10.0
    min_plot_cells: int = 6
    max_plot_cells: int = 100_000
    min_plot_spokes: int = 3
    own_ship_length_m: float = 10.9
    own_ship_beam_m: float = 3.5
    own_ship_margin_m: float = 5.0
    beam_az_deg: float = 5.2
    range_resolution_m: float = 2.5
    blanking_m: float = 3.0
    bearing_sigma_beam_fraction: float = 0.15
    extent_sigma_fraction: float = 0.25
    range_scale_m: float | None = None
    spokes: int | None = None
    samples: int | None = None

    def __post_init__(self):
        if self.cfar not in ("os", "ca"):
            raise ValueError(f"cfar must be 'os' or 'ca', not {self.cfar!r}")
        if not 0.0 < self.pfa < 1.0:
            raise ValueError(f"pfa must be in (0, 1), not {self.pfa}")
        if self.training_cells < 2 or self.training_cells % 2:
            raise ValueError(f"training_cells must be even and >= 2, not {self.training_cells}")
        if self.guard_cells < 0:
            raise ValueError(f"guard_cells must be >= 0, not {self.guard_cells}")
        if not 1 <= self.rank <= self.training_cells:
            raise ValueError(f"os_rank must be in 1..training_cells, not {self.os_rank}")
        if not 0.0 < self.clutter_quantile <= 1.0:
            raise ValueError(f"clutter_quantile must be in (0, 1], not {self.clutter_quantile}")
        for name in ("clutter_window_blocks", "clutter_guard_blocks"):
            a, r = getattr(self, name)
            if a < 1 or r < 1 or a % 2 == 0 or r % 2 == 0:
                raise ValueError(f"{name} must be two odd sizes >= 1, not {(a, r)}")

    @property
    def rank(self) -> int:
        """k of OS-CFAR (1-based)."""
        return int(self.os_rank) if self.os_rank is not None else int(round(0.75 * self.training_cells))

    @property
    def alpha(self) -> float:
        """Threshold multiplier of the configured CFAR at the configured Pfa (exponential noise)."""
        if self.cfar == "ca":
            return ca_alpha(self.training_cells, self.pfa)
        return os_alpha(self.training_cells, self.rank, self.pfa)

    @classmethod
    def from_scenario(cls, scenario: dict, **overrides) -> "RadarFrontEndConfig":
        """The configuration for a recording, from its resolved ``scenario.yaml`` (a dict).

        Reads ``sensors.radar`` (``range_m``, ``spokes``, ``samples``, ``beam_az_deg``,
        ``blanking_m``) and ``own_ship`` (``length_m``, ``beam_m``); absent keys keep the defaults.
        ``overrides`` set any field. The mount is read by :func:`mount_from_scenario`.
        """
        radar = (scenario.get("sensors") or {}).get("radar") or {}
        own = scenario.get("own_ship") or {}
        values: dict = {}
        for key, field_name, kind in (("range_m", "range_scale_m", float), ("spokes", "spokes", int),
                                      ("samples", "samples", int), ("beam_az_deg", "beam_az_deg", float),
                                      ("blanking_m", "blanking_m", float)):
            if radar.get(key) is not None:
                values[field_name] = kind(radar[key])
        if own.get("length_m") is not None:
            values["own_ship_length_m"] = float(own["length_m"])
        if own.get("beam_m") is not None:
            values["own_ship_beam_m"] = float(own["beam_m"])
        values.update(overrides)
        return cls(**values)


def mount_from_scenario(scenario: dict) -> Mount:
    """The radar's :class:`~tdm.frames.Mount` from a resolved scenario dict (``sensors.radar.mount``)."""
    radar = (scenario.get("sensors") or {}).get("radar") or {}
    return Mount.from_dict(radar.get("mount"))


# ---------------------------------------------------------------------------- CFAR


def ca_alpha(n_training: int, pfa: float) -> float:
    """CA-CFAR multiplier ``alpha = N (Pfa^(-1/N) - 1)`` (exponential noise; docs/reference.md section 5)."""
    return float(n_training * (pfa ** (-1.0 / n_training) - 1.0))


@lru_cache(maxsize=64)
def os_alpha(n_training: int, rank: int, pfa: float) -> float:
    """OS-CFAR multiplier for the k-th smallest of N training cells (Rohling 1983, exponential noise).

    Solves ``Pfa = prod_{i=0}^{k-1} (N - i) / (N - i + alpha)`` for alpha.
    """
    n_i = n_training - np.arange(rank, dtype=float)

    def log_pfa_error(alpha: float) -> float:
        return float(np.sum(np.log(n_i / (n_i + alpha)))) - math.log(pfa)

    return float(brentq(log_pfa_error, 1e-9, 1e12, xtol=1e-12, rtol=1e-12))


@lru_cache(maxsize=8)
def video_power_table(threshold_db: float, step_db: float) -> np.ndarray:
    """(16,) float32 power of each video level, units of the mean noise (module docstring, step 1)."""
    v = np.arange(VIDEO_LEVELS, dtype=float)
    p = 10.0 ** ((threshold_db + step_db * (v - 0.5)) / 10.0)
    p[0] = 1.0
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


#: The high bit of every byte of a 64-bit word, and one in every byte (byte-parallel counting).
_HIGH_BITS = np.uint64(0x8080808080808080)
_BYTE_ONES = np.uint64(0x0101010101010101)


def _byte_words(levels: np.ndarray) -> np.ndarray:
    """(S N,) uint64 view: element p holds the 8 bytes of the flat uint8 array from position p on."""
    flat = np.zeros(levels.size + 8, dtype=np.uint8)  # 8 bytes of padding: the last words stay inside
    flat[:levels.size] = levels.ravel()
    return np.ndarray(shape=(levels.size,), dtype=np.uint64, buffer=flat, offset=0, strides=(1,))


def _count_at_least(words: np.ndarray, starts: np.ndarray, n_words: int, add: np.ndarray) -> np.ndarray:
    """(M,) how many of the ``8 n_words`` bytes from each start are >= L, ``add = (128 - L) x 0x01..01``.

    Byte-parallel: a 4-bit level b (0..15) plus 128 - L sets the byte's high bit exactly when
    b >= L, and the sum stays under 256, so no carry crosses into the next byte.
    """
    count = np.zeros(starts.size, dtype=np.int64)
    for w in range(n_words):
        count += np.bitwise_count((words[starts + 8 * w] + add) & _HIGH_BITS)
    return count


def _cfar_cells(echo: np.ndarray, rows: np.ndarray, cols: np.ndarray, config: RadarFrontEndConfig,
                first: int) -> np.ndarray:
    """(M,) bool CFAR decisions for the cells (rows, cols) of ``echo``.

    ``echo`` is uint8 video levels 0..15 or float linear power. OS on video counts the training
    cells at or above the CUT's blocking level (module docstring, step 2): byte-parallel on 64-bit
    words when N/2 is a multiple of 8 (the interior cells), else from the gathered training values.
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
        if half % 8 == 0:
            interior = (cols - guard - half >= first) & (cols + guard + half < n_samples)
            i = np.flatnonzero(interior)
            words = _byte_words(echo)
            flat = rows[i].astype(np.int64) * n_samples + cols[i]
            add = (np.uint64(128) - blocking[echo[rows[i], cols[i]]].astype(np.uint64)) * _BYTE_ONES
            count = (_count_at_least(words, flat - guard - half, half // 8, add)
                     + _count_at_least(words, flat + guard + 1, half // 8, add))
            out[i] = count < need
            todo = np.flatnonzero(~interior)
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


# ---------------------------------------------------------------------------- gap filling, labels


def _fill_runs(flat: np.ndarray, n_samples: int, detected: np.ndarray) -> np.ndarray:
    """(M,) bool: cells from the first to the last detection of their run.

    ``flat`` are the ascending flat indices of the cells strong enough to fill; a run is a maximal
    sequence of them that are consecutive samples of one spoke.
    """
    m = flat.size
    if m == 0:
        return np.zeros(0, dtype=bool)
    brk = np.ones(m, dtype=bool)
    brk[1:] = (np.diff(flat) != 1) | (flat[1:] % n_samples == 0)
    starts = np.flatnonzero(brk)
    run = np.cumsum(brk) - 1
    pos = np.arange(m)
    first_det = np.minimum.reduceat(np.where(detected, pos, m), starts)
    last_det = np.maximum.reduceat(np.where(detected, pos, -1), starts)
    return (pos >= first_det[run]) & (pos <= last_det[run])


def fill_gaps(mask: np.ndarray, echo: np.ndarray, fill_level: float) -> np.ndarray:
    """Detections plus every cell between two detections of a spoke joined by echo >= ``fill_level``.

    Parameters
    ----------
    mask : (S, N) bool
        CFAR detections.
    echo : (S, N) array
        Video levels (or power) the run condition is tested on.
    fill_level : float
        Lowest value of a filling cell.

    Returns
    -------
    (S, N) bool
    """
    mask = np.asarray(mask, dtype=bool)
    flat = np.flatnonzero((np.asarray(echo) >= fill_level) | mask)
    out = mask.copy()
    filled = _fill_runs(flat, mask.shape[1], mask.ravel()[flat])
    out.ravel()[flat[filled]] = True
    return out


def label_plots(mask: np.ndarray) -> tuple[np.ndarray, int]:
    """Connected components of a sweep's detections, circular in azimuth.

    8-connected (a cell touches the 8 around it); the last spoke touches the first (the revolution
    is circular).

    Parameters
    ----------
    mask : (S, N) bool

    Returns
    -------
    labels : (S, N) int32
        0 = background, 1..n = plot, numbered in the order of their first cell.
    n : int
        Number of plots.
    """
    mask = np.asarray(mask, dtype=bool)
    flat = np.flatnonzero(mask)
    lab, n = _label_cells(flat, *mask.shape)
    labels = np.zeros(mask.shape, dtype=np.int32)
    labels.ravel()[flat] = lab
    return labels, n


def _runs(flat: np.ndarray, n_samples: int) -> tuple[np.ndarray, np.ndarray]:
    """Runs of ascending flat cell indices: (M_runs,) first and (M_runs,) last position in ``flat``.

    A run is a maximal sequence of consecutive samples of one spoke.
    """
    brk = np.ones(flat.size, dtype=bool)
    brk[1:] = (np.diff(flat) != 1) | (flat[1:] % n_samples == 0)
    starts = np.flatnonzero(brk)
    return starts, np.append(starts[1:], flat.size) - 1


def _label_cells(flat: np.ndarray, n_spokes: int, n_samples: int) -> tuple[np.ndarray, int]:
    """Labels 1..n of the cells ``flat`` (ascending flat indices) by 8-connectivity, circular in azimuth.

    Works on runs along range: two runs on neighbouring spokes (the last spoke's neighbour is the
    first) touch when their sample intervals, widened by one, overlap; the runs' graph goes through
    ``scipy.sparse.csgraph.connected_components``.
    """
    if flat.size == 0:
        return np.zeros(0, dtype=np.int32), 0
    starts, ends = _runs(flat, n_samples)
    spoke = flat[starts] // n_samples
    a, b = flat[starts] % n_samples, flat[ends] % n_samples
    width = n_samples + 2  # keys keep spokes apart: spoke * width + sample, samples -1 .. n_samples
    key_end, key_start = spoke * width + b, spoke * width + a
    prev = (spoke - 1) % n_spokes
    lo = np.searchsorted(key_end, prev * width + a - 1, side="left")  # first run on prev ending at >= a - 1
    hi = np.searchsorted(key_start, prev * width + b + 1, side="right")  # past the last starting at <= b + 1
    count = np.maximum(hi - lo, 0)
    if n_spokes < 3:  # a spoke is its own neighbour's neighbour: no seam logic needed, but no self-loops either
        count = np.where(prev == spoke, 0, count)
    j = np.repeat(np.arange(starts.size), count)
    i = np.repeat(lo, count) + (np.arange(j.size) - np.repeat(np.cumsum(count) - count, count))
    graph = coo_matrix((np.ones(j.size, dtype=np.int8), (i, j)), shape=(starts.size, starts.size))
    _, comp = connected_components(graph, directed=False)
    # number components 1..n in the order of their first run
    _, first_run, inverse = np.unique(comp, return_index=True, return_inverse=True)
    order = np.argsort(first_run)
    rank = np.empty_like(order)
    rank[order] = np.arange(order.size)
    run_label = (rank[inverse] + 1).astype(np.int32)
    return np.repeat(run_label, ends - starts + 1), int(order.size)


def _spokes_per_label(lab: np.ndarray, spoke: np.ndarray, n_labels: int, n_spokes: int) -> np.ndarray:
    """(n_labels,) number of distinct spokes of each label's cells (cells spoke-major, ascending)."""
    new = np.ones(lab.size, dtype=bool)  # a (label, spoke) pair not seen on the previous cells of the spoke
    new[1:] = (spoke[1:] != spoke[:-1]) | (lab[1:] != lab[:-1])
    pair = np.unique(lab[new].astype(np.int64) * n_spokes + spoke[new])
    return np.bincount(pair // n_spokes, minlength=n_labels)


# ---------------------------------------------------------------------------- clutter map


def _group_spokes(n_spokes: int, wanted: int) -> int:
    """Largest divisor of ``n_spokes`` not above ``wanted`` (at least 1)."""
    for g in range(max(1, wanted), 0, -1):
        if n_spokes % g == 0:
            return g
    return 1


def _integrate_cells(flat: np.ndarray, excess: np.ndarray, shape: tuple[int, int],
                     config: RadarFrontEndConfig) -> tuple[np.ndarray, int]:
    """:func:`beam_integrated_power` from the cells above the floor only (``excess`` = power - 1)."""
    n_spokes, n_samples = shape
    g = _group_spokes(n_spokes, max(1, config.integration_spokes // 2))
    rows, cols = np.divmod(flat, n_samples)
    groups = np.bincount((rows // g) * n_samples + cols, weights=excess,
                         minlength=(n_spokes // g) * n_samples).reshape(n_spokes // g, n_samples)
    integrated = (groups + np.roll(groups, -1, axis=0)) * (0.5 / g) + 1.0
    return integrated.astype(np.float32), g


def beam_integrated_power(power: np.ndarray, config: RadarFrontEndConfig) -> tuple[np.ndarray, int]:
    """Power averaged over ``integration_spokes`` neighbouring spokes, decimated in azimuth.

    Spokes are summed in groups of ``g = integration_spokes / 2`` (a divisor of the spoke count) and
    two neighbouring groups make one window: row i is the mean of spokes ``g i .. g i + 2 g - 1``
    (circular), every sample. A target's echo holds over the beam while the sea's speckle changes
    from spoke to spoke (docs/reference.md 3.8), so this non-coherent integration lowers the clutter's
    spikes, not the target. Decimating by g (1.4 deg at 2048 spokes) costs a target's peak at most
    0.5 dB in a 5.2 deg two-way Gaussian beam.

    Parameters
    ----------
    power : (S, N) float
        Linear power per cell (:func:`video_power`).
    config : RadarFrontEndConfig

    Returns
    -------
    integrated : (S / g, N) float32
    g : int
        Spokes per group.
    """
    power = np.asarray(power, dtype=np.float64)
    flat = np.flatnonzero(power != 1.0)
    return _integrate_cells(flat, power.ravel()[flat] - 1.0, power.shape, config)


@lru_cache(maxsize=8)
def _annulus_offsets(window: tuple[int, int], guard: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
    """Block offsets (azimuth, range) of a centred window minus its centred guard."""
    wa, wr = window
    ga, gr = guard
    a, r = np.meshgrid(np.arange(wa) - wa // 2, np.arange(wr) - wr // 2, indexing="ij")
    keep = ~((np.abs(a) <= ga // 2) & (np.abs(r) <= gr // 2))
    return a[keep], r[keep]


def clutter_map(integrated: np.ndarray, group_spokes: int, config: RadarFrontEndConfig) -> np.ndarray:
    """Seed threshold of every block: the integrated power a plot must reach to stand out of the clutter.

    The integrated sweep (:func:`beam_integrated_power`) is cut into blocks of
    ``clutter_block_spokes x clutter_block_samples`` cells and each block's maximum is taken. The
    local clutter level of a block is the ``clutter_quantile`` of the block maxima (in dB) over an
    annulus of ``clutter_window_blocks`` (azimuth, range) minus ``clutter_guard_blocks`` about it,
    circular in azimuth and cut at the ends of the range scale (a spatial clutter map, after
    Nitzberg's scan-to-scan one). The guard keeps a target's own blocks out; other targets fill a
    few blocks of the annulus, under the quantile. The seed threshold is that level plus
    ``clutter_margin_db``, at least ``min_seed_db``. Only blocks whose own maximum reaches
    ``min_seed_db`` are worked out (the others cannot hold a seed and get ``min_seed_db``).

    Parameters
    ----------
    integrated : (A, N) float
        Integrated power over the mean noise, rows ``group_spokes`` spokes apart.
    group_spokes : int
    config : RadarFrontEndConfig

    Returns
    -------
    (ceil(A / ba), ceil(N / bn)) float32
        Seed threshold per block, linear power over the mean noise; block (i, j) holds rows
        ``i ba .. (i + 1) ba - 1`` and samples ``j bn .. (j + 1) bn - 1``, with
        ``ba = max(1, clutter_block_spokes // group_spokes)``, ``bn = clutter_block_samples``.
    """
    block_db, _ = _block_max_db(integrated, group_spokes, config)
    seed_db = np.full(block_db.shape, config.min_seed_db, dtype=np.float32)
    bi, bj = np.nonzero(block_db >= config.min_seed_db)
    if bi.size:
        seed_db[bi, bj] = np.maximum(_clutter_level_db(block_db, bi, bj, config) + config.clutter_margin_db,
                                     config.min_seed_db)
    return (10.0 ** (seed_db / 10.0)).astype(np.float32)


def _block_max_db(integrated: np.ndarray, group_spokes: int, config: RadarFrontEndConfig) -> tuple[np.ndarray, int]:
    """(sb, nb) float32 block maxima of the integrated power in dB, and rows per block ``ba``."""
    ba = max(1, config.clutter_block_spokes // group_spokes)
    bn = config.clutter_block_samples
    a, n = integrated.shape
    sb, nb = -(-a // ba), -(-n // bn)
    padded = np.asarray(integrated, dtype=np.float32)
    if (sb * ba, nb * bn) != (a, n):
        padded = np.ones((sb * ba, nb * bn), dtype=np.float32)
        padded[:a, :n] = integrated
    block_max = np.maximum.reduce(padded.reshape(sb, ba, nb * bn), axis=1)
    block_max = np.maximum.reduce(block_max.reshape(sb, nb, bn), axis=2)
    return 10.0 * np.log10(np.maximum(block_max, np.float32(1e-6))), ba


def _clutter_level_db(block_db: np.ndarray, bi: np.ndarray, bj: np.ndarray, config: RadarFrontEndConfig) -> np.ndarray:
    """(K,) float32 clutter level (dB) of blocks (bi, bj): the quantile of their annulus's block maxima."""
    sb, nb = block_db.shape
    da, dr = _annulus_offsets(tuple(config.clutter_window_blocks), tuple(config.clutter_guard_blocks))
    rj = bj[:, None] + dr[None, :]
    inside = (rj >= 0) & (rj < nb)
    values = np.where(inside, block_db[(bi[:, None] + da[None, :]) % sb, np.clip(rj, 0, nb - 1)], -np.inf)
    n_valid = inside.sum(axis=1)
    # the q-quantile of each block's valid values: rank ceil(q n) among them (-inf sort first)
    rank = values.shape[1] - n_valid + np.maximum(np.ceil(config.clutter_quantile * n_valid).astype(np.int64), 1) - 1
    q_db = np.empty(bi.size, dtype=np.float32)
    full = n_valid == values.shape[1]
    if full.any():  # one rank for all blocks with a whole annulus: partition
        k = int(rank[full][0])
        q_db[full] = np.partition(values[full], k, axis=1)[:, k]
    if (~full).any():
        part = np.sort(values[~full], axis=1)
        q_db[~full] = part[np.arange(part.shape[0]), rank[~full]]
    return q_db


# ---------------------------------------------------------------------------- plots


def _plot_cells(echo: np.ndarray, range_m: np.ndarray, config: RadarFrontEndConfig
                ) -> tuple[np.ndarray, np.ndarray, int]:
    """Detected and filled cells of a sweep, and its beam-integrated power (module docstring, 1-3, 5).

    Works on the cells above level 0 only (a few per cent of a sweep).

    Returns
    -------
    flat : (M,) int64
        Ascending flat indices of the detected and filled cells.
    integrated : (S / g, N) float32
        :func:`beam_integrated_power` of the sweep.
    g : int
        Spokes per integration group.
    """
    n_spokes, n_samples = echo.shape
    first = _first_valid_sample(range_m, config.blanking_m)
    training_table(n_samples, first, config.training_cells, config.guard_cells)  # validates the size
    power_table = video_power_table(config.video_threshold_db, config.video_step_db)
    nz = np.flatnonzero(echo)
    levels = echo.ravel()[nz]
    keep = (nz % n_samples) >= first
    nz, levels = nz[keep], np.minimum(levels[keep], VIDEO_LEVELS - 1)
    integrated, g = _integrate_cells(nz, power_table[levels] - 1.0, echo.shape, config)
    rows, cols = np.divmod(nz, n_samples)
    testable = levels >= _lowest_candidate_level(config)
    detected = np.zeros(nz.size, dtype=bool)
    detected[testable] = _cfar_cells(echo, rows[testable], cols[testable], config, first)
    if config.fill_level > 0:
        strong = np.flatnonzero(levels >= config.fill_level)
        detected[strong[_fill_runs(nz[strong], n_samples, detected[strong])]] = True
    return nz[detected], integrated, g


def _margin_over_clutter_db(lab: np.ndarray, spoke: np.ndarray, sample: np.ndarray, n_labels: int,
                            eligible: np.ndarray, integrated: np.ndarray, g: int,
                            config: RadarFrontEndConfig) -> np.ndarray:
    """(n_labels,) float32: each eligible plot's peak beam-integrated power over its clutter level, dB
    (-inf for the others and for plots with no cell above the lowest seed threshold).

    A cell of spoke group k lies in integration windows k - 1 and k and takes the larger; a plot's
    peak is its largest, and the clutter level is worked out for the peak's block only
    (:func:`clutter_map` gives the same threshold for every block).
    """
    margin_db = np.full(n_labels, -np.inf, dtype=np.float32)
    a = integrated.shape[0]
    k = spoke // g
    before, here = integrated[(k - 1) % a, sample], integrated[k, sample]
    value = np.maximum(before, here)
    # only cells above the lowest seed threshold can be a kept plot's peak
    cells = np.flatnonzero((value >= np.float32(10.0 ** (config.min_seed_db / 10.0))) & eligible[lab])
    if cells.size == 0:
        return margin_db
    value, lab_c = value[cells], lab[cells]
    row = np.where(before[cells] > here[cells], (k[cells] - 1) % a, k[cells])
    peak = np.full(n_labels, -np.inf, dtype=np.float32)
    np.maximum.at(peak, lab_c, value)
    at_peak = np.flatnonzero(value == peak[lab_c])
    labels, first = np.unique(lab_c[at_peak], return_index=True)
    peak_cell = at_peak[first]
    peak_db = 10.0 * np.log10(peak[labels])
    block_db, ba = _block_max_db(integrated, g, config)
    level_db = _clutter_level_db(block_db, row[peak_cell] // ba,
                                 sample[cells[peak_cell]] // config.clutter_block_samples, config)
    margin_db[labels] = peak_db - level_db
    return margin_db


def radar_detections(sweep: dict, track: OwnshipTrack, mount: Mount, config: RadarFrontEndConfig) -> Detections:
    """Plots of one radar sweep in the TDM's ENU frame.

    Parameters
    ----------
    sweep : dict
        The NPZ contract fields: ``echo`` (S, N) uint8 0..15; ``azimuth_deg`` (S,) clockwise from
        the bow; ``heading_deg`` (S,) own-ship heading per spoke, compass deg; ``time`` (S,) s
        since the recording's start; ``range_m`` (N,) range of each sample, m, ascending.
    track : OwnshipTrack
        Own-ship navigation (position, roll and pitch at any time).
    mount : Mount
        The radar's mounting on the own ship.
    config : RadarFrontEndConfig

    Returns
    -------
    Detections
        ``sensor="radar"``, ``scan_time_s`` the first spoke's time; per plot: ``time_s`` of its
        centre spoke, ``position_m`` its power-weighted centroid in ENU, ``range_m`` from the
        antenna, ``n_cells``, ``height_m`` NaN. Sizes, with ``r`` the plot's range, ``dr`` the
        sample spacing and ``res`` the range resolution:

        - range extent ``Lr = max(extent_r - s_r, dr)``: ``extent_r`` the span of its samples,
          ``s_r = res sqrt(log2(P_max / P_min))`` the width of a Gaussian range point-spread of FWHM
          ``res`` between the plot's strongest and weakest cells;
        - cross-range extent ``Lc = r max(extent_az - s_az, d_az)`` (radians), with
          ``s_az = theta3 sqrt(log2(P_max / P_min) / 2)`` the same for the two-way Gaussian beam
          ``exp(-8 ln2 theta^2 / theta3^2)`` (docs/reference.md 3.2) and ``d_az`` one spoke: the beam's
          smear is taken off, so a point target is about one cell and a ship its own size;
        - ``beam_fill = extent_az / max(s_az, d_az)``: a point echo paints at least the beam's
          ``s_az``, so a plot with a fill well under 1 is narrower than anything received through
          the antenna can be (a sea spike; busy_open_sea, sea state 4: of the plots from 15 dB over
          their background, clutter's have a median fill of 0.17 and 86 % are under 0.5, objects'
          a median of 1.1 and 1 % under 0.5, benchmarks/results/tdm_criteria.md);
        - ``cross_section_m2 = Lr Lc`` (the visible footprint); ``length_m`` / ``width_m`` the larger
          / smaller; ``orientation_deg`` the plot's bearing when the range extent is the longer,
          else the bearing + 90 deg, mod 180.

        Covariance in range and cross-range, rotated to ENU:
        ``var_r = (dr^2 + res^2) / 12 + (f max(Lr, Lc))^2`` (sample spacing and resolution, each a
        uniform error over its width, plus the unseen depth of the target behind its near face,
        taken as its larger visible side) and
        ``var_c = (b theta3 r)^2 + (f Lc)^2`` (bearing error growing with range, plus extent), with
        ``b = bearing_sigma_beam_fraction``, ``f = extent_sigma_fraction``, ``theta3`` in radians.
    """
    echo = np.asarray(sweep["echo"])
    azimuth_deg = np.asarray(sweep["azimuth_deg"], dtype=float)
    heading_deg = np.asarray(sweep["heading_deg"], dtype=float)
    time_s = np.asarray(sweep["time"], dtype=float)
    range_m = np.asarray(sweep["range_m"], dtype=float)
    if echo.ndim != 2 or not np.issubdtype(echo.dtype, np.integer):
        raise ValueError(f"sweep echo must be a 2-D array of integer video levels, not {echo.dtype} {echo.shape}")
    if echo.dtype != np.uint8 or int(echo.max(initial=0)) >= VIDEO_LEVELS:
        if int(echo.min(initial=0)) < 0 or int(echo.max(initial=0)) >= VIDEO_LEVELS:
            raise ValueError(f"sweep echo levels must be 0..{VIDEO_LEVELS - 1}")
        echo = echo.astype(np.uint8)
    n_spokes, n_samples = echo.shape
    if azimuth_deg.shape != (n_spokes,) or heading_deg.shape != (n_spokes,) or time_s.shape != (n_spokes,) \
            or range_m.shape != (n_samples,):
        raise ValueError("sweep azimuth_deg, heading_deg and time need one value per spoke, range_m one per sample")
    for name, expected, actual in (("spokes", config.spokes, n_spokes), ("samples", config.samples, n_samples)):
        if expected is not None and expected != actual:
            raise ValueError(f"sweep has {actual} {name}, the configuration {expected}")
    scan_time = float(time_s[0])

    flat, integrated, g = _plot_cells(echo, range_m, config)
    if flat.size == 0:
        return Detections.empty("radar", scan_time)
    spoke, sample = np.divmod(flat, n_samples)
    lab, n = _label_cells(flat, n_spokes, n_samples)
    n_cells = np.bincount(lab, minlength=n + 1)
    n_spk = _spokes_per_label(lab, spoke, n + 1, n_spokes)
    keep = (n_cells >= config.min_plot_cells) & (n_cells <= config.max_plot_cells) & (n_spk >= config.min_plot_spokes)
    keep[0] = False
    margin_db = _margin_over_clutter_db(lab, spoke, sample, n + 1, keep, integrated, g, config)
    keep &= margin_db >= config.clutter_margin_db
    if not keep.any():
        return Detections.empty("radar", scan_time)
    margin_db = margin_db[np.flatnonzero(keep)].astype(np.float64)
    sel = keep[lab]
    spoke, sample, lab = spoke[sel], sample[sel], lab[sel]
    _, lab = np.unique(lab, return_inverse=True)  # 0..m-1
    m = int(lab.max()) + 1
    power = video_power(echo[spoke, sample], config).astype(np.float64)

    # ---- centroid: power-weighted range and circular-mean bearing (relative to the bow)
    wsum = np.bincount(lab, power, m)
    rng = np.bincount(lab, power * range_m[sample], m) / wsum
    az = np.radians(azimuth_deg[spoke])
    bearing_rel = np.degrees(np.arctan2(np.bincount(lab, power * np.sin(az), m),
                                        np.bincount(lab, power * np.cos(az), m))) % 360.0

    # ---- extents, less the smear of the range point-spread and of the beam
    index = np.arange(m)
    d_az = _wrap_deg(azimuth_deg[spoke] - bearing_rel[lab])
    spoke_deg = 360.0 / n_spokes
    extent_az_deg = ndimage.maximum(d_az, lab, index) - ndimage.minimum(d_az, lab, index) + spoke_deg
    dr = float(np.median(np.diff(range_m))) if n_samples > 1 else 1.0
    extent_r_m = (ndimage.maximum(sample, lab, index) - ndimage.minimum(sample, lab, index) + 1) * dr
    dyn = np.log2(np.maximum(ndimage.maximum(power, lab, index) / ndimage.minimum(power, lab, index), 1.0))
    len_r = np.maximum(extent_r_m - config.range_resolution_m * np.sqrt(dyn), dr)
    beam_smear_deg = config.beam_az_deg * np.sqrt(dyn / 2.0)
    len_c = np.maximum(rng, dr) * np.radians(np.maximum(extent_az_deg - beam_smear_deg, spoke_deg))
    beam_fill = extent_az_deg / np.maximum(beam_smear_deg, spoke_deg)

    # ---- pose at each plot's centre spoke
    centre = _nearest_spoke(azimuth_deg, bearing_rel)
    t_plot = time_s[centre]
    # body -> ENU with the spoke's recorded heading and the track's roll and pitch: the track's
    # rotation turned about the vertical by (track - recorded) heading
    body_rot = _rot_z(np.radians(track.heading_deg(t_plot) - heading_deg[centre])) @ track.rotation(t_plot)
    rot = body_rot @ mount.rotation()  # sensor -> ENU
    a = np.radians(bearing_rel)
    ca, sa = np.cos(a), np.sin(a)
    # elevation (antenna frame) at which the fan beam at azimuth a is horizontal in the world
    e = np.arctan2(-(rot[:, 2, 0] * ca - rot[:, 2, 1] * sa), rot[:, 2, 2])
    d_sensor = np.stack([np.cos(e) * ca, -np.cos(e) * sa, np.sin(e)], axis=1)
    u = np.einsum("nij,nj->ni", rot, d_sensor)[:, :2]
    u /= np.maximum(np.linalg.norm(u, axis=1, keepdims=True), 1e-12)
    antenna = track.position_m(t_plot)[:, :2] + np.einsum("nij,j->ni", body_rot, mount.translation_m())[:, :2]
    position = antenna + rng[:, None] * u

    # ---- own-ship rejection: centroid in the body frame (mount offset and yaw applied)
    p_body = np.stack([rng * ca, -rng * sa, np.zeros(m)], axis=1) @ mount.rotation().T + mount.translation_m()
    off_ship = ~((np.abs(p_body[:, 0]) <= 0.5 * config.own_ship_length_m + config.own_ship_margin_m)
                 & (np.abs(p_body[:, 1]) <= 0.5 * config.own_ship_beam_m + config.own_ship_margin_m))

    # ---- covariance: range / cross-range, rotated to ENU (u radial, c cross)
    f = config.extent_sigma_fraction
    var_r = (dr * dr + config.range_resolution_m ** 2) / 12.0 + (f * np.maximum(len_r, len_c)) ** 2
    sigma_bearing_m = np.maximum(rng, dr) * math.radians(config.beam_az_deg) * config.bearing_sigma_beam_fraction
    var_c = sigma_bearing_m ** 2 + (f * len_c) ** 2
    c = np.stack([u[:, 1], -u[:, 0]], axis=1)
    cov = var_r[:, None, None] * u[:, :, None] * u[:, None, :] + var_c[:, None, None] * c[:, :, None] * c[:, None, :]

    compass = np.degrees(np.arctan2(u[:, 0], u[:, 1]))
    orientation = np.mod(np.where(len_r >= len_c, compass, compass + 90.0), 180.0)
    k = off_ship
    return Detections(
        sensor="radar",
        scan_time_s=scan_time,
        time_s=t_plot[k],
        position_m=position[k],
        position_cov_m2=cov[k],
        cross_section_m2=(len_r * len_c)[k],
        length_m=np.maximum(len_r, len_c)[k],
        width_m=np.minimum(len_r, len_c)[k],
        orientation_deg=orientation[k],
        height_m=np.full(int(np.count_nonzero(k)), np.nan),
        n_cells=np.bincount(lab, minlength=m).astype(np.int64)[k],
        range_m=rng[k],
        strength_db=margin_db[k],
        beam_fill=beam_fill[k],
    )


def _wrap_deg(a):
    """Angles wrapped into [-180, 180) deg."""
    return (np.asarray(a) + 180.0) % 360.0 - 180.0


def _nearest_spoke(azimuth_deg: np.ndarray, bearing_deg: np.ndarray) -> np.ndarray:
    """(M,) index of the spoke whose azimuth is nearest each bearing (circular)."""
    order = np.argsort(azimuth_deg % 360.0)
    az = (azimuth_deg % 360.0)[order]
    pos = np.searchsorted(az, bearing_deg) % az.size
    prev = (pos - 1) % az.size
    nearer_prev = np.abs(_wrap_deg(az[prev] - bearing_deg)) < np.abs(_wrap_deg(az[pos] - bearing_deg))
    return order[np.where(nearer_prev, prev, pos)]


def _rot_z(angle_rad: np.ndarray) -> np.ndarray:
    """(M, 3, 3) rotations about the vertical by ``angle_rad`` (counter-clockwise)."""
    c, s = np.cos(angle_rad), np.sin(angle_rad)
    r = np.zeros(np.shape(angle_rad) + (3, 3))
    r[..., 0, 0], r[..., 0, 1], r[..., 1, 0], r[..., 1, 1], r[..., 2, 2] = c, -s, s, c, 1.0
    return r

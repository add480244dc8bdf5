"""Radar front end: one polar sweep -> CFAR -> plots -> :class:`~tdm.detections.Detections` in ENU.

Steps (numpy/scipy-vectorised; Python loops only over blocks of spokes and chunks of cells). Steps 1-3
and the integration of step 5 run on blocks of whole integration groups of spokes (``_BLOCK_CELLS``
cells), so that their per-cell arrays stay in cache; every step reads only the cells above level 0
(a few per cent of a sea sweep) and gives the same numbers as on the whole sweep at once (tested):

1. Video to power (:func:`video_power`; module :mod:`tdm.frontend.radar_cfar`). A sweep holds 4-bit *log* video levels (docs/reference.md
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

2. CFAR along range (:func:`cfar_mask`, :mod:`tdm.frontend.radar_cfar`), every spoke. The training cells of a cell under test (CUT)
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
   ``alpha x`` the floor): a few per cent of a sweep. For OS on video the counts of a CUT whose
   training cells all lie on its spoke are byte-parallel on the sweep's aligned 64-bit words (eight
   4-bit levels compared at once, the training bytes masked, one ``np.bitwise_count``), or, for a
   blocking level many CUTs share, on the bit plane of the cells that reach it; otherwise
   the training cells are read through ``numpy.lib.stride_tricks.sliding_window_view`` (two
   contiguous halves per CUT) or, near the ends, a precomputed index table.

3. Gap filling along range (:func:`fill_gaps`, :mod:`tdm.frontend.radar_plots`). An extended target (a ship end-on covers tens of samples) fills the
   training window of its own interior, so CFAR keeps only its edges. A cell joins the detections
   when it lies on a spoke between two detections and every cell from one to the other has a
   level >= ``fill_level``.

3b. Clutter-map detection (``clutter_map_detection``, on by default; :mod:`tdm.frontend.radar_extended`): every cell whose
   beam-integrated power reaches its block's clutter-map seed threshold (step 5) is a detection too, so the
   interior of an echo that masked itself joins its edges.

4. Plots (:func:`label_plots`, :mod:`tdm.frontend.radar_plots`): connected components of the detections, 8-connected and circular in azimuth (the last
   spoke touches the first), the same partition ``scipy.ndimage.label`` gives once the components
   that touch across the seam are merged (tested); worked out on runs along range and
   ``scipy.sparse.csgraph.connected_components``, which is faster on a sparse sweep. The size and
   spoke tests of step 6 run on the runs too; only the cells of the plots that pass them are spelt
   out for the clutter test.

5. Clutter map (:func:`clutter_map`, :mod:`tdm.frontend.radar_clutter`): one-dimensional CFAR cannot tell sea clutter from targets on
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

The settings are :class:`RadarFrontEndConfig` (:mod:`tdm.frontend.radar_config`). Every public name of
the front end stays importable from this module.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import connected_components

from tdm.detections import Detections
from tdm.frames import Mount, OwnshipTrack
from tdm.frontend.radar_cfar import (VIDEO_LEVELS, _cfar_cells, _first_valid_sample, _lowest_candidate_level, _nonzero_flat,
                                     cfar_mask, training_table, video_power, video_power_table)
from tdm.frontend.radar_clutter import (LandBlocks, _group_sums, _margin_over_clutter_db, _windows, beam_integrated_power,
                                       clutter_map, integration_group)
from tdm.frontend.radar_config import RadarFrontEndConfig, ca_alpha, mount_from_scenario, os_alpha
from tdm.frontend.radar_extended import clutter_map_cells
from tdm.frontend.radar_land import land_blocks
from tdm.frontend.radar_plots import _runs, fill_gaps, label_plots
from tdm.frontend.radar_sizes import orientation_deg, plot_sizes, resolution_cells
from tdm.land import LandMask, ashore

__all__ = ["RadarFrontEndConfig", "beam_integrated_power", "ca_alpha", "cfar_mask", "clutter_map", "fill_gaps",
           "label_plots", "mount_from_scenario", "os_alpha", "radar_detections", "training_table", "video_power",
           "video_power_table"]

#: Variance of a uniform error over a width w is w^2 / 12 (sample spacing, range resolution).
UNIFORM_VARIANCE_DIVISOR = 12.0
#: Smallest norm of a horizontal beam direction before it is normalised (no division by zero).
_MIN_DIRECTION_NORM = 1e-12
#: Cells per block of spokes the detection steps work on at a time (their per-cell arrays stay in cache).
_BLOCK_CELLS = 1 << 18
#: Sample spacing taken for a sweep of one sample, m (no spacing to measure).
_ONE_SAMPLE_SPACING_M = 1.0




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
    g = integration_group(n_spokes, config)
    step = g * max(1, _BLOCK_CELLS // (g * n_samples))  # spokes per block, whole integration groups
    groups = np.empty((n_spokes // g, n_samples))
    cells = []
    for r0 in range(0, n_spokes, step):
        block = echo[r0:r0 + step]
        flat, groups[r0 // g:(r0 + block.shape[0]) // g] = _block_cells(block, first, g, config)
        cells.append(flat + r0 * n_samples)
    return np.concatenate(cells), _windows(groups, g), g


def _block_cells(block: np.ndarray, first: int, g: int, config: RadarFrontEndConfig) -> tuple[np.ndarray, np.ndarray]:
    """Detected and filled cells of a block of whole integration groups of spokes (S_b, N) of a sweep,
    and its :func:`~tdm.frontend.radar_clutter._group_sums` (S_b / g, N) (module docstring, steps 1-3, 5).

    Works on the cells above level 0 only (a few per cent of a sweep). Returns (M,) int64 ascending
    flat indices within the block.
    """
    n_samples = block.shape[1]
    power_table = video_power_table(config.video_threshold_db, config.video_step_db)
    nz = _nonzero_flat(block)
    rows, cols = np.divmod(nz, n_samples)
    if first > 0:
        keep = cols >= first
        nz, rows, cols = nz[keep], rows[keep], cols[keep]
    levels = np.minimum(block.reshape(-1)[nz], VIDEO_LEVELS - 1)
    groups = _group_sums(rows, cols, power_table[levels] - 1.0, block.shape[0] // g, g, n_samples)
    testable = levels >= _lowest_candidate_level(config)
    if testable.all():
        detected = _cfar_cells(block, rows, cols, config, first)
    else:
        detected = np.zeros(nz.size, dtype=bool)
        detected[testable] = _cfar_cells(block, rows[testable], cols[testable], config, first)
    if config.fill_level > 0:
        strong = levels >= config.fill_level
        if strong.all():
            detected |= _filled_between_detections(nz, detected, n_samples)
        else:
            strong = np.flatnonzero(strong)
            detected[strong] |= _filled_between_detections(nz[strong], detected[strong], n_samples)
    return nz[detected], groups


def _filled_between_detections(flat: np.ndarray, detected: np.ndarray, n_samples: int) -> np.ndarray:
    """(M,) bool: the cells strictly between two detections of one run (module docstring, step 3).

    ``flat`` (M,) are the ascending flat indices of the cells strong enough to fill, ``detected``
    (M,) bool which of them are detections; a run is a maximal sequence of them that are
    consecutive samples of one spoke. Two detections next to each other among the detections
    share a run exactly when every flat index between them is a strong cell (their flat indices lie
    as far apart as their positions) on their spoke, and then the cells between them are filled:
    the same cells as from the first to the last detection of each run
    (:func:`tdm.frontend.radar_plots.fill_gaps`).
    """
    out = np.zeros(flat.size + 1, dtype=np.int8)
    det = np.flatnonzero(detected)
    if det.size < 2:
        return out[:-1].astype(bool)
    at, nxt = det[:-1], det[1:]
    f_at, f_nxt = flat[at], flat[nxt]
    joined = (nxt - at > 1) & (f_nxt - f_at == nxt - at) & (f_at // n_samples == f_nxt // n_samples)
    out[at[joined] + 1] = 1  # each gap opens after one detection and closes at the next: no overlaps
    out[nxt[joined]] = -1
    return np.cumsum(out[:-1], dtype=np.int8).astype(bool)


def _checked_sweep(sweep: dict, config: RadarFrontEndConfig
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """A sweep's arrays, checked against each other and the configuration: echo (uint8 levels),
    azimuth_deg, heading_deg, time (s), range_m (:func:`radar_detections`)."""
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
    return echo, azimuth_deg, heading_deg, time_s, range_m


@dataclass(frozen=True)
class _Plots:
    """The cells of a sweep's kept plots: spoke, sample and plot (0..n - 1) of each; per plot its
    margin over the clutter, dB."""

    spoke: np.ndarray
    sample: np.ndarray
    label: np.ndarray
    n: int
    margin_db: np.ndarray


def _kept_plots(echo: np.ndarray, range_m: np.ndarray, config: RadarFrontEndConfig,
                land: LandBlocks | None = None) -> _Plots | None:
    """The plots that pass the size, spoke and clutter tests (module docstring, steps 1-6), or None.

    Counts and tests run on the plots' runs along range (:func:`_label_runs`); only the cells of the
    plots that pass the size and spoke tests are spelt out for the clutter test. ``land``: the
    clutter map's land blocks, left out of the clutter level (:mod:`tdm.frontend.radar_land`).
    """
    n_spokes, n_samples = echo.shape
    flat, integrated, g = _plot_cells(echo, range_m, config)
    if config.clutter_map_detection:
        flat = _sorted_union(flat, clutter_map_cells(echo, range_m, integrated, g, config))
    if flat.size == 0:
        return None
    runs = _label_runs(flat, n_spokes, n_samples)
    n_cells = np.bincount(runs.label, weights=runs.length, minlength=runs.n + 1)
    keep = (n_cells >= config.min_plot_cells) & (n_cells <= config.max_plot_cells)
    keep[0] = False
    sized = np.flatnonzero(keep[runs.label])
    keep &= _spokes_per_label(runs.label[sized], runs.spoke[sized], runs.n + 1, n_spokes) >= config.min_plot_spokes
    pos, lab, spoke = _run_cells(runs, np.flatnonzero(keep[runs.label]))
    sample = flat[pos] - spoke * n_samples
    margin_db = _margin_over_clutter_db(lab, spoke, sample, runs.n + 1, keep, integrated, g, config, land)
    keep &= margin_db >= config.clutter_margin_db
    if not keep.any():
        return None
    margin_db = margin_db[np.flatnonzero(keep)].astype(np.float64)
    sel = keep[lab]
    number = np.cumsum(keep) - 1  # kept labels -> 0..m-1 in their order
    return _Plots(spoke[sel], sample[sel], number[lab[sel]], int(number[-1]) + 1, margin_db)


def _sorted_union(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``np.union1d`` of two ascending arrays of unique integers, by merging: ``b``'s values not in ``a`` inserted in
    place (no sort of the whole; on a sea-state-4 sweep union1d's hashing took 7 ms of the front end's 40)."""
    if a.size == 0 or b.size == 0:
        return b.astype(np.int64) if a.size == 0 else a
    at = np.searchsorted(a, b)
    new = b[a[np.minimum(at, a.size - 1)] != b]
    return np.insert(a, np.searchsorted(a, new), new)


@dataclass(frozen=True)
class _Runs:
    """A sweep's plot cells as runs along range (ascending flat order): (R,) position in the cells'
    ``flat`` of each run's first cell, its length, spoke and plot label 1..n; n the number of plots."""

    start: np.ndarray
    length: np.ndarray
    spoke: np.ndarray
    label: np.ndarray
    n: int


def _label_runs(flat: np.ndarray, n_spokes: int, n_samples: int) -> _Runs:
    """Runs of the cells ``flat`` (ascending flat indices, not empty) labelled by 8-connectivity,
    circular in azimuth: the partition and numbering of :func:`tdm.frontend.radar_plots._label_cells`.

    Two runs on neighbouring spokes (the last spoke's neighbour is the first) touch when their sample
    intervals, widened by one, overlap; the runs' graph, built as CSR (each run's row its touching
    runs on the previous spoke), goes through ``scipy.sparse.csgraph.connected_components``, which
    numbers components in the order of their first node (checked; renumbered if not).
    """
    starts, ends = _runs(flat, n_samples)
    spoke, a = np.divmod(flat[starts], n_samples)
    b = flat[ends] - spoke * n_samples
    width = n_samples + 2  # keys keep spokes apart: spoke * width + sample, samples -1 .. n_samples
    prev = (spoke - 1) % n_spokes
    lo = np.searchsorted(spoke * width + b, prev * width + a - 1, side="left")  # first on prev ending >= a - 1
    hi = np.searchsorted(spoke * width + a, prev * width + b + 1, side="right")  # past the last starting <= b + 1
    count = np.maximum(hi - lo, 0)
    if n_spokes < 3:  # a spoke is its own neighbour's neighbour: no self-loops
        count = np.where(prev == spoke, 0, count)
    indptr = np.zeros(starts.size + 1, dtype=np.int64)
    np.cumsum(count, out=indptr[1:])
    neighbours = np.repeat(lo - indptr[:-1], count) + np.arange(indptr[-1])
    graph = csr_matrix((np.ones(neighbours.size), neighbours, indptr), shape=(starts.size, starts.size))
    n, comp = connected_components(graph, directed=False)
    return _Runs(starts, ends - starts + 1, spoke, (_numbered_by_first(comp) + 1).astype(np.int32), int(n))


def _numbered_by_first(comp: np.ndarray) -> np.ndarray:
    """(R,) int component numbers 0..n-1 of ``comp`` (R,), renumbered in the order of their first element.

    ``connected_components`` numbers them so already (checked in one pass); else renumbered by sorting.
    """
    if comp.size == 0 or (comp[0] == 0 and not np.any(np.diff(np.maximum.accumulate(comp)) > 1)):
        return comp
    _, first, inverse = np.unique(comp, return_index=True, return_inverse=True)
    return np.argsort(np.argsort(first))[inverse]


def _spokes_per_label(lab: np.ndarray, spoke: np.ndarray, n_labels: int, n_spokes: int) -> np.ndarray:
    """(n_labels,) number of distinct spokes among the runs (or cells) of each label: ``lab`` and ``spoke`` (M,).

    As :func:`tdm.frontend.radar_plots._spokes_per_label`, with the (label, spoke) pairs made distinct by
    a sort (``np.unique`` on integers hashes, several times slower here).
    """
    pair = np.sort(lab.astype(np.int64) * n_spokes + spoke)
    if pair.size:
        pair = pair[np.concatenate(([True], pair[1:] != pair[:-1]))]
    return np.bincount(pair // n_spokes, minlength=n_labels)


def _run_cells(runs: _Runs, which: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The cells of the runs ``which`` (ascending): (M,) position in the cells' ``flat``, label and spoke of each."""
    length = runs.length[which]
    offset = np.cumsum(length) - length  # each run's first cell among the M
    pos = np.repeat(runs.start[which] - offset, length) + np.arange(int(offset[-1] + length[-1]) if length.size else 0)
    return pos, np.repeat(runs.label[which], length), np.repeat(runs.spoke[which], length)


def _centroids(plots: _Plots, power: np.ndarray, range_m: np.ndarray, azimuth_deg: np.ndarray
               ) -> tuple[np.ndarray, np.ndarray]:
    """(m,) power-weighted range (m) and circular-mean bearing relative to the bow (deg, [0, 360)) of each plot."""
    lab, m = plots.label, plots.n
    wsum = np.bincount(lab, power, m)
    plot_range_m = np.bincount(lab, power * range_m[plots.sample], m) / wsum
    az = np.radians(azimuth_deg[plots.spoke])
    bearing_rel_deg = np.degrees(np.arctan2(np.bincount(lab, power * np.sin(az), m),
                                            np.bincount(lab, power * np.cos(az), m))) % 360.0
    return plot_range_m, bearing_rel_deg


def _plot_positions(bearing_rel_deg: np.ndarray, plot_range_m: np.ndarray, azimuth_deg: np.ndarray,
                    heading_deg: np.ndarray, time_s: np.ndarray, track: OwnshipTrack, mount: Mount
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each plot's time (s, its centre spoke's), horizontal unit direction from the antenna (m, 2) and
    ENU position (m, 2), m (module docstring, step 6)."""
    centre = _nearest_spoke(azimuth_deg, bearing_rel_deg)
    t_plot = time_s[centre]
    # body -> ENU with the spoke's recorded heading and the track's roll and pitch: the track's
    # rotation turned about the vertical by (track - recorded) heading
    body_rot = _rot_z(np.radians(track.heading_deg(t_plot) - heading_deg[centre])) @ track.rotation(t_plot)
    rot = body_rot @ mount.rotation()  # sensor -> ENU
    a = np.radians(bearing_rel_deg)
    ca, sa = np.cos(a), np.sin(a)
    # elevation (antenna frame) at which the fan beam at azimuth a is horizontal in the world
    elevation_rad = np.arctan2(-(rot[:, 2, 0] * ca - rot[:, 2, 1] * sa), rot[:, 2, 2])
    d_sensor = np.stack([np.cos(elevation_rad) * ca, -np.cos(elevation_rad) * sa, np.sin(elevation_rad)], axis=1)
    u = np.einsum("nij,nj->ni", rot, d_sensor)[:, :2]
    u /= np.maximum(np.linalg.norm(u, axis=1, keepdims=True), _MIN_DIRECTION_NORM)
    antenna = track.position_m(t_plot)[:, :2] + np.einsum("nij,j->ni", body_rot, mount.translation_m())[:, :2]
    return t_plot, u, antenna + plot_range_m[:, None] * u


def _off_ship(bearing_rel_deg: np.ndarray, plot_range_m: np.ndarray, mount: Mount,
              config: RadarFrontEndConfig) -> np.ndarray:
    """(m,) bool: the plot's centroid lies outside the own ship's box (body frame, mount offset and yaw applied)."""
    a = np.radians(bearing_rel_deg)
    ca, sa = np.cos(a), np.sin(a)
    p_body = (np.stack([plot_range_m * ca, -plot_range_m * sa, np.zeros(plot_range_m.size)], axis=1)
              @ mount.rotation().T + mount.translation_m())
    return ~((np.abs(p_body[:, 0]) <= 0.5 * config.own_ship_length_m + config.own_ship_margin_m)
             & (np.abs(p_body[:, 1]) <= 0.5 * config.own_ship_beam_m + config.own_ship_margin_m))


def _plot_covariance(plot_range_m: np.ndarray, u: np.ndarray, len_r_m: np.ndarray, len_c_m: np.ndarray,
                     spacing_m: float, config: RadarFrontEndConfig) -> np.ndarray:
    """(m, 2, 2) ENU position covariance, m^2: range / cross-range variances rotated (u radial)
    (:func:`radar_detections`)."""
    f = config.extent_sigma_fraction
    var_r = ((spacing_m * spacing_m + config.range_resolution_m ** 2) / UNIFORM_VARIANCE_DIVISOR
             + (f * np.maximum(len_r_m, len_c_m)) ** 2)
    sigma_bearing_m = np.maximum(plot_range_m, spacing_m) * math.radians(config.beam_az_deg) \
        * config.bearing_sigma_beam_fraction
    var_c = sigma_bearing_m ** 2 + (f * len_c_m) ** 2
    c = np.stack([u[:, 1], -u[:, 0]], axis=1)
    return var_r[:, None, None] * u[:, :, None] * u[:, None, :] + var_c[:, None, None] * c[:, :, None] * c[:, None, :]


def radar_detections(sweep: dict, track: OwnshipTrack, mount: Mount, config: RadarFrontEndConfig,
                     land: LandMask | None = None) -> Detections:
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
    land : LandMask, optional
        The chart's land, out of the clutter level (:mod:`tdm.frontend.radar_land`); not dropped here.

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
          their background, clutter's have a median fill of 0.16 and 70 % are under 0.5, objects'
          a median of 1.04 and 1 % under 0.5, benchmarks/results/tdm_criteria.md);
        - ``core_width_m = r sqrt(core_az^2 - (theta3 sqrt(c / 6.02))^2)`` (radians, 0 if negative): the width
          of the cells within ``c = core_db`` of the strongest, less the two-way beam's width ``c`` dB down, in
          quadrature; the size of an object the beam does not resolve, which ``Lc`` (taken down to the plot's
          weakest cell) loses in a saturated echo (docs/tdm.md, "Extended objects");
        - ``resolution_cells = n_cells (360 / spokes / beam_az_deg) (dr / res)``: cells in beamwidths x resolutions;
        - ``echo_spread_m``: how much further the echo a plot is a fragment of reaches than its core
          (:func:`tdm.frontend.radar_echoes.fragment_spread_m`, ``echo_gap_m``; 0 for a plot alone);
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
    echo, azimuth_deg, heading_deg, time_s, range_m = _checked_sweep(sweep, config)
    (n_spokes, n_samples), scan_time = echo.shape, float(time_s[0])
    plots = _kept_plots(echo, range_m, config, _sweep_land_blocks(land, azimuth_deg, heading_deg, time_s, range_m,
                                                                  track, mount, config))
    if plots is None:
        return Detections.empty("radar", scan_time)
    spacing_m, plot_range_m, bearing_rel_deg, power, d_az = _plot_measures(plots, echo, range_m, azimuth_deg, config)
    t_plot, u, position = _plot_positions(bearing_rel_deg, plot_range_m, azimuth_deg, heading_deg, time_s, track,
                                          mount)
    size = plot_sizes(plots.sample, plots.label, plots.n, power, d_az, bearing_rel_deg, plot_range_m, spacing_m,
                      n_spokes, config, _off_land(land, position, plot_range_m, config))
    len_r, len_c = size.len_r_m, size.len_c_m
    k = _off_ship(bearing_rel_deg, plot_range_m, mount, config)
    cov = _plot_covariance(plot_range_m, u, len_r, len_c, spacing_m, config)
    orientation = orientation_deg(u, len_r, len_c)
    n_cells = np.bincount(plots.label, minlength=plots.n).astype(np.int64)
    return Detections(
        sensor="radar", scan_time_s=scan_time, time_s=t_plot[k], position_m=position[k], position_cov_m2=cov[k],
        cross_section_m2=(len_r * len_c)[k], length_m=np.maximum(len_r, len_c)[k],
        width_m=np.minimum(len_r, len_c)[k], orientation_deg=orientation[k],
        height_m=np.full(int(np.count_nonzero(k)), np.nan), n_cells=n_cells[k], range_m=plot_range_m[k],
        strength_db=plots.margin_db[k], beam_fill=size.beam_fill[k],
        resolution_cells=resolution_cells(n_cells[k], n_spokes, spacing_m, config),
        core_width_m=size.core_width_m[k], echo_spread_m=size.echo_spread_m[k])


def _plot_measures(plots: _Plots, echo: np.ndarray, range_m: np.ndarray, azimuth_deg: np.ndarray,
                   config: RadarFrontEndConfig) -> tuple[float, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The sweep's sample spacing (m); each plot's power-weighted range (m) and bearing from the bow (deg) (m,); each
    plot cell's power (linear) and azimuth from its plot's bearing (deg) (M,)."""
    n_samples = echo.shape[1]
    power = video_power(echo[plots.spoke, plots.sample], config).astype(np.float64)
    spacing_m = float(np.median(np.diff(range_m))) if n_samples > 1 else _ONE_SAMPLE_SPACING_M
    plot_range_m, bearing_rel_deg = _centroids(plots, power, range_m, azimuth_deg)
    d_az = _wrap_deg(azimuth_deg[plots.spoke] - bearing_rel_deg[plots.label])
    return spacing_m, plot_range_m, bearing_rel_deg, power, d_az


def _off_land(land: LandMask | None, position_m: np.ndarray, plot_range_m: np.ndarray,
              config: RadarFrontEndConfig) -> np.ndarray | None:
    """(m,) bool: the plots the chart's land will not take (:func:`tdm.land.drop_on_land` with the radar's beam
    margin), which alone may be fragments of one echo; None without a chart."""
    if land is None:
        return None
    return ~ashore(land, position_m, plot_range_m, config.land_beam_fraction, config.beam_az_deg)


def _sweep_land_blocks(land: LandMask | None, azimuth_deg: np.ndarray, heading_deg: np.ndarray, time_s: np.ndarray,
                       range_m: np.ndarray, track: OwnshipTrack, mount: Mount,
                       config: RadarFrontEndConfig) -> LandBlocks | None:
    """The clutter map's land test bound to this sweep (:func:`tdm.frontend.radar_land.land_blocks`), or None
    without a chart or with ``clutter_map_without_land`` off."""
    if land is None or not config.clutter_map_without_land:
        return None

    def land_at(candidates: np.ndarray, spokes_per_block: int, samples_per_block: int,
                beam_fraction: float) -> np.ndarray:
        return land_blocks(land, candidates, spokes_per_block, samples_per_block, azimuth_deg, heading_deg,
                           time_s, range_m, track, mount, beam_fraction, config.beam_az_deg)
    return land_at


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

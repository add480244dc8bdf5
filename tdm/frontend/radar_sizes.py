"""A radar plot's size measures: its extents less the beam's and the range point-spread's smear, its beam fill, its
core width, its echo spread and its resolution cells (the formulas: :func:`tdm.frontend.radar.radar_detections`).

Each works on a sweep's plot cells: ``sample`` (M,) range sample and ``label`` (M,) plot 0..n-1 of each cell, its
``power`` (M,) (linear, over the noise) and ``d_az`` (M,) azimuth from its plot's bearing, deg.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tdm.frontend.radar_config import RadarFrontEndConfig
from tdm.frontend.radar_echoes import fragment_spread_m
from tdm.frontend.radar_plots import label_max_min

__all__ = ["PlotSizes", "orientation_deg", "plot_sizes", "resolution_cells"]

#: The two-way beam ``exp(-8 ln2 theta^2 / theta3^2)`` is the one-way beam squared: its smear between
#: two powers is the one-way width over sqrt(2) (cross-range extent).
TWO_WAY = 2.0
#: The two-way Gaussian beam is down by this many dB at its one-way -3 dB width, ``20 log10(2)``: its width at
#: ``x`` dB down is ``theta3 sqrt(x / 6.02)`` (core width).
TWO_WAY_HALF_POWER_DB = 20.0 * np.log10(2.0)


@dataclass(frozen=True)
class PlotSizes:
    """Per plot (n,): range and cross-range extent (m), beam fill, core width (m) and echo spread (m)."""

    len_r_m: np.ndarray
    len_c_m: np.ndarray
    beam_fill: np.ndarray
    core_width_m: np.ndarray
    echo_spread_m: np.ndarray


def plot_sizes(sample: np.ndarray, label: np.ndarray, n: int, power: np.ndarray, d_az: np.ndarray,
               bearing_deg: np.ndarray, plot_range_m: np.ndarray, spacing_m: float, n_spokes: int,
               config: RadarFrontEndConfig, joinable: np.ndarray | None = None) -> PlotSizes:
    """Every size measure of a sweep's ``n`` plots (module docstring for the cell arrays; ``bearing_deg`` (n,) and
    ``plot_range_m`` (n,) each plot's, ``spacing_m`` the sample spacing, ``n_spokes`` the sweep's spokes;
    ``joinable`` (n,) bool the plots that may be fragments of one echo, None: all)."""
    power_max, power_min = label_max_min(power, label, n)
    core = power >= power_max[label] * 10.0 ** (-config.core_db / 10.0)  # within core_db of its plot's strongest
    len_r, len_c, beam_fill = _extents(sample, label, n, d_az, power_max, power_min, plot_range_m, spacing_m,
                                       n_spokes, config)
    spread = np.zeros(n) if config.echo_gap_m is None else fragment_spread_m(
        d_az, sample, label, n, bearing_deg, plot_range_m, spacing_m, 360.0 / n_spokes, config.echo_gap_m, core,
        power_max, joinable=joinable)
    return PlotSizes(len_r, len_c, beam_fill, _core_widths(label, n, core, d_az, plot_range_m, n_spokes, config),
                     spread)


def _extents(sample: np.ndarray, label: np.ndarray, n: int, d_az: np.ndarray, power_max: np.ndarray,
             power_min: np.ndarray, plot_range_m: np.ndarray, spacing_m: float, n_spokes: int,
             config: RadarFrontEndConfig) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(n,) range extent Lr (m), cross-range extent Lc (m) and beam fill of each plot, less the smear of the range
    point-spread and of the beam; ``power_max``, ``power_min`` (n,) each plot's strongest and weakest cell's power."""
    spoke_deg = 360.0 / n_spokes
    az_max, az_min = label_max_min(d_az, label, n)
    extent_az_deg = az_max - az_min + spoke_deg
    sample_max, sample_min = label_max_min(sample, label, n)
    extent_r_m = (sample_max - sample_min + 1) * spacing_m
    # log2 of the plot's power ratio, strongest to weakest cell
    dynamic_log2 = np.log2(np.maximum(power_max / power_min, 1.0))
    len_r_m = np.maximum(extent_r_m - config.range_resolution_m * np.sqrt(dynamic_log2), spacing_m)
    beam_smear_deg = config.beam_az_deg * np.sqrt(dynamic_log2 / TWO_WAY)
    len_c_m = np.maximum(plot_range_m, spacing_m) * np.radians(np.maximum(extent_az_deg - beam_smear_deg, spoke_deg))
    beam_fill = extent_az_deg / np.maximum(beam_smear_deg, spoke_deg)
    return len_r_m, len_c_m, beam_fill


def _core_widths(label: np.ndarray, n: int, core: np.ndarray, d_az: np.ndarray, plot_range_m: np.ndarray,
                 n_spokes: int, config: RadarFrontEndConfig) -> np.ndarray:
    """(n,) cross-range width of each plot's core, m: the azimuth extent of its ``core`` cells (M,) bool (those
    within ``core_db`` of its strongest), less in quadrature the width the two-way Gaussian beam paints down to
    ``core_db`` (``theta3 sqrt(core_db / 6.02)``), times its range; 0 where the core is no wider than the beam."""
    az_max, az_min = label_max_min(d_az[core], label[core], n)
    core_deg = az_max - az_min + 360.0 / n_spokes
    beam_deg = config.beam_az_deg * np.sqrt(config.core_db / TWO_WAY_HALF_POWER_DB)
    return plot_range_m * np.radians(np.sqrt(np.maximum(core_deg ** 2 - beam_deg ** 2, 0.0)))


def orientation_deg(u: np.ndarray, len_r: np.ndarray, len_c: np.ndarray) -> np.ndarray:
    """(P,) plots' orientation, deg in [0, 180): the bearing of the line of sight ``u`` (P, 2) (east, north) where the
    range extent ``len_r`` (P,) is the longer, else that bearing + 90 deg (``len_c`` (P,) the cross-range extent)."""
    compass = np.degrees(np.arctan2(u[:, 0], u[:, 1]))
    return np.mod(np.where(len_r >= len_c, compass, compass + 90.0), 180.0)


def resolution_cells(n_cells: np.ndarray, n_spokes: int, spacing_m: float, config: RadarFrontEndConfig) -> np.ndarray:
    """(P,) how many of the radar's resolution cells (a beamwidth by a range resolution) plots of ``n_cells`` (P,)
    sweep cells cover: ``n_cells (360 / n_spokes / beam_az_deg) (spacing_m / range_resolution_m)``."""
    return n_cells * (360.0 / n_spokes / config.beam_az_deg) * (spacing_m / config.range_resolution_m)

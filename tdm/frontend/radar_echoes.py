"""Radar plots that are fragments of one echo: how far each may lie from the centre of what painted it.

A long echo seldom stands out of its background in one piece. harbour_approach's 60 m pier, end-on at 550 m, and the
30 m ship moored beside it paint video that is broken along range by a few samples at level 0 (the deck between its
faces and fenders returns little): the front end makes 2-6 plots of it a sweep, different ones each sweep, each a few
metres long, and the tracker one track on each that persists. Each track then reports the small covariance of a small
echo, while the object's centre lies anywhere along the whole echo, 20-30 m from an end fragment.

So plots whose cells share a spoke and lie within ``gap_m`` of each other along it are taken as fragments of one echo
(:func:`fragment_spread_m`), and each plot gets the extent of its echo beyond its own: the span over which its object's
centre may lie from it, which a radar track reports (:func:`tdm.fusion_face.sensor_report`). A plot alone keeps 0.
The gap, ``RadarFrontEndConfig.echo_gap_m`` (10 m, four range resolutions, as the sidelobe rule's range gate), is
the radar's, not fitted: two echoes further apart along one spoke are resolved targets.
"""

from __future__ import annotations

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from tdm.frontend.radar_plots import label_max_min

__all__ = ["FRAGMENT_DB", "fragment_spread_m"]

#: A plot more than this far under its echo's strongest is a piece of that echo's range sidelobes or skirt, not more
#: of the object, dB: the FMCW sets' range response has its first sidelobe 31.5 dB down (docs/radar.md, "Receiver"),
#: and the two-way antenna pattern is 42 dB down at 6 deg (docs/radar.md, "Antenna"); 20 dB keeps the pieces of a
#: pier or a hull, which paint within about 12 dB of each other (harbour_approach).
FRAGMENT_DB = 20.0


def _extents(d_az_deg: np.ndarray, sample: np.ndarray, label: np.ndarray, n: int, bearing_deg: np.ndarray,
             spacing_m: float, spoke_deg: float) -> tuple[tuple[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]:
    """Per plot (n,): the centre and half width of its cells' azimuth interval, deg, each cell a spoke wide, and
    the near and far end of its range interval, m, each sample ``spacing_m`` long."""
    az_high, az_low = label_max_min(d_az_deg, label, n)
    az_low, az_high = bearing_deg + az_low - spoke_deg / 2.0, bearing_deg + az_high + spoke_deg / 2.0
    r_high, r_low = label_max_min(sample.astype(float), label, n)
    return ((az_low + az_high) / 2.0, (az_high - az_low) / 2.0), (r_low * spacing_m, (r_high + 1.0) * spacing_m)


def fragment_spread_m(d_az_deg: np.ndarray, sample: np.ndarray, label: np.ndarray, n: int, bearing_deg: np.ndarray,
                      plot_range_m: np.ndarray, spacing_m: float, spoke_deg: float, gap_m: float,
                      core: np.ndarray | None = None, peak_power: np.ndarray | None = None,
                      fragment_db: float = FRAGMENT_DB, joinable: np.ndarray | None = None) -> np.ndarray:
    """How much further the echo a plot is a fragment of reaches than the plot itself, m (module docstring).

    Parameters
    ----------
    d_az_deg : (M,) float
        Each plot cell's azimuth from its plot's bearing, deg (within +-180).
    sample : (M,) int
        Each cell's range sample.
    label : (M,) int
        Each cell's plot, 0..n-1.
    n : int
        Number of plots.
    bearing_deg : (n,) float
        Each plot's bearing, deg.
    plot_range_m : (n,) float
        Each plot's range, m.
    spacing_m : float
        Range sample spacing, m.
    spoke_deg : float
        Azimuth step between spokes, deg.
    gap_m : float
        Largest gap along a spoke between two plots of one echo, m.
    core : (M,) bool, optional
        The cells that measure how far a plot reaches (its core: within some dB of its strongest cell), so that a
        strong echo's sidelobe arc, joined to its plot, does not stretch the echo; None: every cell. Which plots
        are one echo is decided on all their cells.
    peak_power : (n,) float, optional
        Each plot's strongest cell's power (linear). Where given, only the plots within ``fragment_db`` of their
        echo's strongest measure how far the echo reaches: weaker pieces along its spokes are its range sidelobes
        and skirt (:data:`FRAGMENT_DB`), not more of the object.
    fragment_db : float
    joinable : (n,) bool, optional
        The plots that may be fragments (those the chart's land will not take: a buoy before a skerry is not a piece
        of the skerry's echo); the others are left out and get 0. None: all.

    Returns
    -------
    (n,) float
        Per plot, the larger of its echo's range extent less its own and its echo's cross-range extent less its own
        (at the plot's range), both over core cells, m; 0 for a plot that is its echo.
    """
    if n < 2:
        return np.zeros(n)
    az, rng = _extents(d_az_deg, sample, label, n, bearing_deg, spacing_m, spoke_deg)
    (centre, half), (r_low, r_high) = az, rng
    apart_deg = np.abs((centre[:, None] - centre[None, :] + 180.0) % 360.0 - 180.0)
    share_spokes = apart_deg < half[:, None] + half[None, :]
    range_gap_m = np.maximum(r_low[:, None] - r_high[None, :], r_low[None, :] - r_high[:, None])
    pair = share_spokes & (range_gap_m <= gap_m)
    if joinable is not None:
        pair &= joinable[:, None] & joinable[None, :]
    i, j = np.nonzero(np.triu(pair, 1))
    if i.size == 0:
        return np.zeros(n)
    _, echo = connected_components(coo_matrix((np.ones(i.size), (i, j)), shape=(n, n)), directed=False)
    if core is not None:
        (centre, half), (r_low, r_high) = _extents(d_az_deg[core], sample[core], label[core], n, bearing_deg,
                                                   spacing_m, spoke_deg)
    strong = np.ones(n, dtype=bool)
    if peak_power is not None:
        echo_peak = np.zeros(echo.max() + 1)
        np.maximum.at(echo_peak, echo, peak_power)
        strong = peak_power >= echo_peak[echo] * 10.0 ** (-fragment_db / 10.0)
    return _beyond_m(echo, strong, centre, half, r_low, r_high, plot_range_m)


def _beyond_m(echo: np.ndarray, strong: np.ndarray, centre: np.ndarray, half: np.ndarray, r_low: np.ndarray,
              r_high: np.ndarray, plot_range_m: np.ndarray) -> np.ndarray:
    """(n,) how much further each plot's echo reaches than the plot, m: the larger of the echo's range extent less the
    plot's and its azimuth extent less the plot's (at the plot's range), 0 at least. The echo's extents are those of
    its ``strong`` plots, in range over ``r_low``-``r_high`` (m) and in azimuth over ``centre`` +- ``half`` (deg)
    about its first plot's centre (no wrap at north); ``echo`` (n,) each plot's echo."""
    n = echo.size
    first = np.full(echo.max() + 1, n)
    np.minimum.at(first, echo, np.arange(n))
    rel = (centre - centre[first[echo]] + 180.0) % 360.0 - 180.0
    s = np.flatnonzero(strong)
    e_az_low, e_az_high = _span((rel - half)[s], (rel + half)[s], echo[s], first.size)
    e_r_low, e_r_high = _span(r_low[s], r_high[s], echo[s], first.size)
    beyond_range_m = (e_r_high - e_r_low)[echo] - (r_high - r_low)
    beyond_cross_m = np.radians((e_az_high - e_az_low)[echo] - 2.0 * half) * plot_range_m
    return np.maximum(np.maximum(beyond_range_m, beyond_cross_m), 0.0)


def _span(low: np.ndarray, high: np.ndarray, group: np.ndarray, m: int) -> tuple[np.ndarray, np.ndarray]:
    """(m,) smallest of ``low`` (K,) and (m,) largest of ``high`` (K,) per group 0..m-1 of ``group`` (K,)
    (+inf and -inf for a group without members)."""
    smallest, largest = np.full(m, np.inf), np.full(m, -np.inf)
    np.minimum.at(smallest, group, low)
    np.maximum.at(largest, group, high)
    return smallest, largest

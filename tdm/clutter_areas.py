"""Where the radar's false plots gather: a running map of plots that no track takes.

Sea clutter that passes the radar front end is not spread evenly: it gathers upwind and at short to
middle range, where the sea's spikes and wave groups rise over the clutter map (busy_open_sea seed 35,
sea state 4, wind from 90 deg: 0.4-1.0 plots a scan in each 200 m x 30 deg cell 60-120 deg and
200-1,200 m off, under 0.1 almost everywhere else). A tentative track there is more likely clutter
joined across scans than it is in a quiet cell, so it is asked for more evidence before it is
reported. Marine radars' automatic acquisition does the same with its acquisition and exclusion
areas (IMO MSC.192(79), 5.30: automatic acquisition "in areas of clutter" is to be limited), and
the track score of Blackman & Popoli (*Design and Analysis of Modern Tracking Systems*, 1999, 6.2)
weighs each hit by the local false-alarm density, of which this map is a coarse estimate.

The map is polar about the own ship (range bins x compass sectors: clutter follows the wind and the
range, not the chart) and counts, per radar scan, the plots that no track took (each object's first
plot, and clutter: an object's later plots go to its track, tentative or confirmed). Each cell keeps an exponential moving average of its counts per scan (``memory_scans``). A cell
is a clutter area when its average reaches ``plots_per_scan``, once the map has seen half its memory
(before, one scan's objects would make their own cells clutter areas: each object's first plots are
free, and on busy_open_sea every berg near another was reported 3 s later for it).
"""

from __future__ import annotations

import numpy as np

__all__ = ["ClutterAreas"]


class ClutterAreas:
    """Running polar map of free radar plots (module docstring).

    Parameters
    ----------
    range_m : float
        The radar's range, m (the map's extent).
    cell_range_m : float
        Depth of a cell, m.
    cell_deg : float
        Width of a cell, compass deg (a divisor of 360 or not: the last sector is narrower).
    memory_scans : float
        Scans over which counts are averaged (the moving average's time constant, in scans).
    plots_per_scan : float
        A cell holding at least this many free plots a scan on average is a clutter area.
    """

    def __init__(self, range_m: float, cell_range_m: float, cell_deg: float, memory_scans: float,
                 plots_per_scan: float):
        if not (cell_range_m > 0.0 and cell_deg > 0.0 and memory_scans >= 1.0 and plots_per_scan > 0.0):
            raise ValueError("clutter areas need positive cells, a memory of at least 1 scan and a positive rate")
        self.cell_range_m, self.cell_deg = float(cell_range_m), float(cell_deg)
        self.n_range = max(1, int(np.ceil(range_m / cell_range_m)))
        self.n_sector = int(np.ceil(360.0 / cell_deg))
        self.gain = 1.0 / float(memory_scans)
        self.plots_per_scan = float(plots_per_scan)
        self.rate = np.zeros((self.n_range, self.n_sector))
        self.scans = 0
        self.warm_scans = 0.5 * float(memory_scans)

    def _cells(self, own_m: np.ndarray, positions_m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(N,) range-bin and sector indices of positions (N, 2) ENU m seen from the own ship (2,) m;
        the range bin is n_range for positions beyond the map."""
        rel = np.asarray(positions_m, dtype=float).reshape(-1, 2) - np.asarray(own_m, dtype=float)[:2]
        bins = np.minimum((np.hypot(rel[:, 0], rel[:, 1]) / self.cell_range_m).astype(np.int64), self.n_range)
        compass = np.degrees(np.arctan2(rel[:, 0], rel[:, 1])) % 360.0
        sectors = np.minimum((compass / self.cell_deg).astype(np.int64), self.n_sector - 1)
        return bins, sectors

    def update(self, own_m: np.ndarray, free_positions_m: np.ndarray) -> None:
        """Take one scan's free plots (N, 2) ENU m, seen from the own ship at ``own_m`` (2,) m."""
        counts = np.zeros_like(self.rate)
        bins, sectors = self._cells(own_m, free_positions_m)
        inside = bins < self.n_range
        np.add.at(counts, (bins[inside], sectors[inside]), 1.0)
        self.rate += self.gain * (counts - self.rate)
        self.scans += 1

    def cluttered(self, own_m: np.ndarray, positions_m: np.ndarray) -> np.ndarray:
        """(N,) bool: positions (N, 2) ENU m in a clutter area, seen from the own ship at ``own_m`` (2,) m
        (none while the map has seen fewer than half its memory in scans)."""
        bins, sectors = self._cells(own_m, positions_m)
        inside = bins < self.n_range
        out = np.zeros(bins.shape, dtype=bool)
        if self.scans < self.warm_scans:  # too few scans to tell clutter from the objects' first plots
            return out
        out[inside] = self.rate[bins[inside], sectors[inside]] >= self.plots_per_scan
        return out

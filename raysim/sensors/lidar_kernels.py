"""Compiled kernels of the LiDAR renderer (:mod:`raysim.jit`), each beside the numpy code it replaces.

:func:`world_rays` is :meth:`raysim.sensors.lidar.LidarRenderer._world_rays` for one ray per
beam, with :func:`groundfloor.hdl32e.beam_directions` folded in: a firing's beam from the
encoder-step tables, then the own-ship's affine map at the cycle start plus its change over
the cycle times the firing's fraction of it, in the numpy path's order of operations.
"""

from __future__ import annotations

import numpy as np

from raysim.jit import kernel


@kernel
def _world_rays(firing_az, cos_el, sin_el, cos_az, sin_az, z_offset_m, a0, da, frac, origins_out, directions_out):
    n_cycles, n_lasers = firing_az.shape
    for c in range(n_cycles):
        for j in range(n_lasers):
            step = firing_az[c, j]
            d0 = cos_el[j] * cos_az[step]
            d1 = -cos_el[j] * sin_az[step]
            d2 = sin_el[j]
            z = z_offset_m[j]
            f = frac[j]
            for i in range(3):
                start = d0 * a0[c, 0, i] + d1 * a0[c, 1, i] + d2 * a0[c, 2, i]
                change = d0 * da[c, 0, i] + d1 * da[c, 1, i] + d2 * da[c, 2, i]
                directions_out[c, j, i] = start + change * f
                start = z * a0[c, 2, i] + a0[c, 3, i]
                change = z * da[c, 2, i] + da[c, 3, i]
                origins_out[c, j, i] = start + change * f


def world_rays(firing_az: np.ndarray, cos_el: np.ndarray, sin_el: np.ndarray, cos_az: np.ndarray,
               sin_az: np.ndarray, z_offset_m: np.ndarray, a0: np.ndarray, da: np.ndarray,
               frac: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """World rays of C firing cycles of one ray per beam, in one pass.

    Parameters
    ----------
    firing_az : (C, L) uint16
        Encoder step (0.01 deg) of each firing, L lasers.
    cos_el, sin_el, z_offset_m : (L,) float64
        Each laser's elevation cosine and sine and its beam origin's height in the sensor frame, m.
    cos_az, sin_az : (36000,) float64
        Cosine and sine of each encoder step.
    a0, da : (C, 4, 3) float64
        The sensor -> world affine map at each cycle start (rows: R^T, then the origin in m) and its
        change over the cycle.
    frac : (L,) float64
        Each firing's fraction of the cycle.

    Returns
    -------
    origins_m, directions : (C, L, 3) float64
        Ray origins in the world, m, and unit directions (to the map's interpolation).
    """
    shape = firing_az.shape + (3,)
    origins, directions = np.empty(shape), np.empty(shape)
    _world_rays(np.ascontiguousarray(firing_az), cos_el, sin_el, cos_az, sin_az, z_offset_m,
                np.ascontiguousarray(a0), np.ascontiguousarray(da), frac, origins, directions)
    return origins, directions


__all__ = ["world_rays"]

"""The sea surface seen by the sensors: whitecap (foam) coverage and its moving patches.

Calm water is a specular mirror at 905 nm (Fresnel reflectance about 2 %): a
mast-mounted LiDAR at grazing angles gets nothing back from it. Foam on breaking
crests is a diffuse reflector and does return points (docs/reference.md section 2,
VRX issues 29/135). raysim models the fraction of the sea covered by whitecaps
from the wind with Monahan & O'Muircheartaigh (1980),
``W = 3.84e-6 U10^3.41`` (U10 in m/s, W a fraction), using the larger of the
configured wind and the wind typical of the configured Douglas sea state, and
lays the foam out as patches: a smooth random field of plane waves travelling at
deep-water phase speed ``sqrt(g / k)``, thresholded so that the covered fraction
is W. Patches are a few metres to tens of metres across and drift with the waves.
"""

from __future__ import annotations

import numpy as np
from scipy.special import ndtri

#: Douglas sea state -> significant wave height upper bound, m (WMO sea state code 3700).
DOUGLAS_WAVE_HEIGHT_M = (0.0, 0.1, 0.5, 1.25, 2.5, 4.0, 6.0)
#: Wind speed typical of each Douglas sea state 0..6, m/s (Beaufort-Douglas correspondence,
#: mid-band values; unverified engineering table).
SEA_STATE_WIND_MPS = (0.0, 2.0, 4.5, 7.0, 9.5, 12.5, 16.0)
GRAVITY_MPS2 = 9.81
N_WAVES = 8
#: Wavelengths of the foam pattern, m (patch sizes; unverified).
FOAM_WAVELENGTH_RANGE_M = (4.0, 40.0)


def whitecap_fraction(wind_speed_mps: float) -> float:
    """Monahan & O'Muircheartaigh (1980): fraction of the sea covered by whitecaps."""
    return float(min(1.0, 3.84e-6 * max(wind_speed_mps, 0.0) ** 3.41))


class FoamField:
    """Where the sea carries foam, for any points and times.

    Parameters
    ----------
    wind_speed_mps : float
        Configured wind speed.
    sea_state : int
        Douglas sea state 0..6.
    wind_from_deg : float
        Compass direction the wind blows from: the patches travel downwind.
    rng : numpy.random.Generator
        The world's ``sea.foam`` stream (wave directions, lengths and phases).
    """

    def __init__(self, wind_speed_mps: float, sea_state: int, wind_from_deg: float, rng: np.random.Generator):
        self.effective_wind_mps = max(float(wind_speed_mps), SEA_STATE_WIND_MPS[int(sea_state)])
        self.coverage = whitecap_fraction(self.effective_wind_mps)
        downwind = np.radians(90.0 - (wind_from_deg + 180.0))  # ENU angle the waves travel to
        spread = rng.uniform(-np.pi / 3, np.pi / 3, N_WAVES)
        wavelength = np.exp(rng.uniform(*np.log(FOAM_WAVELENGTH_RANGE_M), N_WAVES))
        k = 2 * np.pi / wavelength
        self.kx = k * np.cos(downwind + spread)
        self.ky = k * np.sin(downwind + spread)
        self.omega = np.sqrt(GRAVITY_MPS2 * k)
        self.phase = rng.uniform(0.0, 2 * np.pi, N_WAVES)
        # sum of N cosines with random phases / sqrt(N/2) is close to standard normal
        self.threshold = float(ndtri(1.0 - self.coverage)) if 0.0 < self.coverage < 1.0 else (np.inf if self.coverage <= 0 else -np.inf)

    def is_foam(self, x_m: np.ndarray, y_m: np.ndarray, t_s: np.ndarray) -> np.ndarray:
        """Whether the sea carries foam at points of it at given times.

        Parameters
        ----------
        x_m, y_m : (N,) float
            East and north positions on the sea, metres.
        t_s : (N,) float
            Times, seconds since scenario start.

        Returns
        -------
        (N,) bool
        """
        if self.coverage <= 0.0 or x_m.shape[0] == 0:
            return np.zeros(np.shape(x_m), dtype=bool)
        # float32 about a reference point and time (folded into the phases in float64) keeps the
        # phase error below 1e-4 rad while halving the cost of the cosines
        x0, y0, t0 = float(x_m[0]), float(y_m[0]), float(t_s[0])
        phase = np.mod(self.phase + self.kx * x0 + self.ky * y0 - self.omega * t0, 2 * np.pi).astype(np.float32)
        local = np.empty((x_m.shape[0], 3), dtype=np.float32)
        np.subtract(x_m, x0, out=local[:, 0], casting="same_kind")  # in the inputs' precision, then rounded
        np.subtract(y_m, y0, out=local[:, 1], casting="same_kind")
        np.subtract(t_s, t0, out=local[:, 2], casting="same_kind")
        waves = np.stack([self.kx, self.ky, -self.omega]).astype(np.float32)  # (3, N_WAVES)
        arg = local @ waves
        add_to_rows(arg, phase)
        field = sum_rows(np.cos(arg, out=arg))
        field /= np.float32(np.sqrt(N_WAVES / 2.0))
        return field > self.threshold


#: Rows of a (N, W) array added to at once by :func:`add_to_rows` (long inner loops).
_ROWS_AT_ONCE = 32


def add_to_rows(a: np.ndarray, row: np.ndarray) -> None:
    """``a += row`` for a C-contiguous (N, W) array, the same sums, over rows of ``_ROWS_AT_ONCE * W`` values.

    Broadcasting a short row steps W values at a time; the tiled row makes the inner loop long.

    Parameters
    ----------
    a : (N, W) float32, C-contiguous
        Added to in place.
    row : (W,) float32
    """
    m = a.shape[0] // _ROWS_AT_ONCE * _ROWS_AT_ONCE
    if m and a.flags.c_contiguous:
        block = a[:m].reshape(-1, _ROWS_AT_ONCE * a.shape[1])
        block += np.tile(row, _ROWS_AT_ONCE)
        a[m:] += row
    else:
        a += row


def sum_rows(a: np.ndarray) -> np.ndarray:
    """``a.sum(axis=1)`` of a (N, 8) float32 array, the same values, by seven column additions.

    NumPy sums a contiguous row of 8 values pairwise with 8 partial sums:
    ``((a0 + a1) + (a2 + a3)) + ((a4 + a5) + (a6 + a7))`` (``pairwise_sum`` in its
    ``loops_utils.h``); the columns added in that order give the same values (up to
    the sign of a zero sum), without a reduction per row. Other widths: ``a.sum(axis=1)``.

    Parameters
    ----------
    a : (N, W) float32

    Returns
    -------
    (N,) float32
    """
    if a.ndim != 2 or a.shape[1] != 8:
        return a.sum(axis=1)
    c = [a[:, k] for k in range(8)]
    left = np.add(c[0], c[1])
    left += np.add(c[2], c[3])
    right = np.add(c[4], c[5])
    right += np.add(c[6], c[7])
    left += right
    return left

"""Sea-clutter texture fixed to the sea surface: correlated in space and time, moving with the waves.

The compound K model (REF 3.8) writes clutter intensity as texture x speckle. The texture is the
local power of the sea's scatterers (wave fronts, breaking crests): it belongs to the sea, not to
the radar. Here it is a stationary Gaussian random field on a periodic world-fixed tile:

- space: Gaussian correlation, LONGER ALONG THE WAVE CRESTS (across the wind) than along the wind, so the
  bright patches and spikes lie along the wave fronts as on a marine radar's picture of the sea (Young,
  Rosenthal & Ziemer 1985, JGR 90(C1) 1049: the image's spectrum is the waves' spectrum, crests across the
  wind). The lengths are REF 3.8's two values, ``b = (pi/2) W^2 / g`` and ``2 b``, with W the sea state's wind
  (REF 3.8 table): ``b`` along the wind, a quarter of the wavelength ``2 pi W^2 / g`` of waves whose phase speed
  is W (crest to mid-slope), and ``2 b`` (half that wavelength) along the crests. NOTE: REF 3.8 writes the range
  correlation as ``b sqrt(3 cos^2(A) + 1)`` with A the look direction to the wind, i.e. the longer length
  looking along the wind; here the longer length is given to the crests, the deliberate deviation issue 19 asks
  for (spikes aligned with the wave fronts; engineering choice, unverified against measured range correlation);
- motion: the tile drifts downwind at W, the phase speed of waves of that correlation length
  (``c = sqrt(g L / (2 pi))`` with ``L = 2 pi W^2 / g`` gives ``c = W``);
- time: key frames ``T = 2 pi W / g`` apart (the period of those waves; "correlated over
  seconds", REF 3.8; engineering choice, unverified), blended as ``cos(pi u/2) F_k + sin(pi u/2) F_k+1``
  so the field keeps unit variance and decorrelates over one key interval.

Each key frame comes from its own named random stream (``radar.texture.<k>``), so any
revolution renders the same without the ones before it.
"""

from __future__ import annotations

import math

import numpy as np
import scipy.fft

from raysim.random_streams import stream
from raysim.sensors import radar_physics as phys

__all__ = ["SeaTexture"]

#: Highest Douglas sea state of the REF 3.8 wind table.
MAX_SEA_STATE = 6
#: Correlation length along the wave crests (across the wind) over that along the wind: REF 3.8's
#: ``sqrt(3 cos^2 A + 1)`` at A = 0 over A = 90 deg, given to the crests (module docstring).
CREST_OVER_WIND = 2.0
#: Tile cells per along-wind (shortest) correlation length.
CELLS_PER_LENGTH = 2.0
#: Key frames kept in memory (a revolution needs two; the oldest goes first).
KEY_FRAMES_KEPT = 4


class SeaTexture:
    """Unit-variance Gaussian sea texture at world points and times.

    Parameters
    ----------
    seed : int
        The scenario seed.
    sea_state : int
        Douglas sea state 0..6 (sets the wind W of the correlation length, drift and key interval).
    wind_from_deg : float
        Direction the wind comes from, degrees clockwise from north; waves travel the other way.
    tile_cells : int
        Tile size in cells each way (a power of two; the tile repeats beyond it).
    """

    def __init__(self, seed: int, sea_state: int, wind_from_deg: float, tile_cells: int = 1024):
        w = phys.TEXTURE_WIND_MPS[int(np.clip(sea_state, 0, MAX_SEA_STATE))]
        base = (math.pi / 2.0) * w * w / phys.G_MPS2
        # along the wind (the waves' travel) b, along the crests (across the wind) 2 b
        self.length_along_m, self.length_across_m = base, CREST_OVER_WIND * base
        self.cell_m = self.length_along_m / CELLS_PER_LENGTH
        self.n = int(tile_cells)
        if self.n & (self.n - 1):
            raise ValueError(f"tile_cells must be a power of two, got {tile_cells}")
        self.seed = int(seed)
        to_rad = math.radians(wind_from_deg + 180.0)  # direction the waves travel, clockwise from north
        self.down_wind = np.array([math.sin(to_rad), math.cos(to_rad)])  # east, north
        self.drift_mps = w
        self.key_s = 2.0 * math.pi * w / phys.G_MPS2
        # spectral filter: Gaussian correlation exp(-d^2 / (2 L^2)) has the power spectrum of a Gaussian
        # kernel of standard deviation L / sqrt(2) in each principal direction
        f = np.fft.fftfreq(self.n, d=self.cell_m)
        fx, fy = np.meshgrid(f, np.fft.rfftfreq(self.n, d=self.cell_m), indexing="ij")
        along = fx * self.down_wind[0] + fy * self.down_wind[1]
        across = -fx * self.down_wind[1] + fy * self.down_wind[0]
        sa, sc = self.length_along_m / math.sqrt(2.0), self.length_across_m / math.sqrt(2.0)
        self._transfer = np.exp(-2.0 * math.pi**2 * ((along * sa) ** 2 + (across * sc) ** 2)).astype(np.float32)
        self._keys: dict[int, np.ndarray] = {}

    def _key(self, k: int) -> np.ndarray:
        if k not in self._keys:
            if len(self._keys) >= KEY_FRAMES_KEPT:
                self._keys.pop(min(self._keys))
            white = stream(self.seed, f"radar.texture.{k}").standard_normal((self.n, self.n), dtype=np.float32)
            spectrum = scipy.fft.rfft2(white)  # complex64
            spectrum *= self._transfer
            field = scipy.fft.irfft2(spectrum, s=(self.n, self.n), overwrite_x=True)  # float32
            field /= field.std()
            self._keys[k] = field.reshape(-1)
        return self._keys[k]

    def sample(self, east_m: np.ndarray, north_m: np.ndarray, time_s: float) -> np.ndarray:
        """Texture (standard normal, correlated) at world points, one time for all of them.

        Parameters
        ----------
        east_m, north_m : (...) float
            Local ENU position of the sea cells, m.
        time_s : float
            Scenario time (one per revolution: the texture changes over seconds, a revolution lasts 2.5 s).

        Returns
        -------
        (...) float32
        """
        u = time_s / self.key_s
        k = int(math.floor(u))
        frac = u - k
        shift = self.drift_mps * time_s * self.down_wind
        mask = self.n - 1  # the tile repeats: index modulo n (a power of two) by masking
        flat = self._cell_index(east_m, shift[0], mask)
        flat *= self.n
        flat += self._cell_index(north_m, shift[1], mask)
        a = self._key(k).take(flat)
        b = self._key(k + 1).take(flat)
        a *= math.cos(0.5 * math.pi * frac)  # float32 (a Python float scalar keeps the array's precision)
        b *= math.sin(0.5 * math.pi * frac)
        a += b
        return a

    def _cell_index(self, coordinate_m: np.ndarray, shift_m: np.float64, mask: int) -> np.ndarray:
        """(...) int64 tile cell of each coordinate along one axis: ``floor((x - shift) / cell) & mask``, in float64.

        Parameters
        ----------
        coordinate_m : (...) float
            East or north of each point, m.
        shift_m : numpy.float64
            The tile's drift along that axis, m (a float64 scalar: the difference is formed in float64).
        mask : int
            ``n - 1``: the index modulo the tile size.
        """
        x = np.subtract(coordinate_m, shift_m, dtype=np.float64)
        x *= 1.0 / self.cell_m
        np.floor(x, out=x)
        index = x.astype(np.int64)
        index &= mask
        return index

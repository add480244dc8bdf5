"""The marine radar's antenna pattern: a slotted-waveguide linear array and its vertical aperture.

Horizontal (azimuth) pattern, one way, as a complex field with ``g_h(0) = 1``:

    g_h(theta) = [AF(theta) E(theta) + j max(c E(theta), b)] / (1 + j c)
    AF(theta)  = sum_m w_m cos(k d x_m sin theta) / sum_m w_m,   x_m = m - (M - 1) / 2

- ``w_m``: Taylor n-bar amplitude taper (T. T. Taylor, "Design of line-source antennas for
  narrow beamwidth and low side lobes", IRE Trans. Antennas Propag. AP-3(1), 16-28, 1955;
  ``scipy.signal.windows.taylor``), n-bar = :data:`TAYLOR_NBAR`.
- ``M`` elements (slots) at spacing ``d``: ``M`` is the count nearest an aperture of the
  Taylor-broadened width at :data:`ELEMENT_SPACING_WL` wavelengths spacing, then ``d`` is solved
  so that the realised -3 dB width (fill included) is the configured one. Array factor and
  pattern multiplication: C. A. Balanis, "Antenna Theory: Analysis and Design", 3rd ed., Wiley
  2005, ch. 6.
- ``c``: the diffuse field of the array's random element errors. J. Ruze ("Antenna tolerance
  theory -- a review", Proc. IEEE 54(4), 633-640, 1966): uncorrelated amplitude/phase errors of
  variance ``s^2`` add, on average over the ensemble of antennas, ``s^2 / (eta M)`` of the peak
  power at every angle (times the element pattern), ``eta`` the taper efficiency. ``c^2`` is
  that floor, put in quadrature with the (real) array factor so that ``|g_h|^2`` equals Ruze's
  mean pattern ``|AF|^2 + c^2`` (times ``E^2``) at every angle. It fills the nulls: a strong
  target's sidelobe arc is continuous, as on real sets. The floor is
  :data:`FLOOR_BELOW_SIDELOBE_DB` under the configured sidelobe level and the Taylor design
  level is set so that design plus floor is the configured near-in level (an antenna built to a
  sidelobe figure is built to a tolerance whose floor sits a few dB under it; modelling choice,
  unverified). At the defaults the floor is -28 dB: ``s`` about 0.15 (for example 11 % amplitude
  and 6 deg phase rms) for the 17 slots. The mean pattern, not one random unit: a single unit's
  pattern keeps nulls of random depth at random angles, so the seed does not enter.
- ``E(theta) = max(cos^q theta, b)`` in front, ``b`` behind (|theta| > 90 deg): the slot's own
  pattern over the array's finite ground plane, ``q`` = :data:`ELEMENT_COS_POWER`. Behind, the
  array factor repeats its front (``sin theta`` is symmetric about 90 deg): a back lobe ``b AF``,
  -35 dB at 180 deg with the diffuse ``b`` beside it. The diffuse field never falls below ``b`` either (spill-over and scattering by the
  pedestal and radome), so from about 60 deg round to the back the pattern sits near ``b``.
  ``b`` is :data:`BACK_LOBE_DB` (-38 dB), or 10 dB under the Ruze floor if that is lower
  (engineering defaults, unverified).

A typical marine open-array sheet gives "sidelobes -23 dB within +-10 deg, -30 dB outside"
(typical figure, not verified for the Broadband 4G dome). At the defaults this pattern has
-25 dB near-in sidelobes, -25..-30 dB from 10 to 30 deg (a few dB over that envelope), about
-31 dB at 40 deg, -35 dB at 60 deg, and -38 dB from 65 deg round to the back (-35 dB at 180).

Vertical pattern, one way, real: a cosine-tapered aperture of height ``h`` (Balanis, 3rd ed.,
table 7.2: ``f(psi) = cos(psi) / (1 - (2 psi / pi)^2)``, ``psi = (pi h / lambda) sin el``, first
sidelobe -23 dB), ``h`` set so that the -3 dB width is the configured one.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq
from scipy.signal.windows import taylor


C_MPS = 299_792_458.0
TAYLOR_NBAR = 4  # near-in sidelobes held near the design level (Taylor 1955)
ELEMENT_SPACING_WL = 0.7  # slot spacing, wavelengths (about lambda_g / 2 of X-band guide)
FLOOR_BELOW_SIDELOBE_DB = 3.0  # Ruze floor below the configured near-in sidelobe level, dB
ELEMENT_COS_POWER = 1.5  # element factor cos^q theta
BACK_LOBE_DB = -38.0  # one-way back-lobe / scattering level, dB (at most; see the module doc)
BACK_BELOW_FLOOR_DB = 10.0  # the back level is at least this far under the Ruze floor, dB
MIN_ELEMENTS = 4
_HALF_POWER = 1.0 / math.sqrt(2.0)


def _cosine_aperture(psi: np.ndarray) -> np.ndarray:
    """Field of a cosine-tapered line source, peak 1 at ``psi = 0`` (Balanis table 7.2).

    Parameters
    ----------
    psi : ndarray, any shape
        ``(pi h / lambda) sin(angle)``, rad.

    Returns
    -------
    ndarray, same shape, float64
        ``cos(psi) / (1 - (2 psi / pi)^2)``; the removable singularity at ``|psi| = pi / 2``
        takes its limit ``pi / 4``.
    """
    psi = np.asarray(psi, dtype=np.float64)
    den = 1.0 - (2.0 * psi / math.pi) ** 2
    near = np.abs(den) < 1e-9
    return np.where(near, math.pi / 4.0, np.cos(psi) / np.where(near, 1.0, den))


def _wrap_deg(theta_deg) -> np.ndarray:
    """Angles wrapped to [-180, 180) deg, float64."""
    t = np.asarray(theta_deg, dtype=np.float64)
    return (t + 180.0) % 360.0 - 180.0


class AntennaPattern:
    """Horizontal and vertical one-way field patterns of the radar antenna (see module doc).

    Parameters
    ----------
    beam_az_deg : float
        Horizontal -3 dB width (one way), deg.
    beam_el_deg : float
        Vertical -3 dB width (one way), deg.
    sidelobe_db : float
        One-way near-in sidelobe level (negative), dB re. the peak.
    seed : int
        Scenario seed. Unused: the pattern is Ruze's ensemble mean (see the module doc), the
        same for every seed; kept so that a per-unit realisation can draw from
        ``stream(seed, "radar.antenna")`` without changing the call.
    f_ghz : float
        Carrier frequency, GHz (sets the aperture size in metres; the pattern in angle depends
        only on the widths and sidelobe level).
    """

    def __init__(self, beam_az_deg: float = 5.2, beam_el_deg: float = 25.0, sidelobe_db: float = -25.0,
                 seed: int = 0, f_ghz: float = 9.41):
        self.beam_az_deg = float(beam_az_deg)
        self.beam_el_deg = float(beam_el_deg)
        self.sidelobe_db = float(sidelobe_db)
        self.wavelength_m = C_MPS / (f_ghz * 1e9)
        floor_db = self.sidelobe_db - FLOOR_BELOW_SIDELOBE_DB
        self.floor_db = floor_db
        # Taylor design level so that design (+) floor = the configured level, in power
        design_lin = 10.0 ** (self.sidelobe_db / 10.0) - 10.0 ** (floor_db / 10.0)
        self.design_sll_db = -10.0 * math.log10(design_lin)
        self.n_elements = self._element_count()
        m = self.n_elements
        self.x_m = np.arange(m, dtype=np.float64) - 0.5 * (m - 1)
        taper = taylor(m, nbar=min(TAYLOR_NBAR, max(m // 2, 1)), sll=self.design_sll_db, norm=False)
        self.seed = int(seed)  # the pattern is Ruze's ensemble mean: no random draw
        self.weights = taper / np.sum(taper)
        self._fill = 10.0 ** (floor_db / 20.0)
        self.back_db = min(BACK_LOBE_DB, floor_db - BACK_BELOW_FLOOR_DB)
        self._back = 10.0 ** (self.back_db / 20.0)
        self.spacing_m = self._solve_spacing()
        self._psi3_scale = self._vertical_scale()

    # ---------------------------------------------------------------- horizontal

    def _element_count(self) -> int:
        """Slots in an aperture of the Taylor-broadened width at :data:`ELEMENT_SPACING_WL` spacing.

        The width ``0.886 lambda / L`` of the uniform aperture (Balanis table 7.2) broadened by a
        rough linear fit in the design level (1.13 at 25 dB): it only picks ``M``; ``d`` is then
        solved for the exact width.
        """
        broadening = 0.886 * (1.0 + 0.0167 * max(self.design_sll_db - 13.26, 0.0))
        self._length_wl = broadening / math.radians(self.beam_az_deg)
        return max(MIN_ELEMENTS, int(round(self._length_wl / ELEMENT_SPACING_WL)))

    def _field(self, theta_deg: np.ndarray, kd: float) -> np.ndarray:
        """Un-normalised field ``AF E + j max(c E, b)``.

        Parameters
        ----------
        theta_deg : ndarray, shape (n,)
            Azimuth off boresight, deg, in [-180, 180).
        kd : float
            ``k d``, rad.

        Returns
        -------
        ndarray, shape (n,), complex128
        """
        rad = np.radians(theta_deg)
        # symmetric real taper: AF = sum w cos(kd x sin) = 1 - 2 sum w sin^2(kd x sin / 2) (exactly 1 at 0)
        af = 1.0 - 2.0 * (np.sin(np.multiply.outer(0.5 * kd * np.sin(rad), self.x_m)) ** 2 @ self.weights)
        back = self._back
        elem = np.where(np.abs(theta_deg) <= 90.0,
                        np.maximum(np.abs(np.cos(rad)) ** ELEMENT_COS_POWER, back), back)
        return af * elem + 1j * np.maximum(self._fill * elem, back)

    def _width_deg(self, kd: float) -> float:
        """Realised -3 dB width (left to right crossing) of the horizontal pattern for ``kd``, deg."""
        peak = abs(1.0 + 1j * self._fill)

        def excess(t: float) -> float:
            return float(np.abs(self._field(np.array([t]), kd))[0]) / peak - _HALF_POWER

        hi = 3.0 * self.beam_az_deg
        right = brentq(excess, 1e-6, min(hi, 89.0), xtol=1e-9)
        left = brentq(excess, -min(hi, 89.0), -1e-6, xtol=1e-9)
        return right - left

    def _solve_spacing(self) -> float:
        """Element spacing (m) giving the configured -3 dB width."""
        kd_guess = 2.0 * math.pi * self._length_wl / self.n_elements
        lo, hi = 0.6 * kd_guess, 1.6 * kd_guess
        kd = brentq(lambda v: self._width_deg(v) - self.beam_az_deg, lo, hi, xtol=1e-10)
        self._kd = kd
        return kd * self.wavelength_m / (2.0 * math.pi)

    def horizontal_voltage(self, theta_deg: np.ndarray) -> np.ndarray:
        """One-way horizontal field pattern, complex, ``g_h(0) = 1``.

        Parameters
        ----------
        theta_deg : array_like, any shape
            Azimuth off boresight, deg, any value (wrapped to [-180, 180)).

        Returns
        -------
        ndarray, same shape, complex128
        """
        t = _wrap_deg(theta_deg)
        flat = self._field(t.ravel(), self._kd) / (1.0 + 1j * self._fill)
        return flat.reshape(t.shape).astype(np.complex128)

    def two_way_power_db(self, theta_deg) -> np.ndarray:
        """Two-way power pattern ``40 log10 |g_h|``, dB (0 at boresight); same shape as the input."""
        g = np.abs(self.horizontal_voltage(theta_deg))
        with np.errstate(divide="ignore"):
            return 40.0 * np.log10(g)

    def spoke_kernel(self, spokes: int) -> np.ndarray:
        """Two-way field ``g_h(theta)^2`` at circular spoke offsets, for convolution over spokes.

        Parameters
        ----------
        spokes : int
            Spokes per revolution ``S``.

        Returns
        -------
        ndarray, shape (S,), complex128
            Element ``j`` is at offset ``theta = j 360 / S`` deg (``j > S/2`` is ``(j - S) 360 / S``).
        """
        offsets_deg = np.arange(int(spokes), dtype=np.float64) * (360.0 / int(spokes))
        g = self.horizontal_voltage(offsets_deg)
        return g * g

    # ---------------------------------------------------------------- vertical

    def _vertical_scale(self) -> float:
        """``pi h / lambda`` so that the cosine aperture's -3 dB width is ``beam_el_deg``."""
        psi3 = brentq(lambda p: float(_cosine_aperture(np.array(p))) - _HALF_POWER, 1e-6, 3.0)
        return psi3 / math.sin(math.radians(0.5 * self.beam_el_deg))

    @property
    def aperture_height_m(self) -> float:
        """Height of the vertical aperture, m."""
        return self._psi3_scale * self.wavelength_m / math.pi

    @property
    def aperture_length_m(self) -> float:
        """Length of the horizontal array (``M d``), m."""
        return self.n_elements * self.spacing_m

    def vertical_voltage(self, el_deg: np.ndarray) -> np.ndarray:
        """One-way vertical field pattern, real, peak 1 at 0 deg.

        Parameters
        ----------
        el_deg : array_like, any shape
            Elevation off the antenna's horizontal plane, deg.

        Returns
        -------
        ndarray, same shape, float64 (negative in the odd sidelobes)
        """
        el = np.asarray(el_deg, dtype=np.float64)
        return _cosine_aperture(self._psi3_scale * np.sin(np.radians(el)))

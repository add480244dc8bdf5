"""Marine X-band radar physics: pure, vectorised functions (no rendering, no I/O).

Every figure comes from docs/reference.md section 3 (cited by item number as
"REF 3.n") unless marked "(unverified)": those are engineering defaults, kept as named
parameters so that a measured value can replace them.

Units: powers are linear unless the name ends in ``_db``; angles in degrees where the
name says ``_deg``, radians otherwise; ranges in metres.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.special import gammaincinv, i0e, ndtr

from raysim.sea import DOUGLAS_WAVE_HEIGHT_M

# ------------------------------------------------------------------ constants

C_MPS = 299_792_458.0  # speed of light
FREQUENCY_GHZ = 9.41  # X band, REF 3 table (lambda = 3.19 cm)
EARTH_RADIUS_M = 6_371_000.0  # mean earth radius
EFFECTIVE_EARTH_FACTOR = 4.0 / 3.0  # standard refraction, REF 3.4 (re = 8495 km)
EFFECTIVE_EARTH_RADIUS_M = EFFECTIVE_EARTH_FACTOR * EARTH_RADIUS_M
KT0_DBM_PER_HZ = -174.0  # thermal noise density at 290 K, REF 3.1
G_MPS2 = 9.81  # gravity, for the clutter texture correlation length (REF 3.8)

# Radar equation example values, REF 3.1 (a Broadband 3G/4G class FMCW radar)
PT_W = 0.1  # transmit power
ANTENNA_GAIN_DBI = 23.0  # one way
SWEEP_S = 1e-3  # coherent FMCW sweep per spoke
NOISE_FIGURE_DB = 5.0
LOSSES_DB = 6.0

# Antenna, REF 3 table / 3.2 (unverified for the 18 in dome)
BEAM_AZ_DEG = 5.2  # -3 dB horizontal width
BEAM_EL_DEG = 25.0  # -3 dB vertical width
RANGE_RESOLUTION_M = 2.5  # c/(2B), REF 3 table / 3.3 ("about 2-3 m")

# NRL sea clutter coefficients (Gregers-Hansen & Mital 2012; REF 3.7): c1..c5
NRL_COEFFS = {
    "HH": (-73.0, 20.781, 7.351, 25.65, 0.0054),
    "VV": (-50.796, 25.93, 0.7093, 21.588, 0.00211),
}
# Ward et al. K-distribution shape (REF 3.8): polarisation constant and clamp
WARD_K_POL = {"VV": 1.39, "HH": 2.09}
NU_MIN, NU_MAX = 0.1, 20.0  # REF 3.8 "clamp nu to about [0.1, 20]"
# Wind speed W per Douglas sea state 0..6 for the texture correlation length (REF 3.8 gives SS1..6;
# SS0 takes the SS1 value, an assumption)
TEXTURE_WIND_MPS = (2.5, 2.5, 4.5, 6.0, 8.5, 11.0, 14.0)

# Rain, REF 3.9 (ITU-R P.838 at 9.41 GHz, one way; Marshall-Palmer Z-R)
RAIN_RATE_TABLE_MM_PER_H = np.array([1.0, 4.0, 16.0, 50.0])
RAIN_ATTENUATION_TABLE_DB_PER_KM = np.array([0.0093, 0.056, 0.33, 1.44])
WATER_K2 = 0.93  # |K|^2 of water
Z_R_A, Z_R_B = 200.0, 1.6  # Z = a R^b, mm^6/m^3


def wavelength_m(f_ghz: float = FREQUENCY_GHZ) -> float:
    """Wavelength, m."""
    return C_MPS / (f_ghz * 1e9)


def db(x):
    """10 log10 of a power ratio (-inf for 0)."""
    with np.errstate(divide="ignore"):
        return 10.0 * np.log10(x)


def undb(x_db):
    """Power ratio of a dB value."""
    return np.power(10.0, np.asarray(x_db, dtype=float) / 10.0)


# ------------------------------------------------------------------ geometry (REF 3.4)


def horizon_m(height_m, re_m: float = EFFECTIVE_EARTH_RADIUS_M):
    """Distance to the radar horizon of a point at ``height_m``: sqrt(2 re h)."""
    return np.sqrt(2.0 * re_m * np.maximum(np.asarray(height_m, dtype=float), 0.0))


def grazing_angle_deg(height_m, range_m, re_m: float = EFFECTIVE_EARTH_RADIUS_M):
    """Grazing angle at the sea at slant range ``range_m`` seen from ``height_m`` (4/3 earth).

    ``psi = asin(h/r + h^2/(2 re r) - r/(2 re))``; NaN beyond the horizon (argument <= 0);
    90 deg inside the antenna height.
    """
    h = np.asarray(height_m, dtype=float)
    r = np.maximum(np.asarray(range_m, dtype=float), 1e-6)
    arg = h / r + h * h / (2.0 * re_m * r) - r / (2.0 * re_m)
    psi = np.degrees(np.arcsin(np.clip(arg, -1.0, 1.0)))
    return np.where(arg > 0.0, psi, np.nan)


def hidden_height_m(distance_m, antenna_height_m, re_m: float = EFFECTIVE_EARTH_RADIUS_M):
    """Height below which a point at horizontal ``distance_m`` is below the radar horizon.

    ``(d - sqrt(2 re ha))^2 / (2 re)`` beyond the antenna's horizon, 0 before it (REF 3.4).
    """
    beyond = np.maximum(np.asarray(distance_m, dtype=float) - horizon_m(antenna_height_m, re_m), 0.0)
    return beyond * beyond / (2.0 * re_m)


# ------------------------------------------------------------------ radar equation (REF 3.1)


def snr(sigma_m2, range_m, pt_w: float = PT_W, gain_dbi: float = ANTENNA_GAIN_DBI, f_ghz: float = FREQUENCY_GHZ,
        sweep_s: float = SWEEP_S, noise_figure_db: float = NOISE_FIGURE_DB, losses_db: float = LOSSES_DB,
        kt0_dbm_per_hz: float = KT0_DBM_PER_HZ, propagation_f4=1.0):
    """Single-sweep FMCW SNR (linear): ``Pt G^2 lambda^2 sigma T F^4 / ((4 pi)^3 R^4 kT0 Fn L)``."""
    lam = wavelength_m(f_ghz)
    kt0_w_per_hz = 10.0 ** ((kt0_dbm_per_hz - 30.0) / 10.0)
    const = pt_w * undb(2.0 * gain_dbi) * lam * lam * sweep_s / ((4.0 * math.pi) ** 3 * kt0_w_per_hz
                                                                 * undb(noise_figure_db) * undb(losses_db))
    r = np.maximum(np.asarray(range_m, dtype=float), 1e-3)
    return const * np.asarray(sigma_m2, dtype=float) * propagation_f4 / r**4


def snr_db(sigma_m2, range_m, **kw):
    """:func:`snr` in dB."""
    return db(snr(sigma_m2, range_m, **kw))


# ------------------------------------------------------------------ antenna (REF 3.2)


def two_way_gain(theta_deg, width_3db_deg: float = BEAM_AZ_DEG):
    """Two-way power gain (peak 1) of a Gaussian beam: ``exp(-4 ln2 theta^2/theta3^2)`` squared."""
    t = np.asarray(theta_deg, dtype=float)
    return np.exp(-8.0 * math.log(2.0) * t * t / (width_3db_deg * width_3db_deg))


def one_way_gain_db(theta_deg, width_3db_deg: float):
    """One-way power gain of a Gaussian beam in dB (peak 0): ``-4 ln2 (10 / ln 10) theta^2 / theta3^2``."""
    t = np.asarray(theta_deg)
    return (-40.0 * math.log(2.0) / math.log(10.0) / (width_3db_deg * width_3db_deg)) * t * t


def two_way_equivalent_width_rad(width_3db_deg: float) -> float:
    """Integral of :func:`two_way_gain` over angle, rad: ``theta3 sqrt(pi / (8 ln 2))`` (0.753 theta3)."""
    return math.radians(width_3db_deg) * math.sqrt(math.pi / (8.0 * math.log(2.0)))


# ------------------------------------------------------------------ sea clutter (REF 3.7, 3.8)


def nrl_sigma0_db(psi_deg, f_ghz: float = FREQUENCY_GHZ, sea_state=2, pol: str = "HH"):
    """NRL mean sea reflectivity sigma0 (dB m^2/m^2), Gregers-Hansen & Mital 2012.

    ``c1 + c2 log10(sin psi) + (27.5 + c3 psi) log10(f)/(1 + 0.95 psi)
    + c4 (SS + 1)^(1/(2 + 0.085 psi + 0.033 SS)) + c5 psi^2`` (psi deg, f GHz, Douglas SS).
    Valid for psi 0.1..60 deg; used below 0.1 deg as is (it keeps falling with sin psi).
    """
    c1, c2, c3, c4, c5 = NRL_COEFFS[pol]
    psi = np.asarray(psi_deg, dtype=float)
    ss = np.asarray(sea_state, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        return (c1 + c2 * np.log10(np.sin(np.radians(psi))) + (27.5 + c3 * psi) * math.log10(f_ghz) / (1.0 + 0.95 * psi)
                + c4 * (ss + 1.0) ** (1.0 / (2.0 + 0.085 * psi + 0.033 * ss)) + c5 * psi * psi)


def clutter_cell_area_m2(range_m, psi_deg, beam_width_rad: float, range_cell_m: float):
    """Sea area of a resolution cell at low grazing: ``R theta dR sec(psi)`` (REF 3.7)."""
    return np.asarray(range_m, dtype=float) * beam_width_rad * range_cell_m / np.cos(np.radians(psi_deg))


def ward_shape_nu(psi_deg, cell_area_m2, pol: str = "HH", theta_swell_deg=0.0, nu_min: float = NU_MIN,
                  nu_max: float = NU_MAX):
    """K-distribution shape: ``log10 nu = 2/3 log10 psi + 5/8 log10 Ac - k_pol - cos(2 theta_sw)/3``, clamped."""
    with np.errstate(divide="ignore", invalid="ignore"):
        log_nu = ((2.0 / 3.0) * np.log10(np.asarray(psi_deg, dtype=float)) + 0.625 * np.log10(cell_area_m2)
                  - WARD_K_POL[pol] - np.cos(np.radians(2.0 * np.asarray(theta_swell_deg, dtype=float))) / 3.0)
    return np.clip(np.nan_to_num(10.0 ** log_nu, nan=nu_min), nu_min, nu_max)


class GammaQuantiles:
    """Fast Gamma(nu, mean 1) quantiles of standard-normal values, by table lookup.

    ``scipy.special.gammaincinv`` costs about 0.7 us a value; a revolution has 2 M clutter
    cells. The table holds ``nu_steps`` log-spaced shapes in [NU_MIN, NU_MAX] (nearest is
    used) and ``z_steps`` normal quantiles in [-z_max, z_max] (linear interpolation).
    """

    def __init__(self, nu_steps: int = 64, z_steps: int = 1201, z_max: float = 6.0):
        self.log_nu = np.linspace(math.log(NU_MIN), math.log(NU_MAX), nu_steps)
        self.z = np.linspace(-z_max, z_max, z_steps)
        nu = np.exp(self.log_nu)[:, None]
        u = np.clip(ndtr(self.z)[None, :], 1e-300, 1.0 - 1e-16)
        self.table = (gammaincinv(nu, u) / nu).astype(np.float64)
        self.dz = self.z[1] - self.z[0]
        self._table32 = self.table.reshape(-1).astype(np.float32)
        # each entry with its step to the next, (lo, hi - lo) as one complex64: one gather reads both (the step is
        # the float32 difference the interpolation forms, so the same values; the last step is never read)
        pairs = np.zeros((self._table32.size, 2), np.float32)
        pairs[:, 0] = self._table32
        pairs[:-1, 1] = self._table32[1:] - self._table32[:-1]
        self._pairs = pairs.view(np.complex64).reshape(-1)

    def __call__(self, z: np.ndarray, log_nu: np.ndarray) -> np.ndarray:
        """Gamma(nu, mean 1) quantiles of standard-normal ``z``; ``log_nu`` is ln(shape), broadcastable.

        The values of :meth:`reference` (the same operations in the same precisions), with fewer passes: one gather
        of (entry, step) pairs and the arithmetic in place.

        Parameters
        ----------
        z : (...) float
            Standard-normal values (cast to float32).
        log_nu : (...) float32
            Natural log of the K shape of each value.

        Returns
        -------
        (...) float64
            Quantiles (the interpolation's weights are float64).
        """
        z = np.asarray(z, dtype=np.float32)
        step = np.float32(self.log_nu[1] - self.log_nu[0])
        row = np.clip(log_nu, self.log_nu[0], self.log_nu[-1])  # float64 (float64 bounds), as in the reference
        row -= np.float32(self.log_nu[0])
        row /= step
        np.rint(row, out=row)
        flat = row.astype(np.intp)
        flat *= self.z.size
        pos = z - np.float32(self.z[0])
        pos *= np.float32(1.0 / self.dz)
        np.clip(pos, 0.0, np.float32(self.z.size - 1.001), out=pos)
        j = pos.astype(np.int32)
        flat = np.add(flat, j, out=flat if flat.shape == j.shape else None)
        frac = pos - j  # float32 - int32: float64, as in the reference
        pair = self._pairs.take(flat)
        if frac.shape != pair.shape:  # log_nu broader than z
            frac = np.broadcast_to(frac, pair.shape).copy()
        frac *= pair.imag  # the reference's (hi - lo) * frac
        frac += pair.real
        return frac

    def reference(self, z: np.ndarray, log_nu: np.ndarray) -> np.ndarray:
        """:meth:`__call__` written plainly (kept for the tests: the fast form must give these bytes)."""
        z = np.asarray(z, dtype=np.float32)
        step = np.float32(self.log_nu[1] - self.log_nu[0])
        k = np.rint((np.clip(log_nu, self.log_nu[0], self.log_nu[-1]) - np.float32(self.log_nu[0])) / step).astype(np.int32)
        pos = np.clip((z - np.float32(self.z[0])) * np.float32(1.0 / self.dz), 0.0, np.float32(self.z.size - 1.001))
        j = pos.astype(np.int32)
        frac = pos - j
        flat = k * np.int32(self.z.size) + j
        lo = self._table32.take(flat)
        hi = self._table32.take(flat + 1)
        return lo + (hi - lo) * frac


# ------------------------------------------------------------------ rain (REF 3.9)


def rain_attenuation_db_per_km(rain_mm_per_h):
    """One-way specific attenuation at 9.41 GHz, dB/km: the ITU-R P.838 values, log-log interpolated.

    Outside 1..50 mm/h the end segments' power laws are extended; 0 mm/h gives 0.
    """
    r = np.asarray(rain_mm_per_h, dtype=float)
    lr, la = np.log(RAIN_RATE_TABLE_MM_PER_H), np.log(RAIN_ATTENUATION_TABLE_DB_PER_KM)
    x = np.log(np.maximum(r, 1e-12))
    slope_lo = (la[1] - la[0]) / (lr[1] - lr[0])
    slope_hi = (la[-1] - la[-2]) / (lr[-1] - lr[-2])
    y = np.interp(x, lr, la)
    y = np.where(x < lr[0], la[0] + slope_lo * (x - lr[0]), y)
    y = np.where(x > lr[-1], la[-1] + slope_hi * (x - lr[-1]), y)
    return np.where(r > 0, np.exp(y), 0.0)


def rain_reflectivity_z(rain_mm_per_h):
    """Radar reflectivity factor Z = 200 R^1.6, mm^6/m^3 (Marshall-Palmer)."""
    return Z_R_A * np.power(np.maximum(np.asarray(rain_mm_per_h, dtype=float), 0.0), Z_R_B)


def rain_eta_m2_per_m3(rain_mm_per_h, f_ghz: float = FREQUENCY_GHZ, k2: float = WATER_K2):
    """Rain volume backscatter ``eta = pi^5 |K|^2 Z / lambda^4``, m^2/m^3 (Z converted to m^6/m^3)."""
    lam = wavelength_m(f_ghz)
    return math.pi**5 * k2 * rain_reflectivity_z(rain_mm_per_h) * 1e-18 / lam**4


# ------------------------------------------------------------------ targets (REF 3.6)


def flat_plate_rcs_m2(area_m2: float, f_ghz: float = FREQUENCY_GHZ) -> float:
    """Normal-incidence RCS of a flat conducting plate, ``4 pi A^2 / lambda^2`` (REF 3.6)."""
    return 4.0 * math.pi * area_m2**2 / wavelength_m(f_ghz) ** 2


# ------------------------------------------------------------------ multipath (REF 3.5)

# Significant wave height of each Douglas sea state 0..6, m: the middle of its WMO code 3700 band
# (raysim.sea.DOUGLAS_WAVE_HEIGHT_M holds the bands' upper bounds); rms surface height = Hs / 4.
SEA_STATE_HS_M = tuple((lo + hi) / 2.0 for lo, hi in zip((0.0,) + DOUGLAS_WAVE_HEIGHT_M[:-1], DOUGLAS_WAVE_HEIGHT_M))


def ament_factor(sea_state: int, sin_grazing, f_ghz: float = FREQUENCY_GHZ):
    """Roughness reduction of the sea's specular reflection: ``exp(-2 (2 pi sigma_h sin psi / lambda)^2)`` (REF 3.5)."""
    sigma_h = SEA_STATE_HS_M[int(np.clip(sea_state, 0, 6))] / 4.0
    x = 2.0 * math.pi * sigma_h * np.asarray(sin_grazing, dtype=float) / wavelength_m(f_ghz)
    return np.exp(-2.0 * x * x)


def multipath_f4(antenna_height_m, target_height_m, range_m, sea_state: int = 0, f_ghz: float = FREQUENCY_GHZ):
    """Two-way pattern-propagation factor ``F^4`` of the two-ray model over the sea (REF 3.5).

    ``F^2 = 1 + rho^2 - 2 rho cos(4 pi ha ht / (lambda R))`` with the reflection coefficient
    ``-rho`` (near -1 at low grazing) and ``rho`` the Ament roughness factor at the specular
    point's grazing angle ``(ha + ht) / R``; with ``rho = 1``: ``F^4 = 16 sin^4(2 pi ha ht/(lambda R))``.
    Heights are above the sea (a target at or below the waterline gets ``(1 - rho)^4``).
    """
    ha = np.maximum(np.asarray(antenna_height_m, dtype=float), 0.0)
    ht = np.maximum(np.asarray(target_height_m, dtype=float), 0.0)
    r = np.maximum(np.asarray(range_m, dtype=float), 1e-3)
    rho = ament_factor(sea_state, np.minimum((ha + ht) / r, 1.0), f_ghz)
    f2 = 1.0 + rho * rho - 2.0 * rho * np.cos(4.0 * math.pi * ha * ht / (wavelength_m(f_ghz) * r))
    return f2 * f2


# ------------------------------------------------------------------ ray fan


def elevation_grid_rad(antenna_height_m: float, resolve_range_m: float, resolve_m: float, top_height_m: float,
                       low_height_m: float, el_max_deg: float, el_min_deg: float) -> tuple[np.ndarray, np.ndarray]:
    """Elevation angles of a spoke's rays (antenna frame, descending) and the extent each stands for.

    - At and above the horizon the spacing at elevation ``e`` is ``max(s0, e s / (H - ha))`` with
      ``s0 = resolve_m / resolve_range_m``: rays at most ``resolve_m`` apart at the resolve range,
      and since an object no taller than ``H = top_height_m`` seen at ``e`` is nearer than
      ``(H - ha) / tan e``, at most ``resolve_m`` apart on it wherever it stands.
    - Below the horizon the rays meet the flat sea at distances ``d_1 > d_2 > ...`` from
      ``1.5 resolve_range_m`` inwards with ``d_i / d_(i+1) = ha / (ha - low_height_m)``: at any
      distance some ray passes between the waterline and ``low_height_m`` (a buoy or a growler that
      low is hit wherever it floats), down to ``el_min_deg``; never more than ``max(s0, |e| resolve_m / ha)``
      apart (``resolve_m`` at the distance where the ray meets the sea).

    Returns
    -------
    el_rad : (K,) float64
    d_el_rad : (K,) float64
    """
    ha = max(float(antenna_height_m), 0.1)
    s0 = resolve_m / max(float(resolve_range_m), 1.0)
    up_ratio = resolve_m / max(top_height_m - ha, resolve_m)
    e_max, e_min = math.radians(el_max_deg), math.radians(el_min_deg)
    up, e = [], 0.0
    while e < e_max:
        e += max(s0, e * up_ratio)
        up.append(min(e, e_max))
    shrink = max(ha - min(low_height_m, 0.9 * ha), 1e-3) / ha  # d_(i+1) / d_i
    down, e, d = [], 0.0, 1.5 * max(float(resolve_range_m), 1.0)
    while e > e_min:
        while -math.atan2(ha, d) >= e:  # the next sea-going ray below e
            d *= shrink
        # ... or nearer: never more than max(s0, |e| resolve_m / ha) apart (resolve_m at the ray's sea distance)
        e = max(e - max(s0, -e * resolve_m / ha), -math.atan2(ha, d), e_min)
        down.append(e)
    el = np.array(up[::-1] + [0.0] + down)
    edges = np.concatenate([[el[0] + 0.5 * (el[0] - el[1])], 0.5 * (el[1:] + el[:-1]),
                            [el[-1] - 0.5 * (el[-2] - el[-1])]])
    return el, edges[:-1] - edges[1:]


# ------------------------------------------------------------------ receiver (REF 3.10)


def stc_gain_db(range_m, a0_db: float, n: float, r0_m: float):
    """Sensitivity time control: ``min(0, -A0 + 10 n log10(R/R0))`` dB (0 everywhere when A0 = 0)."""
    if a0_db <= 0.0:
        return np.zeros_like(np.asarray(range_m, dtype=float))
    r = np.maximum(np.asarray(range_m, dtype=float), 1e-3)
    return np.minimum(0.0, -a0_db + 10.0 * n * np.log10(r / r0_m))


def quantise(power_db, floor_db: float, step_db: float, levels: int = 16) -> np.ndarray:
    """4-bit video on FIXED absolute levels: ``clip(floor((P_dB - floor_dB)/step_dB), 0, 15)``.

    Levels are relative to the receiver noise (P in dB re. noise), never to each spoke's maximum.
    NaN reads 0, +inf the top level.
    """
    p = np.asarray(power_db)
    p = p.astype(np.float32) if p.dtype != np.float32 else p
    v = p - np.float32(floor_db)
    v *= np.float32(1.0 / step_db)
    np.fmax(v, np.float32(0.0), out=v)  # fmax: NaN (and -inf) -> 0
    np.minimum(v, np.float32(levels - 0.5), out=v)  # +inf -> the top level
    return v.astype(np.uint8)  # truncation is floor on [0, levels)


# ------------------------------------------------------------------ sea clutter: wind direction (GIT)

#: The GIT model's grazing-angle range, deg (Horst, Dyer & Tuley 1978: 0.1 to 10 deg); steeper cells keep 10 deg.
GIT_MAX_GRAZING_DEG = 10.0


def git_wind_direction_db(psi_deg, f_ghz: float = FREQUENCY_GHZ):
    """Wind-direction factor of the GIT sea-clutter model, normalised to keep the mean over look directions.

    Georgia Tech (GIT) model, M. M. Horst, F. B. Dyer & M. T. Tuley, "Radar sea clutter model", Int. IEEE
    AP/S-URSI Symposium, 1978 (as given by V. Gregers-Hansen & R. Mital, "An improved empirical model for radar
    sea clutter reflectivity", NRL/MR/5310--12-9346, 2012, and Ward, Tough & Watts, *Sea Clutter*, 2nd ed. 2013):

    ``A_u = exp(0.2 cos(phi) (1 - 2.8 psi) (lambda + 0.015)^-0.4)``

    with ``phi`` the look direction relative to upwind (0: looking into the wind), ``psi`` the grazing angle in
    rad and ``lambda`` the wavelength in m. NRL's sigma0 (REF 3.7) is a fit to Nathanson's tables, averaged over
    the wind direction, so the clutter is multiplied by ``A_u / <A_u>``, the mean over ``phi`` being
    ``I0(a)`` for ``A_u = exp(a cos phi)``. Upwind over downwind is ``exp(2 a)``: 5.8 dB at 9.41 GHz and low
    grazing.

    Parameters
    ----------
    psi_deg : (N,) float
        Grazing angle, deg (clipped to [0, 10] deg, the model's range).
    f_ghz : float
        Frequency, GHz.

    Returns
    -------
    a_db : (N,) float64
        ``10 log10(e) a``: the factor in dB is ``a_db cos(phi) - mean_db``.
    mean_db : (N,) float64
        ``10 log10 I0(a)``, dB.
    """
    psi_rad = np.radians(np.clip(np.asarray(psi_deg, dtype=float), 0.0, GIT_MAX_GRAZING_DEG))
    a = 0.2 * (1.0 - 2.8 * psi_rad) * (wavelength_m(f_ghz) + 0.015) ** -0.4
    to_db = 10.0 / math.log(10.0)
    return to_db * a, to_db * (np.log(i0e(a)) + np.abs(a))  # ln I0(a) = ln(i0e(a)) + |a|

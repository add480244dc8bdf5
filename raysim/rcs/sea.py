"""Specular reflection of radar waves off the sea: Fresnel coefficients of sea water times roughness.

Importable without the CLI or the ray tracer (the radar renderer's image paths use
:func:`sea_reflection_coefficient`). Conventions (radar multipath literature, e.g.
L. V. Blake, *Radar Range-Performance Analysis*, Artech House 1986, ch. 6): ``psi`` is the
grazing angle (from the surface), the permittivity is ``eps' - j eps''`` (engineering
``exp(+j omega t)``), and the coefficients are

    Gamma_H = (sin psi - sqrt(eps - cos^2 psi)) / (sin psi + sqrt(eps - cos^2 psi))
    Gamma_V = (eps sin psi - sqrt(eps - cos^2 psi)) / (eps sin psi + sqrt(eps - cos^2 psi))

so a perfect conductor has ``Gamma_H = -1, Gamma_V = +1`` and both tend to ``-1`` at grazing
over sea water; ``Gamma_V`` has its (pseudo-)Brewster minimum near ``atan(1 / sqrt|eps|)``.
Sources: J. A. Stratton, *Electromagnetic Theory*, McGraw-Hill 1941, sec. 9.5 (Fresnel);
L. A. Klein and C. T. Swift, "An improved model for the dielectric constant of sea water at
microwave frequencies", IEEE Trans. Antennas Propag. AP-25(1), 104-111, 1977 (permittivity);
W. S. Ament, "Toward a theory of reflection by a rough surface", Proc. IRE 41(1), 142-146, 1953
and A. R. Miller, R. M. Brown and E. Vegh, "New derivation for the rough-surface reflection
coefficient and for the distribution of sea-wave elevations", IEE Proc. 131 Pt H(2), 114-116,
1984 (roughness).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.special import i0e

from raysim.sensors.radar_physics import SEA_STATE_HS_M, ament_factor

__all__ = [
    "SEA_TEMPERATURE_C",
    "SEA_SALINITY_PSU",
    "ROUGHNESS_MODELS",
    "sea_water_permittivity",
    "fresnel_coefficient",
    "roughness_factor",
    "sea_reflection_coefficient",
    "reflect_field",
    "SeaSurface",
]

#: Default sea temperature, deg C, and salinity, psu (open ocean; Klein and Swift's model).
SEA_TEMPERATURE_C = 20.0
SEA_SALINITY_PSU = 35.0
#: Specular roughness reductions: Ament (1953) and Miller, Brown and Vegh (1984).
ROUGHNESS_MODELS = ("ament", "miller-brown")
_EPS0_F_M = 8.854187817e-12


def sea_water_permittivity(
    f_ghz: float, temperature_c: float = SEA_TEMPERATURE_C, salinity_psu: float = SEA_SALINITY_PSU,
) -> complex:
    """Relative complex permittivity ``eps' - j eps''`` of sea water (Klein and Swift 1977).

    A Debye relaxation plus ionic conductivity, ``eps = eps_inf + (eps_s - eps_inf) / (1 + j w tau)
    - j sigma / (w eps_0)``, with ``eps_inf = 4.9`` and ``eps_s(T, S)``, ``tau(T, S)``,
    ``sigma(T, S)`` the fits of Klein and Swift (1977), eqs. 13-18 (valid 0-40 psu, -2..30 C,
    up to about 10 GHz). 9.41 GHz, 20 C, 35 psu: ``57.3 - 37.3j`` (ITU-R P.527 gives about the
    same for sea water at X band).

    Parameters
    ----------
    f_ghz : float
        Frequency, GHz.
    temperature_c : float
        Water temperature, deg C.
    salinity_psu : float
        Salinity, psu (g/kg).

    Returns
    -------
    complex
        Relative permittivity, negative imaginary part (loss).
    """
    t, s = float(temperature_c), float(salinity_psu)
    omega = 2.0 * math.pi * f_ghz * 1e9
    eps_s = (87.134 - 1.949e-1 * t - 1.276e-2 * t**2 + 2.491e-4 * t**3) * (
        1.0 + 1.613e-5 * s * t - 3.656e-3 * s + 3.210e-5 * s**2 - 4.232e-7 * s**3)
    tau_s = (1.768e-11 - 6.086e-13 * t + 1.104e-14 * t**2 - 8.111e-17 * t**3) * (
        1.0 + 2.282e-5 * s * t - 7.638e-4 * s - 7.760e-6 * s**2 + 1.105e-8 * s**3)
    delta = 25.0 - t
    beta = (2.0333e-2 + 1.266e-4 * delta + 2.464e-6 * delta**2
            - s * (1.849e-5 - 2.551e-7 * delta + 2.551e-8 * delta**2))
    sigma_s_m = s * (0.182521 - 1.46192e-3 * s + 2.09324e-5 * s**2 - 1.28205e-7 * s**3) * math.exp(-delta * beta)
    return complex(4.9 + (eps_s - 4.9) / (1.0 + 1j * omega * tau_s) - 1j * sigma_s_m / (omega * _EPS0_F_M))


def _polarisation(pol: str) -> str:
    p = pol.upper()
    if p not in ("H", "V", "HH", "VV"):
        raise ValueError(f"polarisation must be H, V, HH or VV, got {pol!r}")
    return p[0]


def fresnel_coefficient(grazing_rad, pol: str, eps: complex) -> np.ndarray:
    """Fresnel amplitude reflection coefficient of a flat half-space, (N,) complex (module conventions).

    Parameters
    ----------
    grazing_rad : array_like (N,)
        Grazing angle psi, rad, in [0, pi/2].
    pol : str
        ``H`` (``HH``, TE) or ``V`` (``VV``, TM).
    eps : complex
        Relative permittivity ``eps' - j eps''``.
    """
    psi = np.asarray(grazing_rad, dtype=float)
    sin_psi, cos_psi = np.sin(psi), np.cos(psi)
    root = np.sqrt(eps - cos_psi**2 + 0j)
    a = sin_psi if _polarisation(pol) == "H" else eps * sin_psi
    return (a - root) / (a + root)


def roughness_factor(sea_state: int, sin_grazing, f_ghz: float, model: str = "ament") -> np.ndarray:
    """Specular (coherent) amplitude reduction of a rough sea, (N,) float in (0, 1].

    ``g = k sigma_h sin psi`` with ``sigma_h = H_s / 4`` (H_s the sea state's significant wave
    height, :data:`raysim.sensors.radar_physics.SEA_STATE_HS_M`). Ament (1953):
    ``exp(-2 g^2)`` (:func:`raysim.sensors.radar_physics.ament_factor`); Miller, Brown and
    Vegh (1984): ``exp(-2 g^2) I0(2 g^2)``, closer to measurements when ``g`` > 0.5.
    """
    if model == "ament":
        return np.asarray(ament_factor(sea_state, sin_grazing, f_ghz), dtype=float)
    if model != "miller-brown":
        raise ValueError(f"roughness model must be one of {ROUGHNESS_MODELS}, got {model!r}")
    sigma_h = SEA_STATE_HS_M[int(np.clip(sea_state, 0, 6))] / 4.0
    g = 2.0 * math.pi * f_ghz / 0.299792458 * sigma_h * np.asarray(sin_grazing, dtype=float)
    return i0e(2.0 * g * g)  # exp(-x) I0(x), x = 2 g^2


def sea_reflection_coefficient(
    grazing_rad, pol: str, sea_state: int, f_ghz: float, model: str = "ament",
    temperature_c: float = SEA_TEMPERATURE_C, salinity_psu: float = SEA_SALINITY_PSU,
) -> np.ndarray:
    """Coherent specular reflection coefficient of the sea: Fresnel times roughness, (N,) complex.

    Parameters
    ----------
    grazing_rad : array_like (N,)
        Grazing angle, rad, in [0, pi/2].
    pol : str
        ``H``/``HH`` or ``V``/``VV``.
    sea_state : int
        Douglas sea state 0..6 (0: flat, Fresnel only).
    f_ghz : float
        Frequency, GHz.
    model : str
        Roughness model, ``ament`` or ``miller-brown`` (:func:`roughness_factor`).
    temperature_c, salinity_psu : float
        Sea water (:func:`sea_water_permittivity`).

    Returns
    -------
    (N,) complex128
        Multiply the incident field's H (or V) component by it (module conventions).
    """
    psi = np.asarray(grazing_rad, dtype=float)
    eps = sea_water_permittivity(f_ghz, temperature_c, salinity_psu)
    return fresnel_coefficient(psi, pol, eps) * roughness_factor(sea_state, np.sin(psi), f_ghz, model)


def reflect_field(field: np.ndarray, direction: np.ndarray, gamma_h, gamma_v) -> np.ndarray:
    """Field vectors reflected off the plane z = 0, (M, 3) complex.

    ``E' = Gamma_H (E.h) h + Gamma_V (E.p) (-R p)`` with ``h = d x z / |d x z|`` (x at normal
    incidence), ``p = h x d`` and ``R`` the mirror in z = 0, so ``Gamma_H = -1, Gamma_V = +1``
    gives the perfect conductor's ``-R E``.

    Parameters
    ----------
    field : (M, 3) complex or float
        Incident field vectors (perpendicular to ``direction``).
    direction : (M, 3) float64
        Unit incident propagation directions (``d_z < 0``).
    gamma_h, gamma_v : (M,) complex or scalar
        Coefficients (:func:`sea_reflection_coefficient`).
    """
    d = np.asarray(direction, dtype=float)
    h = np.column_stack([d[:, 1], -d[:, 0], np.zeros(len(d))])  # d x z
    norm = np.linalg.norm(h, axis=1, keepdims=True)
    h = np.where(norm > 1e-12, h / np.maximum(norm, 1e-300), np.array([1.0, 0.0, 0.0]))
    p = np.cross(h, d)
    p_reflected = -p * np.array([1.0, 1.0, -1.0])
    e_h = np.sum(field * h, axis=1) * gamma_h
    e_p = np.sum(field * p, axis=1) * gamma_v
    return e_h[:, None] * h + e_p[:, None] * p_reflected


@dataclass(frozen=True)
class SeaSurface:
    """The sea plane z = 0 as seen by the SBR engine.

    Attributes
    ----------
    sea_state : int
        Douglas sea state 0..6 (roughness).
    f_ghz : float
        Radar frequency, GHz.
    conductor : bool
        A flat perfect conductor instead (``Gamma_H = -1, Gamma_V = +1``; the old upper bound).
    model : str
        Roughness model (:data:`ROUGHNESS_MODELS`).
    """

    sea_state: int = 3
    f_ghz: float = 9.41
    conductor: bool = False
    model: str = "ament"

    def reflect(self, field: np.ndarray, direction: np.ndarray) -> np.ndarray:
        """:func:`reflect_field` with this sea's coefficients at each ray's grazing angle, (M, 3) complex."""
        d = np.asarray(direction, dtype=float)
        if self.conductor:
            return reflect_field(field, d, -1.0, 1.0)
        psi = np.arcsin(np.clip(np.abs(d[:, 2]), 0.0, 1.0))
        gamma_h = sea_reflection_coefficient(psi, "H", self.sea_state, self.f_ghz, self.model)
        gamma_v = sea_reflection_coefficient(psi, "V", self.sea_state, self.f_ghz, self.model)
        return reflect_field(field, d, gamma_h, gamma_v)

"""Physical optics of one ray tube of the radar's fan: the complex echo of the surface patch it lights.

A ray of the radar's fan stands for a tube of cross-section ``w_u x w_v`` across the ray
(``w_u = R d_az``, ``w_v = R d_el``). Where it hits a surface of unit normal ``n`` the physical-optics
(PO, Kirchhoff) scattering amplitude of the lit patch, from an incident direction ``d_in`` into a
scattered direction ``d_out`` (both unit propagation directions), in sqrt(m^2) so that
``sigma = |A|^2``, is

    A = (sqrt(4 pi) / lambda) (-n . (d_in - d_out) / 2) dA S exp(-j k (L_in + L_out))

- ``dA = w_u w_v / |n . d|`` the patch's surface area (``d`` the tube's direction);
- ``S = sinc(k g.u w_u / 2) sinc(k g.v w_v / 2)`` (unnormalised sinc) the exact integral of the
  linear phase over the patch, ``g = (d_in - d_out) - n ((d_in - d_out) . d) / (n . d)`` the phase
  gradient across the tube's axes ``u, v``; so the patches of a flat facet sum coherently to the
  facet's exact PO integral however coarse the tubes (a plate facing the radar gives
  ``4 pi A^2 / lambda^2``, its ``sinc^2`` lobe when turned);
- ``L_in + L_out`` the path length there and back: every echo carries its phase.

Monostatic (``d_out = -d_in``) this is the scalar PO backscatter ``sqrt(4 pi)/lambda int n.i exp(2jk i.r) dA``;
bistatic it is the scalar Kirchhoff form (the polarisation factors of a perfect conductor, which
are 1 for HH in the plane of incidence, are not kept).

Sources: P. Beckmann and A. Spizzichino, *The Scattering of Electromagnetic Waves from Rough
Surfaces*, Pergamon 1963, ch. 3 (Kirchhoff/PO integral); H. Ling, R.-C. Chou, S.-W. Lee,
"Shooting and bouncing rays", IEEE Trans. AP 37(2), 1989 (ray-tube integration, as in
:mod:`raysim.rcs.po`).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["patch_amplitude", "reflect", "dot"]


def dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise dot product of (M, 3) arrays: (M,)."""
    return np.einsum("ij,ij->i", a, b)


def _sinc_of_phase(k_rad_m: float, g_dot_axis: np.ndarray, width_m: np.ndarray) -> np.ndarray:
    """``np.sinc(k g_dot_axis width / (2 pi))`` (M,), by numpy's own steps in place: the same bytes, fewer copies.

    Parameters
    ----------
    k_rad_m : float
        Wavenumber, rad/m.
    g_dot_axis : (M,) float64
        Phase gradient along the tube's axis (consumed: overwritten).
    width_m : (M,) float64
        Tube width along that axis, m.
    """
    x = g_dot_axis
    x *= k_rad_m  # k g: evaluated left to right as in ``k * g * w / (2 pi)``
    x *= width_m
    x /= 2.0 * math.pi
    x *= math.pi  # numpy's sinc: y = pi x, eps where y == 0, sin(y) / y
    x[x == 0] = np.finfo(x.dtype).eps
    out = np.sin(x)
    out /= x
    return out


def reflect(v: np.ndarray, n: np.ndarray) -> np.ndarray:
    """Mirror (M, 3) vectors ``v`` in planes of unit normals ``n`` (M, 3): ``v - 2 (v.n) n``."""
    return v - 2.0 * dot(v, n)[:, None] * n


def patch_amplitude(k_rad_m: float, normal: np.ndarray, d_tube: np.ndarray, axis_u: np.ndarray, axis_v: np.ndarray,
                    width_u_m: np.ndarray, width_v_m: np.ndarray, d_in: np.ndarray, d_out: np.ndarray,
                    path_m: np.ndarray) -> np.ndarray:
    """PO scattering amplitude of tube patches (module docstring), complex, sqrt(m^2).

    Parameters
    ----------
    k_rad_m : float
        Wavenumber ``2 pi / lambda``, rad/m.
    normal : (M, 3) float64
        Unit surface normals facing the tube (``n . d_tube < 0``).
    d_tube, axis_u, axis_v : (M, 3) float64
        The tube's unit direction and cross-section axes (orthonormal).
    width_u_m, width_v_m : (M,) float64
        The tube's widths along ``axis_u`` and ``axis_v``, m.
    d_in, d_out : (M, 3) float64
        Unit propagation directions of the incident and the scattered wave.
    path_m : (M,) float64
        Total path length radar -> patch -> radar of this path, m.

    Returns
    -------
    (M,) complex128
        Zero where either leg lies behind the patch (``-n . d_in <= 0`` or ``n . d_out <= 0``).
    """
    n_dot_d = dot(normal, d_tube)
    n_dot_d = np.where(np.abs(n_dot_d) < 1e-9, -1e-9, n_dot_d)
    diff = d_in - d_out
    g = diff - normal * (dot(diff, d_tube) / n_dot_d)[:, None]
    shape = _sinc_of_phase(k_rad_m, dot(g, axis_u), width_u_m)
    shape *= _sinc_of_phase(k_rad_m, dot(g, axis_v), width_v_m)
    area_m2 = width_u_m * width_v_m / np.abs(n_dot_d)
    lit = (dot(normal, d_in) < 0.0) & (dot(normal, d_out) > 0.0)
    obliquity = np.where(lit, -dot(normal, diff) / 2.0, 0.0)
    scale = math.sqrt(4.0 * math.pi) * k_rad_m / (2.0 * math.pi)
    return scale * obliquity * area_m2 * shape * np.exp(-1j * k_rad_m * path_m)

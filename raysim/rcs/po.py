"""Physical optics (PO) ray-tube integration of the SBR hits: the far-field backscatter.

At each mesh hit a ray tube of cross-section ``a x a`` (side ``a`` = the launch spacing; a tube
of a plane wave keeps its cross-section through plane reflections) induces the PO current
``J = 2 n x H_i`` over its footprint ``a^2 / |n . d|`` on the facet. Its far field towards the
radar (unit vector ``s``) is, per unit incident field and with the free-space impedance
cancelled,

    E_s R = -j k / (4 pi) * s x (s x (2 n x (d x E))) * a^2 / |n . d| * S * exp(-j k L)

where ``L`` is the total path length (launch plane -> hits -> back to the launch plane) to the
tube centre and ``S = sinc(k g.u a / 2) sinc(k g.v a / 2)`` is the exact integral of the linear
phase over the tube's footprint (``g`` the in-facet phase gradient, ``u, v`` the tube axes), so a
flat facet's PO integral is exact however coarse the tubes. The contributions of all tubes and
all bounces are summed coherently and ``sigma = 4 pi |p . sum|^2`` (p the receive polarisation).
Over a flat sea the field radiated towards the sea's mirror direction ``s'`` reaches the radar
after a reflection off the sea (image theory; Fresnel coefficients of sea water times the rough-sea
specular reduction at the grazing angle = the elevation, :mod:`raysim.rcs.sea`); it is added as a
second term.

Source: H. Ling, R.-C. Chou and S.-W. Lee, "Shooting and bouncing rays: calculating the RCS
of an arbitrarily shaped cavity", IEEE Trans. Antennas Propag. 37(2), 194-205, 1989; the
ray-tube integration at the hit points as in S. Bhalla and H. Ling (1993) / Xpatch.
"""

from __future__ import annotations

import numpy as np

from raysim.rcs.sbr import MeshHits
from raysim.rcs.sea import SeaSurface

__all__ = ["scattered_field"]

_MIRROR = np.array([1.0, 1.0, -1.0])


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.sum(a * b, axis=-1)


def _tube_field(
    hits: MeshHits, out: np.ndarray, k: float, spacing_m: float, gamma: float, ref_point: np.ndarray,
    ref_offset_m: float, s_hat: np.ndarray, sea: SeaSurface | None, k_rms: float,
) -> np.ndarray:
    """Sum (3,) complex of the PO far fields of ``hits`` radiated in direction ``out`` (3,).

    The return path length is measured to the launch plane ``ref_point + ref_offset_m * s_hat``
    along ``s_hat``; for ``out`` = the sea mirror of ``s_hat`` the hit point is mirrored
    (image theory), which gives the path via the sea, and the sum is reflected off ``sea``.
    """
    d, n, e = hits.direction, hits.normal, hits.field
    cos_i = np.abs(_dot(n, d))
    current = 2.0 * np.cross(n, np.cross(d, e))  # (M, 3), J * eta
    radiated = out * _dot(out, current)[:, None] - current  # s x (s x J)
    image = not np.allclose(out, s_hat)
    point = hits.point_m * _MIRROR if image else hits.point_m
    back_m = ref_offset_m - (point - ref_point) @ s_hat
    g = (d - out) - n * (_dot(d - out, d) / _dot(n, d))[:, None]
    shape = np.sinc(k * _dot(g, hits.axis_u) * spacing_m / (2 * np.pi)) * np.sinc(
        k * _dot(g, hits.axis_v) * spacing_m / (2 * np.pi))
    coherent = np.exp(-0.5 * (k_rms * (cos_i + np.abs(_dot(n, out)))) ** 2)  # rough plating (Beckmann)
    weight = gamma * spacing_m**2 / cos_i * shape * coherent * np.exp(-1j * k * (hits.path_m + back_m))
    total = weight @ radiated  # (3,) complex
    if image:  # the sea reflects the field radiated along ``out`` back towards s_hat
        total = sea.reflect(total[None, :], out[None, :])[0]
    return (-1j * k / (4.0 * np.pi)) * total


def scattered_field(
    bounces: list[MeshHits], k: float, spacing_m: float, gamma: float, s_hat: np.ndarray,
    ref_point: np.ndarray, ref_offset_m: float, sea: SeaSurface | None, k_rms: float = 0.0,
) -> np.ndarray:
    """Coherent backscattered far field ``E_s R`` per unit incident field, (3,) complex, m.

    Parameters
    ----------
    bounces : list of MeshHits
        The mesh hits of every bounce (:func:`raysim.rcs.sbr.trace`).
    k : float
        Wavenumber ``2 pi / lambda``, rad/m.
    spacing_m : float
        Tube side, m.
    gamma : float
        Amplitude reflection coefficient of the mesh material (scales the PO current).
    s_hat : (3,) float64
        Unit vector towards the radar.
    ref_point : (3,) float64
        Centre of the launch grid, m.
    ref_offset_m : float
        Distance of the launch plane from ``ref_point`` along ``s_hat``, m.
    sea : SeaSurface or None
        Add the paths that return via the sea (z = 0).
    k_rms : float
        Wavenumber times the rms unfairness of the plating, rad: each hit's radiation towards
        ``out`` keeps the coherent fraction ``exp(-(k_rms (|n.d| + |n.out|))^2 / 2)`` (P. Beckmann
        and A. Spizzichino, *The Scattering of Electromagnetic Waves from Rough Surfaces*, 1963).

    Returns
    -------
    (3,) complex128
        ``sigma = 4 pi |p . E_s R|^2`` for receive polarisation ``p``.
    """
    total = np.zeros(3, dtype=complex)
    outs = [s_hat] + ([s_hat * _MIRROR] if sea is not None and s_hat[2] > 0.0 else [])
    for hits in bounces:
        if len(hits.point_m) == 0:
            continue
        for out in outs:
            total += _tube_field(hits, out, k, spacing_m, gamma, ref_point, ref_offset_m, s_hat, sea, k_rms)
    return total

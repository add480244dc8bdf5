"""Shooting and bouncing rays (SBR): a plane wave of ray tubes traced through Embree.

The incident plane wave is a dense square grid of parallel ray tubes launched from a plane
perpendicular to the radar direction over the target's projected extent. Each tube is traced
with Open3D's :class:`open3d.t.geometry.RaycastingScene` (Embree); at each hit it is reflected
specularly, ``d' = d - 2 (d.n) n``, its electric-field vector is reflected as at a perfect
conductor, ``E' = Gamma (-E + 2 (E.n) n)``, and it is recast from the hit point offset by a small
epsilon, up to ``n_bounces`` hits. A flat sea (the plane z = 0) is an optional mirror
intersected analytically, reflecting with the Fresnel coefficients of sea water times the
rough-sea specular reduction (:class:`raysim.rcs.sea.SeaSurface`). Every mesh hit is handed to
the physical-optics integration of :mod:`raysim.rcs.po`.

Source: H. Ling, R.-C. Chou and S.-W. Lee, "Shooting and bouncing rays: calculating the RCS
of an arbitrarily shaped cavity", IEEE Trans. Antennas Propag. 37(2), 194-205, 1989.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import open3d as o3d

from raysim.rcs.sea import SeaSurface

__all__ = ["MeshHits", "launch_grid", "trace"]

#: Offset of a recast ray's origin along its new direction, m.
EPSILON_M = 1e-4
#: Padding of the mesh's bounding box that rays are advanced to before casting, m.
BOX_PAD_M = 0.5


@dataclass
class MeshHits:
    """The tubes that hit the mesh at one bounce.

    Attributes
    ----------
    point_m : (M, 3) float64
        Hit points, body frame, m.
    direction : (M, 3) float64
        Unit propagation direction of the incident tube.
    normal : (M, 3) float64
        Unit facet normal turned against the incident direction (``n . d < 0``).
    field : (M, 3) complex128
        Incident electric-field vector (amplitude includes the reflection coefficients so far).
    path_m : (M,) float64
        Path length from the launch (reference) plane to the hit, m.
    axis_u, axis_v : (M, 3) float64
        The tube's cross-section axes (launch grid axes, reflected with the tube).
    """

    point_m: np.ndarray
    direction: np.ndarray
    normal: np.ndarray
    field: np.ndarray
    path_m: np.ndarray
    axis_u: np.ndarray
    axis_v: np.ndarray


def _reflect(v: np.ndarray, n: np.ndarray) -> np.ndarray:
    """Mirror vectors ``v`` (M, 3) in planes of unit normals ``n`` (M, 3)."""
    return v - 2.0 * np.sum(v * n, axis=1, keepdims=True) * n


def launch_grid(
    vertices_m: np.ndarray, s_hat: np.ndarray, u_hat: np.ndarray, v_hat: np.ndarray, spacing_m: float,
    mirror_sea: bool,
) -> tuple[np.ndarray, float, np.ndarray]:
    """Centres of the ray tubes on the launch plane.

    Parameters
    ----------
    vertices_m : (V, 3) float64
        Mesh vertices, m.
    s_hat, u_hat, v_hat : (3,) float64
        Unit vector towards the radar and the two launch-grid axes (orthonormal).
    spacing_m : float
        Tube side, m.
    mirror_sea : bool
        Also cover the mesh's mirror image in z = 0 (rays that reach the mesh via the sea).

    Returns
    -------
    origins_m : (N, 3) float64
        Tube centres on the launch plane, m.
    plane_offset_m : float
        Distance of the launch plane from the projection centre along ``s_hat``, m.
    centre_m : (3,) float64
        The projection centre (middle of the bounding box), m.
    """
    pts = vertices_m if not mirror_sea else np.vstack([vertices_m, vertices_m * [1.0, 1.0, -1.0]])
    centre = 0.5 * (vertices_m.min(axis=0) + vertices_m.max(axis=0))
    rel = pts - centre
    pu, pv = rel @ u_hat, rel @ v_hat
    us = np.arange(pu.min() - spacing_m, pu.max() + spacing_m, spacing_m)
    vs = np.arange(pv.min() - spacing_m, pv.max() + spacing_m, spacing_m)
    gu, gv = np.meshgrid(us, vs, indexing="ij")
    offset = float(np.max(np.linalg.norm(rel, axis=1))) + 1.0
    origins = centre + offset * s_hat + gu.reshape(-1, 1) * u_hat + gv.reshape(-1, 1) * v_hat
    return origins, offset, centre


def _box_entry(o: np.ndarray, d: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Slab test: entry and exit distances (M,) of rays into the box [lo, hi]; entry > exit on a miss."""
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / d
        t1, t2 = (lo - o) * inv, (hi - o) * inv
    t1 = np.nan_to_num(t1, nan=-np.inf)
    t2 = np.nan_to_num(t2, nan=np.inf)
    t_in = np.max(np.minimum(t1, t2), axis=1)
    t_out = np.min(np.maximum(t1, t2), axis=1)
    return t_in, t_out


def _cast(scene, o: np.ndarray, d: np.ndarray, t_far: np.ndarray, lo, hi) -> tuple[np.ndarray, np.ndarray]:
    """Mesh hit distance (M,) (inf on a miss or beyond ``t_far``) and facet normal (M, 3)."""
    t_in, t_out = _box_entry(o, d, lo, hi)
    near = np.maximum(t_in, 0.0)
    cast = (t_in <= t_out) & (t_out > 0.0) & (near < t_far)
    t = np.full(len(o), np.inf)
    normal = np.zeros((len(o), 3))
    if cast.any():
        start = o[cast] + near[cast, None] * d[cast]  # advanced to the box: small float32 coordinates
        rays = np.hstack([start, d[cast]]).astype(np.float32)
        ans = scene.cast_rays(o3d.core.Tensor(rays))
        t_hit = ans["t_hit"].numpy().astype(np.float64)
        hit = np.isfinite(t_hit)
        idx = np.flatnonzero(cast)[hit]
        t[idx] = near[idx] + t_hit[hit]
        normal[idx] = ans["primitive_normals"].numpy()[hit]
    t[t >= t_far] = np.inf
    return t, normal


def _launch(origins_m: np.ndarray, direction: np.ndarray, field: np.ndarray, axes: tuple[np.ndarray, np.ndarray],
            sea: bool):
    """The tubes' start: origins (N, 3), directions, complex fields, grid axes (N, 3) each and path lengths (N,).

    With the sea, a tube that begins under water starts further back along its line (its path < 0 there), and one
    that cannot reach the air is dropped.
    """
    n = len(origins_m)
    o = origins_m.copy()
    d = np.tile(direction, (n, 1))
    e = np.tile(np.asarray(field, dtype=complex), (n, 1))
    au, av = np.tile(axes[0], (n, 1)), np.tile(axes[1], (n, 1))
    path = np.zeros(n)
    if sea:
        below = o[:, 2] < 0.0
        if direction[2] < 0.0:
            back = (-o[below, 2] + EPSILON_M) / -direction[2]
            o[below] -= back[:, None] * direction
            path[below] -= back
        keep = o[:, 2] >= 0.0
        o, d, e, au, av, path = o[keep], d[keep], e[keep], au[keep], av[keep], path[keep]
    return o, d, e, au, av, path


def trace(
    vertices_m: np.ndarray, faces: np.ndarray, origins_m: np.ndarray, direction: np.ndarray,
    field: np.ndarray, axes: tuple[np.ndarray, np.ndarray], gamma: float, n_bounces: int,
    sea: SeaSurface | None, k_rms: float = 0.0,
) -> list[MeshHits]:
    """Trace a plane wave of ray tubes; return the mesh hits of every bounce.

    Parameters
    ----------
    vertices_m : (V, 3) float64
        Mesh vertices, m.
    faces : (F, 3) int
        Triangles.
    origins_m : (N, 3) float64
        Tube centres on the launch plane, m (path length 0 there).
    direction : (3,) float64
        Unit propagation direction of the plane wave (away from the radar).
    field : (3,) float64
        Unit transmit polarisation vector (perpendicular to ``direction``).
    axes : tuple of two (3,) float64
        The launch grid's unit axes.
    gamma : float
        Amplitude reflection coefficient of the mesh's material (1 for a perfect conductor).
    n_bounces : int
        Maximum number of hits (mesh or sea) per tube.
    sea : SeaSurface or None
        Reflect off the plane z = 0 too (Fresnel and roughness, or a perfect conductor).
    k_rms : float
        Wavenumber times the rms unfairness of the mesh's plating, rad: each mesh reflection's
        coherent amplitude is multiplied by ``exp(-2 (k_rms cos theta_i)^2)`` (Kirchhoff
        coherent reflection of a Gaussian rough surface; Ament 1953, Ruze 1966).

    Returns
    -------
    list of MeshHits
        One entry per bounce (possibly empty).
    """
    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(o3d.core.Tensor(vertices_m.astype(np.float32)),
                        o3d.core.Tensor(np.asarray(faces, dtype=np.uint32)))
    lo, hi = vertices_m.min(axis=0) - BOX_PAD_M, vertices_m.max(axis=0) + BOX_PAD_M
    o, d, e, au, av, path = _launch(origins_m, direction, field, axes, sea is not None)
    out: list[MeshHits] = []
    z_hat = np.array([0.0, 0.0, 1.0])
    for _ in range(n_bounces):
        if len(o) == 0:
            break
        t_sea = np.full(len(o), np.inf)
        if sea is not None:
            down = d[:, 2] < 0.0
            t_sea[down] = -o[down, 2] / d[down, 2]
        t_mesh, normal = _cast(scene, o, d, t_sea, lo, hi)
        on_mesh = np.isfinite(t_mesh)
        on_sea = ~on_mesh & np.isfinite(t_sea)
        t = np.where(on_mesh, t_mesh, t_sea)
        alive = on_mesh | on_sea
        nrm = np.where(on_mesh[:, None], normal, z_hat)
        nrm = nrm * -np.sign(np.sum(nrm * d, axis=1, keepdims=True) + 1e-300)  # face the incident ray
        p = o + np.where(alive, t, 0.0)[:, None] * d
        m = on_mesh
        out.append(MeshHits(p[m], d[m], nrm[m], e[m], path[m] + t[m], au[m], av[m]))
        e_sea = sea.reflect(e[on_sea], d[on_sea]) if on_sea.any() else None
        coherent = gamma * np.exp(-2.0 * (k_rms * np.sum(d * nrm, axis=1, keepdims=True)) ** 2)
        e = coherent * (-e + 2.0 * np.sum(e * nrm, axis=1, keepdims=True) * nrm)
        if e_sea is not None:
            e[on_sea] = e_sea
        d, au, av = _reflect(d, nrm), _reflect(au, nrm), _reflect(av, nrm)
        path = path + np.where(alive, t, 0.0)
        o = p + EPSILON_M * d
        if sea is not None:
            o[on_sea, 2] = np.maximum(o[on_sea, 2], EPSILON_M * 0.1)
        o, d, e, au, av, path = o[alive], d[alive], e[alive], au[alive], av[alive], path[alive]
    return out

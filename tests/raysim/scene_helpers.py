"""Helpers of the ray-engine tests: meshes, objects, analytic slabs, ray fans (tests/raysim/test_scene*.py)."""

from __future__ import annotations

import numpy as np
import open3d as o3d
import trimesh

from raysim.pose import rotation_matrices
from raysim.scene import NO_HIT, SceneObject

MM = 1e-3


def make_object(object_id, mesh: trimesh.Trimesh, motion, materials=None) -> SceneObject:
    """A SceneObject from a trimesh mesh (body frame)."""
    n = len(mesh.faces)
    mat = np.zeros(n, dtype=np.int16) if materials is None else np.asarray(materials, dtype=np.int16)
    return SceneObject(object_id, np.asarray(mesh.vertices, float), np.asarray(mesh.faces), mat, motion)


def quad(half_m: float) -> trimesh.Trimesh:
    """A square in the body y-z plane at x = 0 (two triangles)."""
    h = half_m
    v = np.array([[0, -h, -h], [0, h, -h], [0, h, h], [0, -h, h]], float)
    return trimesh.Trimesh(v, np.array([[0, 1, 2], [0, 2, 3]]), process=False)


def unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def slab(o_b: np.ndarray, d_b: np.ndarray, half: np.ndarray):
    """Analytic ray / axis-aligned box (centred at 0, half extents ``half``) in the body frame.

    Returns entry range (inf if missed), entry axis, entry normal sign and the
    gap between the largest and second largest slab entry (edge ambiguity).
    """
    with np.errstate(divide="ignore", invalid="ignore"):
        t1 = (-half - o_b) / d_b
        t2 = (half - o_b) / d_b
    tn = np.where(np.isnan(t1), -np.inf, np.minimum(t1, t2))
    tf = np.where(np.isnan(t1), np.inf, np.maximum(t1, t2))
    near, far = tn.max(axis=1), tf.min(axis=1)
    hit = (near <= far) & (near > 0)
    axis = tn.argmax(axis=1)
    sign = -np.sign(d_b[np.arange(len(d_b)), axis])
    srt = np.sort(tn, axis=1)
    return np.where(hit, near, np.inf), axis, sign, srt[:, 2] - srt[:, 1]


def world_to_body(o, d, pos, yaw):
    """Rays into a yawed body frame (per ray positions/yaws allowed)."""
    yaw = np.broadcast_to(yaw, (len(o),))
    r = rotation_matrices(yaw, np.zeros_like(yaw), np.zeros_like(yaw))
    return np.einsum("nji,nj->ni", r, o - pos), np.einsum("nji,nj->ni", r, d), r


def rays_towards(origin, targets):
    o = np.broadcast_to(np.asarray(origin, float), targets.shape).copy()
    return o, unit(targets - o)


def brute_force(objects: list[SceneObject], o, d, times) -> tuple[np.ndarray, np.ndarray]:
    """Every ray against every object with plain Open3D (no culling): nearest range and id."""
    best = np.full(len(o), np.inf)
    ids = np.full(len(o), NO_HIT, dtype=np.int32)
    for obj in objects:
        sc = o3d.t.geometry.RaycastingScene()
        sc.add_triangles(o3d.core.Tensor(obj.vertices_m.astype(np.float32)), o3d.core.Tensor(obj.faces.astype(np.uint32)))
        poses = obj.motion.poses(times)
        r = poses.rotation()
        rays = np.hstack([np.einsum("nji,nj->ni", r, o - poses.position_m), np.einsum("nji,nj->ni", r, d)])
        t = sc.cast_rays(o3d.core.Tensor(rays.astype(np.float32)))["t_hit"].numpy().astype(float)
        better = t < best
        best[better] = t[better]
        ids[better] = obj.object_id
    return best, ids

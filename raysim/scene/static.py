"""The static part of the scene: every fixed object in one Open3D scene, and its culling.

Static objects (motion :class:`raysim.motion.Stationary`) are transformed once
to world coordinates and put together in ONE ``RaycastingScene``, in
coordinates relative to ``offset_m`` (the mean of the objects' positions
snapped to a 1024 m grid, so zero for a scene centred near the world origin)
so that float32 keeps sub-millimetre precision at kilometre-scale
coordinates; ray origins are shifted by the same offset, in float64, before
casting.

Culling: a table direction cell -> nearest static bounding sphere distance; a
ray is cast only if that distance is below its sea range and its range limit.
When a subsample shows that most rays would be cast anyway (a sensor
surrounded by geometry), the table is skipped and all rays are cast.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np
import open3d as o3d

from raysim.scene.geometry import (AZ_BINS, EL_BINS, bounding_sphere, direction_cells, face_against, intersect_sea,
                                   sphere_cells, sphere_near_m)
from raysim.scene.hits import NO_HIT, Hits, SceneObject
from raysim.scene.rays import CHUNK, RayBatch, offset_tile, pack_rays, scratch, split_run

STATIC_CULL_MAX_FRACTION = 0.5
"""Cast all rays at the static scene when more than this fraction are candidates."""
_SUBSAMPLE_RAYS = 2048
"""Rays sampled to estimate the static candidate fraction."""
_OFFSET_GRID_M = 1024.0
"""The static scene's offset is snapped to this grid, metres."""
NEAR_TABLE_LOOP_MAX_RUNS = 64
"""Up to this many azimuth runs the near table is filled block by block; beyond, by one scatter."""
NEAR_TABLE_SCATTER_MAX_CELLS = 4_000_000
"""Largest number of (run, cell) pairs filled by one scatter (memory stays small); beyond, block by block."""
NEAR_TABLE_MARGIN_M = 50.0
"""The far objects' near table is built for the origin box grown by this much, metres, and kept while later boxes
stay inside the grown one."""
NEAR_TABLE_FAR_M = 500.0
"""Objects whose bounding sphere is this far from the grown origin box, metres, are far (their table is kept)."""


@dataclass
class StaticPart:
    """All static objects in one Open3D scene (world frame shifted by ``offset_m``).

    Built with :meth:`build`; ``nthreads`` is Embree's thread count (0 = all
    cores) and ``workers`` the threads of the per-ray numpy work.
    """

    scene: o3d.t.geometry.RaycastingScene
    offset_m: np.ndarray  # (3,) float64
    offset_tile: np.ndarray | None  # offset pattern for pack_rays
    geometry_object: np.ndarray  # (G,) int32: object id per geometry id
    geometry_face_offset: np.ndarray  # (G,) int64: first face of each geometry in face_material
    face_material: np.ndarray  # (F_total,) int16
    geometry_object_ext: np.ndarray  # (G + 1,) geometry_object + [NO_HIT] (index -1 = miss)
    geometry_face_offset_ext: np.ndarray  # (G + 1,) geometry_face_offset + [F_total + 1]
    face_material_ext: np.ndarray  # (F_total + 1,) face_material + [-1]
    sphere_centres: np.ndarray  # (G, 3) float64: world bounding sphere per object
    sphere_radii: np.ndarray  # (G,) float64
    nthreads: int = 0
    workers: int = 1
    _near_cache: tuple | None = None  # grown box: centre (3,), spread m; far objects (G,) bool; their table or None;
    # the table's least entry (m, inf if none)

    @classmethod
    def build(cls, objects: Sequence[SceneObject], nthreads: int, workers: int) -> "StaticPart":
        """Put static objects, in world coordinates minus an offset, in one Open3D scene.

        Parameters
        ----------
        objects : sequence of SceneObject
            At least one static object (its pose is taken at t = 0).
        nthreads : int
            Embree threads (0 = all cores).
        workers : int
            Threads of the per-ray numpy work.

        Returns
        -------
        StaticPart
        """
        poses = [o.motion.poses(np.zeros(1)) for o in objects]
        mean = np.mean([p.position_m[0] for p in poses], axis=0)
        offset = np.round(mean / _OFFSET_GRID_M) * _OFFSET_GRID_M
        scene = o3d.t.geometry.RaycastingScene(nthreads=nthreads)
        geometry_object, face_offset, materials, centres, radii = [], [], [], [], []
        n_faces = 0
        for obj, pose in zip(objects, poses):
            world = np.asarray(obj.vertices_m, dtype=np.float64) @ pose.rotation()[0].T + pose.position_m[0]
            gid = scene.add_triangles(
                o3d.core.Tensor(np.ascontiguousarray(world - offset, dtype=np.float32)),
                o3d.core.Tensor(np.ascontiguousarray(obj.faces, dtype=np.uint32)),
            )
            if gid != len(geometry_object):
                raise RuntimeError(f"unexpected Open3D geometry id {gid}")
            geometry_object.append(obj.object_id)
            face_offset.append(n_faces)
            materials.append(np.asarray(obj.face_material, dtype=np.int16))
            n_faces += len(obj.faces)
            c, r = bounding_sphere(world)
            centres.append(c)
            radii.append(r)
        return cls(
            scene=scene,
            offset_m=offset,
            offset_tile=offset_tile(offset),
            geometry_object=np.array(geometry_object, dtype=np.int32),
            geometry_face_offset=np.array(face_offset, dtype=np.int64),
            face_material=np.concatenate(materials),
            geometry_object_ext=np.array(geometry_object + [NO_HIT], dtype=np.int32),
            geometry_face_offset_ext=np.array(face_offset + [n_faces + 1], dtype=np.int32),
            face_material_ext=np.concatenate(materials + [np.array([-1], dtype=np.int16)]),
            sphere_centres=np.array(centres),
            sphere_radii=np.array(radii),
            nthreads=nthreads,
            workers=workers,
        )

    def near_table(self, batch: RayBatch) -> np.ndarray | None:
        """Nearest distance at which a static object can be met through each direction cell, or None.

        None when the origin box lies within reach of a static object's bounding sphere: that sphere covers every
        cell at distance 0, so every ray is a candidate and the table is of no use (cast all).

        The far objects' part of the table (spheres NEAR_TABLE_FAR_M or more from the box: a coast in tiles) is
        built for the box grown by NEAR_TABLE_MARGIN_M and kept while later boxes stay inside the grown one (a
        sensor on a moving ship). A table built for a larger box is conservative for a smaller one inside it: it
        lets through a few more rays, which miss or hit beyond their limit, so the hits are the same. The other
        objects' part is built for the box itself at every call, and the two are merged by their minimum.
        Objects that cannot be met within the batch's range limit are left out (:meth:`_within`), and the far
        part too when all its entries lie beyond that limit: the rays cast are the same.

        Parameters
        ----------
        batch : RayBatch
            With its origin box (``origin_centre``, ``spread_m``) set; its ``max_range`` (or None).

        Returns
        -------
        (CELLS,) float32 or None
            Metres (rounded down); ``inf`` where no static object can be met.
        """
        centre, spread = np.asarray(batch.origin_centre, dtype=np.float64), float(batch.spread_m)
        reach = np.linalg.norm(self.sphere_centres - centre, axis=1) - self.sphere_radii
        if np.any(reach <= spread):
            return None
        cap = np.inf if batch.max_range is None else float(np.max(batch.max_range))
        within = self._within(centre, spread, cap)
        if spread > NEAR_TABLE_MARGIN_M:
            return self._build_near_table(within, centre, spread)
        cached = self._near_cache
        if cached is None or np.linalg.norm(centre - cached[0]) + spread > cached[1]:
            grown = spread + NEAR_TABLE_MARGIN_M
            far = reach - grown >= NEAR_TABLE_FAR_M
            far_table = self._build_near_table(far, centre, grown) if far.any() else None
            far_min = np.inf if far_table is None else float(far_table.min())
            cached = (centre.copy(), grown, far, far_table, far_min)
            self._near_cache = cached
        far, far_table, far_min = cached[2], cached[3], cached[4]
        if far_table is None:
            return self._build_near_table(within, centre, spread)
        if far.all():
            return far_table
        near_table = self._build_near_table(~far & within, centre, spread)
        if far_min >= cap:  # no far object within the range limit: its entries decide no ray
            return near_table
        return np.minimum(far_table, near_table)

    def _within(self, centre: np.ndarray, spread_m: float, cap_m: float) -> np.ndarray:
        """(G,) bool: the objects that may be met within ``cap_m`` from the origin box (all if ``cap_m`` is inf).

        A ray is cast at the static scene only if a table entry of its cell is below its limit (at most
        ``cap_m``); an object whose entries are all at or beyond ``cap_m`` decides no ray and is left out
        of the table (a margin of 1e-3 relative plus 1 mm covers the entries' rounding down by 1e-6).

        Parameters
        ----------
        centre : (3,) float64
            Centre of the origin box, metres.
        spread_m : float
            Its half-diagonal, metres.
        cap_m : float
            The batch's greatest range limit, metres.
        """
        if not np.isfinite(cap_m):
            return np.ones(self.sphere_radii.size, dtype=bool)
        near = sphere_near_m(self.sphere_centres, self.sphere_radii, centre, spread_m)
        return near <= cap_m * (1.0 + 1e-3) + 1e-3

    def _build_near_table(self, which: np.ndarray, origin_centre: np.ndarray, spread_m: float) -> np.ndarray:
        """(CELLS,) float32: the near table of the objects ``which`` ((G,) bool) for origins within ``spread_m``
        of ``origin_centre`` (metres); ``inf`` everywhere for no object."""
        table = np.full((AZ_BINS, EL_BINS), np.inf, dtype=np.float32)
        if not which.any():
            return table.reshape(-1)
        cells = sphere_cells(self.sphere_centres[which], self.sphere_radii[which], origin_centre, spread_m)
        near = np.nextafter((cells.near_m * (1 - 1e-6)).astype(np.float32), np.float32(-np.inf))  # round down
        runs = cells.runs(np.arange(len(near)))
        area = (runs[2] - runs[1] + 1) * (runs[4] - runs[3] + 1)
        if runs[0].size > NEAR_TABLE_LOOP_MAX_RUNS and int(area.sum()) <= NEAR_TABLE_SCATTER_MAX_CELLS:
            _scatter_min(table, near, runs, area)  # many small blocks (land in tiles): one scatter
            return table.reshape(-1)
        for k, lo, hi, e0, e1 in zip(*runs):
            block = table[lo : hi + 1, e0 : e1 + 1]
            np.minimum(block, near[k], out=block)
        return table.reshape(-1)

    def fraction(self, batch: RayBatch, near_table: np.ndarray, sea: bool) -> float:
        """Fraction of the batch's rays the static table would keep (estimated on a subsample).

        Parameters
        ----------
        batch : RayBatch
        near_table : (CELLS,) float32
            From :meth:`near_table`, metres.
        sea : bool
            Whether the sea stops the rays.

        Returns
        -------
        float
            In [0, 1].
        """
        step = max(1, batch.n // _SUBSAMPLE_RAYS)
        sub = slice(0, batch.n, step)
        d = batch.directions[sub]
        cells = direction_cells(d[:, 0], d[:, 1], d[:, 2])
        lim = np.full(cells.shape[0], np.inf)
        if sea:
            lim = intersect_sea(batch.origins[sub, 2], d[:, 2])
        if batch.max_range is not None:
            mr = batch.max_range[sub] if batch.max_range.ndim else float(batch.max_range)
            lim = np.minimum(lim, mr)
        return float(np.mean(near_table[cells] < lim))

    def cast_all(self, batch: RayBatch) -> Hits:
        """Cast all rays of a batch at the static scene.

        Per-ray work: packing, one float32 -> float64 copy of ``t_hit``, one
        comparison (plus three table look-ups when many rays hit); the rest
        touches hits only. Open3D's own primitive and normal arrays are
        returned as they are (-1 and zeros where no hit).

        Parameters
        ----------
        batch : RayBatch
            N rays (world frame, metres).

        Returns
        -------
        Hits
            N hits on the static objects (world-frame normals facing the rays).
        """
        st = self
        n = batch.n
        rays = scratch("rays", (n, 6))
        pack_rays(batch.origins, batch.directions, st.offset_m, self.workers, out=rays)
        res = st.scene.cast_rays(o3d.core.Tensor.from_numpy(rays), nthreads=self.nthreads)
        t32 = res["t_hit"].numpy()
        gid = res["geometry_ids"].numpy().view(np.int32)  # INVALID_ID -> -1
        prim = res["primitive_ids"].numpy().view(np.int32)  # INVALID_ID -> -1
        normal = res["primitive_normals"].numpy()  # zeros where no hit
        rng = np.empty(n, dtype=np.float64)
        obj = np.empty(n, dtype=np.int32)
        material = np.empty(n, dtype=np.int16)
        split_run(
            n,
            self.workers,
            lambda a, b: _static_results_part(st, batch.directions, rays, t32, gid, prim, normal, rng, obj, material, a, b),
        )
        return Hits(rng, obj, normal, material, prim)

    def merge_some(self, hits: Hits, batch: RayBatch, idx: np.ndarray) -> None:
        """Cast rays ``idx`` at the static scene; keep hits nearer than the current ones and within the rays'
        range limit (in place).

        Parameters
        ----------
        hits : Hits
            The batch's N current hits, updated in place.
        batch : RayBatch
            Its ``max_range`` (metres, or None) bounds the hits kept.
        idx : (M,) int
            Rays to cast.
        """
        st = self
        if idx.size == 0:
            return
        rays = scratch("rays", (idx.size, 6))
        pack_rays(batch.origins, batch.directions, st.offset_m, self.workers, out=rays, idx=idx)
        res = st.scene.cast_rays(o3d.core.Tensor.from_numpy(rays), nthreads=self.nthreads)
        t = res["t_hit"].numpy()
        sel = np.flatnonzero(t < np.take(hits.range_m, idx))  # misses are inf
        if sel.size and batch.max_range is not None:  # float32 ranges against the float64 limit, in float64
            mr = batch.max_range if batch.max_range.ndim == 0 else np.take(batch.max_range, np.take(idx, sel))
            sel = sel[np.take(t, sel).astype(np.float64) <= mr]
        if sel.size == 0:
            return
        j = idx[sel]
        g = res["geometry_ids"].numpy().view(np.int32)[sel]
        prim = res["primitive_ids"].numpy().view(np.int32)[sel]
        normal = res["primitive_normals"].numpy()[sel]
        face_against(normal, np.arange(sel.size), np.take(batch.directions, j, axis=0))
        hits.range_m[j] = t[sel]
        hits.object_id[j] = st.geometry_object[g]
        hits.primitive[j] = prim
        hits.material[j] = st.face_material[st.geometry_face_offset[g] + prim]
        hits.normal[j] = normal


def _scatter_min(table: np.ndarray, near: np.ndarray, runs: tuple[np.ndarray, ...], area: np.ndarray) -> None:
    """``table[lo:hi+1, e0:e1+1] = min(table, near[label])`` for every run at once (``np.minimum.at``).

    Parameters
    ----------
    table : (AZ_BINS, EL_BINS) float32
        Filled in place.
    near : (K,) float32
        Nearest distance per object, metres.
    runs : tuple of (R,) int64
        ``label, lo, hi, e0, e1`` (:meth:`SphereCells.runs`).
    area : (R,) int64
        Cells of each run's block.
    """
    label, lo, hi, e0, e1 = runs
    n_el = e1 - e0 + 1
    run = np.repeat(np.arange(label.size), area)
    offset = np.arange(run.size) - np.repeat(np.cumsum(area) - area, area)
    cell = (lo[run] + offset // n_el[run]) * EL_BINS + e0[run] + offset % n_el[run]
    np.minimum.at(table.reshape(-1), cell, near[label[run]])


def _static_results_part(
    st: StaticPart,
    directions: np.ndarray,
    rays: np.ndarray,
    t32: np.ndarray,
    gid: np.ndarray,
    prim: np.ndarray,
    normal: np.ndarray,
    rng: np.ndarray,
    obj: np.ndarray,
    material: np.ndarray,
    a: int,
    b: int,
) -> None:
    """Turn Open3D's answers for rays ``a:b`` into ranges, ids, materials; flip normals.

    Chunk by chunk (small temporaries stay in cache). A chunk with many hits is
    handled with whole-chunk table look-ups (misses index the sentinels) and a
    normal/direction dot product against the packed float32 rays; a chunk with
    few hits is filled, then only its hits are touched.
    """
    for s in range(a, b, CHUNK):
        e = min(b, s + CHUNK)
        np.copyto(rng[s:e], t32[s:e])
        g = gid[s:e]
        if 16 * np.count_nonzero(g[::16] >= 0) > (e - s) // 8:  # many hits (a subsample decides)
            np.take(st.geometry_object_ext, g, out=obj[s:e], mode="wrap")
            face = np.take(st.geometry_face_offset_ext, g, mode="wrap")
            face += prim[s:e]
            np.take(st.face_material_ext, face, out=material[s:e], mode="wrap")
            n_c, r_c = normal[s:e], rays[s:e]
            dot = n_c[:, 0] * r_c[:, 3]  # 0 where no hit (zero normal)
            dot += n_c[:, 1] * r_c[:, 4]
            dot += n_c[:, 2] * r_c[:, 5]
            flip = np.flatnonzero(dot > 0)
            if flip.size:
                n_c[flip] *= -1.0
        else:
            obj[s:e] = NO_HIT
            material[s:e] = -1
            hit = np.flatnonzero(g >= 0)
            j = hit + s
            gh = g[hit]
            obj[j] = st.geometry_object[gh]
            material[j] = st.face_material[st.geometry_face_offset[gh] + prim[j]]
            face_against(normal, j, np.take(directions, j, axis=0))

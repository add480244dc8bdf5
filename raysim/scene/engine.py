"""The ray engine's entry point: :class:`Scene` and its ``cast``.

A cast takes a batch of world-frame rays, each with its own time, and returns
the first hit of each (:class:`raysim.scene.hits.Hits`). It runs a cheap
per-batch pre-pass (origin box, direction cells, sea ranges, static
candidates; numpy, chunked and split over threads), starts from the sea
(:func:`raysim.scene.geometry.intersect_sea`), merges the static part
(:class:`raysim.scene.static.StaticPart`), drops hits beyond the range limit,
then lets the moving objects (:class:`raysim.scene.moving.MovingPart`) replace
farther hits.
"""

from __future__ import annotations

import os
from typing import Sequence

import numpy as np
import open3d as o3d

from raysim import jit
from raysim.scene import kernels
from raysim.scene.geometry import direction_cells, intersect_sea, origin_box
from raysim.scene.hits import NO_HIT, SEA_ID, Hits, SceneObject, check_object, drop_beyond
from raysim.scene.moving import MovingPart
from raysim.scene.rays import CHUNK, RayBatch, split_run
from raysim.scene.static import STATIC_CULL_MAX_FRACTION, StaticPart


class Scene:
    """Objects and the sea, answering "what does this ray hit at its time".

    Parameters
    ----------
    objects : sequence of SceneObject
        Static and moving objects (ids need not be unique or dense).
    sea : bool
        Include the flat sea surface z = 0.
    sea_material : int
        Material index reported for sea hits.
    nthreads : int
        Threads for Embree (0 = all cores); also bounds the threads used for
        per-ray numpy work.
    cull : bool
        Cull rays (see :mod:`raysim.scene`). ``False`` casts every ray at the
        static scene and at every moving object (a brute-force reference).
    """

    def __init__(
        self,
        objects: Sequence[SceneObject],
        sea: bool = True,
        sea_material: int = -1,
        nthreads: int = 0,
        cull: bool = True,
    ) -> None:
        for obj in objects:
            check_object(obj)
        objects = [o for o in objects if len(o.faces)]  # nothing to hit on an empty mesh
        self.sea = bool(sea)
        self.sea_material = int(sea_material)
        self.nthreads = int(nthreads)
        self.cull = bool(cull)
        self._workers = max(1, min(self.nthreads or (os.cpu_count() or 1), 4))
        static = [o for o in objects if o.is_static]
        self._static = StaticPart.build(static, self.nthreads, self._workers) if static else None
        self._moving = MovingPart([o for o in objects if not o.is_static], self.nthreads, self.cull)

    @property
    def static_raycasting_scene(self) -> o3d.t.geometry.RaycastingScene | None:
        """The Open3D scene of the static objects (coordinates minus ``static_offset_m``)."""
        return None if self._static is None else self._static.scene

    @property
    def static_offset_m(self) -> np.ndarray:
        """(3,) world position of the static scene's coordinate origin, metres."""
        return np.zeros(3) if self._static is None else self._static.offset_m.copy()

    @property
    def n_bodies(self) -> int:
        """Number of distinct moving meshes (each moving object has its own copy in the atlas)."""
        return self._moving.n_bodies

    @property
    def n_atlas_geometries(self) -> int:
        """Meshes in the moving objects' one acceleration structure (one per moving object)."""
        return len(self._moving)

    def cast(
        self,
        origins_m: np.ndarray,
        directions: np.ndarray,
        times_s: np.ndarray,
        max_range_m: float | np.ndarray = np.inf,
    ) -> Hits:
        """First hit of each ray, each ray seeing the world at its own time.

        Parameters
        ----------
        origins_m : (N, 3) float64
            Ray origins in the world (ENU) frame, metres.
        directions : (N, 3) float
            Unit ray directions in the world frame.
        times_s : (N,) float64
            Time of each ray, seconds since scenario start.
        max_range_m : float or (N,) float
            Hits farther than this count as no hit, metres.

        Returns
        -------
        Hits
            One entry per ray.
        """
        origins = np.ascontiguousarray(origins_m, dtype=np.float64)
        dirs = np.ascontiguousarray(directions, dtype=np.float64)
        times = np.ascontiguousarray(times_s, dtype=np.float64).reshape(-1)
        n = origins.shape[0]
        if origins.shape != (n, 3) or dirs.shape != (n, 3) or times.shape != (n,):
            raise ValueError("origins and directions must be (N, 3) and times (N,)")
        max_range = np.asarray(max_range_m, dtype=np.float64)
        if max_range.ndim and max_range.shape != (n,):
            raise ValueError("max_range_m must be a scalar or (N,)")
        if n == 0:
            return Hits.empty(0)
        finite_range = bool(np.any(np.isfinite(max_range)))
        batch = RayBatch(origins, dirs, times, max_range if finite_range else None)
        self._prepare(batch)
        if self._static is not None and batch.static_candidates is None:
            hits = self._static.cast_all(batch)
            if self.sea:
                self._merge_sea(hits, batch)
            if finite_range:
                drop_beyond(hits, max_range)
        else:  # the sea ranges and the static hits merged are already within the range limit
            hits = self._sea_hits(batch)
            if self._static is not None:
                self._static.merge_some(hits, batch, batch.static_candidates)
        if len(self._moving):
            self._moving.cast(hits, batch)
        return hits

    # ---------------------------------------------------------- batch pre-pass

    def _prepare(self, batch: RayBatch) -> None:
        """Per-batch pre-pass: origin box, direction cells, sea ranges, static candidates (in ``batch``)."""
        movers = bool(len(self._moving))
        need_cells = self.cull and (self._static is not None or movers)
        if not need_cells:
            if self.sea:
                batch.sea_range = self._sea_range(batch, slice(None))
            return
        if jit.ENABLED:
            lo, hi = kernels.origin_box(batch.origins)
        else:
            parts = split_run(batch.n, self._workers, lambda a, b: origin_box(batch.origins[a:b]))
            lo = np.min([p[0] for p in parts], axis=0)
            hi = np.max([p[1] for p in parts], axis=0)
        batch.origin_centre = (lo + hi) / 2
        batch.spread_m = float(np.linalg.norm(hi - lo) / 2) * (1 + 1e-9) + 1e-9
        near_table = self._static.near_table(batch) if self._static is not None else None
        if near_table is not None and self._static.fraction(batch, near_table, self.sea) > STATIC_CULL_MAX_FRACTION:
            near_table = None
        if near_table is None and not movers:  # cells are of no use: sea only
            if self.sea:
                batch.sea_range = self._sea_range(batch, slice(None))
            return
        n = batch.n
        batch.cells = np.empty(n, dtype=np.uint16)
        if self.sea:
            batch.sea_range = np.empty(n, dtype=np.float64)
        parts = split_run(n, self._workers, lambda a, b: self._prepass_part(batch, near_table, a, b))
        if near_table is not None:
            batch.static_candidates = parts[0] if len(parts) == 1 else np.concatenate(parts)

    def _prepass_part(self, batch: RayBatch, near_table: np.ndarray | None, a: int, b: int) -> np.ndarray | None:
        """Fill the cells and sea ranges of rays ``a:b``; return their static candidates (or None)."""
        if jit.ENABLED:  # one compiled pass (raysim.scene.kernels), the same values
            return kernels.prepass(batch.origins, batch.directions, batch.max_range, near_table, batch.cells,
                                   batch.sea_range, a, b)
        cand = []
        for s in range(a, b, CHUNK):
            e = min(b, s + CHUNK)
            d32 = batch.directions[s:e].T.astype(np.float32)
            batch.cells[s:e] = direction_cells(d32[0], d32[1], d32[2])
            if batch.sea_range is not None:
                batch.sea_range[s:e] = self._sea_range(batch, slice(s, e))
            if near_table is not None:
                near = np.take(near_table, batch.cells[s:e])
                cand.append(np.flatnonzero(near < batch.limit(slice(s, e))) + s)
        if near_table is None:
            return None
        return np.concatenate(cand) if len(cand) != 1 else cand[0]

    # --------------------------------------------------------------------- sea

    @staticmethod
    def _sea_range(batch: RayBatch, s: slice) -> np.ndarray:
        """Range to the sea of rays ``s``, metres (``inf`` where none or beyond the ray's range limit)."""
        mr = batch.max_range
        if mr is not None and mr.ndim:
            mr = mr[s]
        return intersect_sea(batch.origins[s, 2], batch.directions[s, 2], mr)

    def _sea_normal_z(self, batch: RayBatch) -> np.ndarray:
        """(N,) float32: z of the sea normal facing each ray (+1 from above, -1 from below)."""
        return np.where(batch.directions[:, 2] < 0, np.float32(1.0), np.float32(-1.0))

    def _sea_hits(self, batch: RayBatch) -> Hits:
        """Hits of the sea alone (no hit everywhere if the scene has no sea).

        Integer passes instead of masked writes: where ``hit``, the id is ``NO_HIT + (SEA_ID - NO_HIT)``,
        the material ``-1 + (sea_material + 1)`` and the normal's z ``+1`` from above, ``-1`` from below
        (an int8 sign times ``hit``: exactly ``0.0``, never ``-0.0``, elsewhere).
        """
        n = batch.n
        if not self.sea:
            return Hits.empty(n)
        rng = batch.sea_range  # owned by this batch: returned as is
        hit = rng < np.inf
        hit8 = hit.view(np.int8)
        obj = hit.astype(np.int32)
        obj *= SEA_ID - NO_HIT
        obj += NO_HIT
        material = hit.astype(np.int16)
        material *= self.sea_material + 1
        material -= 1
        sign = (batch.directions[:, 2] < 0).view(np.int8) * np.int8(2)  # 2 from above, 0 from below
        sign -= 1
        sign *= hit8
        normal = np.zeros((n, 3), dtype=np.float32)
        normal[:, 2] = sign
        return Hits(rng, obj, normal, material, np.full(n, -1, dtype=np.int32))

    def _merge_sea(self, hits: Hits, batch: RayBatch) -> None:
        """Let the sea surface replace farther hits (in place)."""
        t = batch.sea_range
        nearer = t < hits.range_m
        replaced = nearer & (hits.object_id != NO_HIT)  # rows with a farther object hit
        if replaced.any():
            rows = np.flatnonzero(replaced)
            hits.primitive[rows] = -1
            hits.normal[rows] = 0.0
        np.copyto(hits.range_m, t, where=nearer)
        np.copyto(hits.object_id, SEA_ID, where=nearer)
        np.copyto(hits.material, self.sea_material, where=nearer)
        np.copyto(hits.normal[:, 2], self._sea_normal_z(batch), where=nearer)

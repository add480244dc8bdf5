"""The ray engine: first hit of each ray, each ray at its own time.

Embree (through Open3D's :class:`open3d.t.geometry.RaycastingScene`) does the
triangle work; this package decides which rays go to which acceleration
structure and turns Embree's answers into :class:`Hits`. One module per job:

:mod:`raysim.scene.hits`
    What the engine casts at and answers with: :class:`SceneObject`,
    :class:`Hits`, :data:`SEA_ID`, :data:`NO_HIT`.
:mod:`raysim.scene.geometry`
    Direction cells (:func:`direction_cells`: :data:`AZ_BINS` bins of a
    monotonic pseudo-azimuth times :data:`EL_BINS` bins of the direction's z
    component), the cells a sphere may be seen in from a box of origins, and
    the analytic tests: sea plane ``z = 0`` (:func:`intersect_sea`), ray/sphere,
    ray/box.
:mod:`raysim.scene.poses`
    The pose bank: poses of many moving objects at many times in one
    vectorised pass per motion kind, with the motions' own kernels
    (:mod:`raysim.motion`); swept bounding spheres over a batch's time span.
:mod:`raysim.scene.rays`
    The ray batch, packing rays into Open3D's float32 layout
    (:func:`pack_rays`), and the small thread pool of the per-ray numpy work
    (Open3D holds the GIL while casting; numpy releases it in its loops).
:mod:`raysim.scene.static`
    The static objects in ONE Open3D scene (world coordinates minus an offset
    snapped to 1024 m, for float32 precision) and their culling table
    (direction cell -> nearest static sphere).
:mod:`raysim.scene.moving`
    The moving objects in ONE Open3D scene, the atlas (each body-frame mesh in
    its own cell, never rebuilt): candidate (ray, object) pairs culled by
    direction cells and swept spheres, moved into the body frames at the rays'
    own times, cast in one call.
:mod:`raysim.scene.engine`
    :class:`Scene` and its ``cast``: pre-pass, sea, static part, range limit,
    moving part.

The own ship (the sensors' carrier) is no special case here: a sensor on it
casts through :class:`raysim.sensors.carrier.CarrierScene`, which holds one
``Scene`` of the world without the own ship and one of the own ship's
body-frame mesh alone (see docs/architecture.md).
"""

from raysim.scene.engine import Scene
from raysim.scene.geometry import AZ_BINS, EL_BINS, direction_cells, intersect_sea, pseudo_azimuth
from raysim.scene.hits import NO_HIT, SEA_ID, Hits, SceneObject
from raysim.scene.rays import pack_rays

__all__ = [
    "AZ_BINS",
    "EL_BINS",
    "NO_HIT",
    "SEA_ID",
    "Hits",
    "Scene",
    "SceneObject",
    "direction_cells",
    "intersect_sea",
    "pack_rays",
    "pseudo_azimuth",
]

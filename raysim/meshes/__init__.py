"""Body meshes: procedural icebergs, ship hulls, buoys, piers, and user mesh files.

Body frame (REP-103): x forward, y left, z up, metres, z = 0 at the waterline. The origin is
the object's reference point, the point placed at the object's scenario ``position``: the
centre of the waterline footprint for floating objects, the landward end centre for a pier.

Every generator returns a :class:`BodyMesh`: float64 vertices, int64 triangles, and one
material index per triangle into :data:`raysim.materials.MATERIALS`. Generated meshes are
closed (watertight) per component and smooth: the ray engine (Embree) is up to five times
slower on spiky meshes (docs/reference.md section 7).

Default dimensions of generated ships are rules of thumb chosen to look plausible on sensors
(unverified, documented on each function); scenarios can override length, beam and height.
"""

import logging

from raysim.meshes.body import BodyMesh
from raysim.meshes.files import MeshError, load_mesh
from raysim.meshes.icebergs import ICEBERG_DRAFT_RATIO, iceberg
from raysim.meshes.ships import (
    OWN_SHIP_MAX_HEIGHT_M,
    default_beam_m,
    default_draft_m,
    default_freeboard_m,
    own_ship,
    ship_hull,
)
from raysim.meshes.structures import buoy, pier

__all__ = [
    "BodyMesh",
    "MeshError",
    "OWN_SHIP_MAX_HEIGHT_M",
    "ICEBERG_DRAFT_RATIO",
    "default_beam_m",
    "default_freeboard_m",
    "default_draft_m",
    "iceberg",
    "ship_hull",
    "own_ship",
    "buoy",
    "pier",
    "load_mesh",
]

# trimesh logs through the "trimesh" logger; without any handler Python's last-resort handler
# would print its warnings to stderr. A NullHandler (standard library practice) keeps loading
# silent unless the application configures logging itself.
logging.getLogger("trimesh").addHandler(logging.NullHandler())

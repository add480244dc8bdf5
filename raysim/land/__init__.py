"""Land: GeoJSON coast and harbour polygons (:mod:`raysim.land.geojson`) and their meshes (:mod:`raysim.land.mesh`).

docs/land.md describes the scenario's ``land:`` entries, the file rules and how the meshes are made.
"""

from raysim.land.geojson import MAX_LAND_FILE_BYTES, LandPolygon, read_land_file
from raysim.land.mesh import DEFAULT_BASE_Z_M, LAND_MATERIALS, land_mesh, to_local

__all__ = ["DEFAULT_BASE_Z_M", "LAND_MATERIALS", "MAX_LAND_FILE_BYTES", "LandPolygon", "land_mesh", "read_land_file",
           "to_local"]

"""Land building blocks (issue 20): GeoJSON land files and the meshes of land polygons."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
import trimesh
from shapely.geometry import Point, Polygon, box

from raysim.errors import InputError
from raysim.land import LAND_MATERIALS, land_mesh, read_land_file, to_local
from raysim.materials import MATERIALS, material_index
from tests.raysim.helpers import FRAME, ORIGIN

BASE_Z_M = -2.0


def _trimesh(polygon: Polygon, height_m: float, slope_deg: float | None = None) -> trimesh.Trimesh:
    vertices, faces = land_mesh(polygon, height_m, slope_deg, base_z_m=BASE_Z_M)
    assert vertices.dtype == np.float64 and faces.dtype == np.int64
    return trimesh.Trimesh(vertices, faces, process=False)


def _walls(mesh: trimesh.Trimesh) -> tuple[np.ndarray, np.ndarray]:
    """Centres and unit normals of the vertical faces."""
    vertical = np.abs(mesh.face_normals[:, 2]) < 1e-9
    return mesh.triangles_center[vertical], mesh.face_normals[vertical]


# --- meshes -----------------------------------------------------------------------------------


def test_square_island_is_watertight_with_exact_volume_and_outward_vertical_walls():
    island = box(-40.0, -25.0, 60.0, 25.0)
    mesh = _trimesh(island, 12.0)
    assert mesh.is_watertight and mesh.is_winding_consistent
    assert mesh.volume == pytest.approx(island.area * (12.0 - BASE_Z_M), rel=1e-6)
    assert mesh.vertices[:, 2].min() == BASE_Z_M and mesh.vertices[:, 2].max() == 12.0
    centres, normals = _walls(mesh)
    assert len(centres) == 8  # two triangles per side, from the base to the top
    outward = centres[:, :2] - np.array(island.centroid.coords[0])
    # each wall's normal is the axis along which its centre lies off the centre, pointing away
    axis = np.where(np.abs(normals[:, 0]) > 0.5, 0, 1)
    assert np.all(normals[np.arange(len(axis)), axis] * outward[np.arange(len(axis)), axis] > 0)
    assert np.allclose(np.abs(normals).max(axis=1), 1.0)


def test_hole_walls_face_into_the_hole_and_its_volume_is_subtracted():
    hole = [(30.0, 30.0), (30.0, 60.0), (60.0, 60.0), (60.0, 30.0)]
    holed = Polygon([(0.0, 0.0), (100.0, 0.0), (100.0, 100.0), (0.0, 100.0)], [hole])
    mesh = _trimesh(holed, 10.0)
    assert mesh.is_watertight
    assert mesh.volume == pytest.approx((100.0**2 - 30.0**2) * (10.0 - BASE_Z_M), rel=1e-6)
    centres, normals = _walls(mesh)
    in_hole = (centres[:, 0] > 29.0) & (centres[:, 0] < 61.0) & (centres[:, 1] > 29.0) & (centres[:, 1] < 61.0)
    assert in_hole.sum() == 8
    towards_hole_centre = np.array([45.0, 45.0]) - centres[in_hole, :2]
    assert np.all(np.sum(normals[in_hole, :2] * towards_hole_centre, axis=1) > 0)


def test_sloped_island_volume_is_the_frustum_plus_the_submerged_slab():
    side_m, height_m, slope_deg = 100.0, 10.0, 30.0
    island = box(0.0, 0.0, side_m, side_m)
    mesh = _trimesh(island, height_m, slope_deg)
    assert mesh.is_watertight
    top_side_m = side_m - 2.0 * height_m / math.tan(math.radians(slope_deg))
    a_base, a_top = side_m**2, top_side_m**2
    frustum = height_m / 3.0 * (a_base + a_top + math.sqrt(a_base * a_top))
    assert mesh.volume == pytest.approx(frustum + a_base * -BASE_Z_M, rel=0.01)
    top = mesh.vertices[mesh.vertices[:, 2] == height_m]
    assert np.ptp(top[:, 0]) == pytest.approx(top_side_m, rel=1e-9)


def test_sloped_circle_volume_is_the_cone_frustum():
    radius_m, height_m, slope_deg = 200.0, 20.0, 20.0
    island = Point(0.0, 0.0).buffer(radius_m, quad_segs=64)
    mesh = _trimesh(island, height_m, slope_deg)
    assert mesh.is_watertight
    r_top = radius_m - height_m / math.tan(math.radians(slope_deg))
    frustum = math.pi * height_m / 3.0 * (radius_m**2 + radius_m * r_top + r_top**2)
    assert mesh.volume == pytest.approx(frustum + math.pi * radius_m**2 * -BASE_Z_M, rel=0.01)


def test_narrow_sloped_island_gets_a_lower_plateau():
    mesh = _trimesh(box(0.0, 0.0, 10.0, 10.0), 50.0, 30.0)
    assert mesh.is_watertight and mesh.volume > 0
    top_m = mesh.vertices[:, 2].max()
    assert top_m == pytest.approx(0.9 * 5.0 * math.tan(math.radians(30.0)))


def test_triangle_count_grows_linearly_with_the_outline():
    for slope_deg in (None, 30.0):
        counts = [len(land_mesh(Point(0.0, 0.0).buffer(500.0, quad_segs=n // 4), 10.0, slope_deg)[1])
                  for n in (100, 1000)]
        assert counts[1] / counts[0] == pytest.approx(10.0, rel=0.2)


def test_lonlat_polygon_to_local_metres_and_back():
    east, north = np.array([0.0, 300.0, 300.0, 0.0]), np.array([0.0, 0.0, 200.0, 200.0])
    lat, lon = FRAME.to_geodetic(east, north)
    lonlat = Polygon(np.column_stack([lon, lat])[::-1])  # clockwise in, counter-clockwise out
    local = to_local(lonlat, FRAME)
    assert local.exterior.is_ccw
    assert local.area == pytest.approx(300.0 * 200.0, rel=1e-6)
    xy = np.asarray(local.exterior.coords)[:-1]
    assert np.abs(xy[:, None, :] - np.column_stack([east, north])[None]).sum(axis=2).min(axis=1).max() < 1e-6


def test_land_materials_are_appended_materials():
    for name in LAND_MATERIALS:
        assert MATERIALS[material_index(name)].name == name
    assert [material_index(n) for n in ("rock", "vegetation", "sand")] == [11, 12, 13]  # after "sea"; never reorder


# --- GeoJSON ----------------------------------------------------------------------------------

SQUARE = [[10.47, 59.43], [10.48, 59.43], [10.48, 59.44], [10.47, 59.44], [10.47, 59.43]]
HOLE = [[10.473, 59.433], [10.473, 59.436], [10.476, 59.436], [10.476, 59.433], [10.473, 59.433]]


def _write(tmp_path, document, name="land.geojson") -> str:
    path = tmp_path / name
    path.write_text(document if isinstance(document, str) else json.dumps(document), encoding="utf-8")
    return str(path)


def _feature(coordinates, kind="Polygon", **properties):
    return {"type": "Feature", "properties": properties, "geometry": {"type": kind, "coordinates": coordinates}}


def test_feature_collection_properties_override_the_defaults(tmp_path):
    document = {"type": "FeatureCollection", "features": [
        _feature([SQUARE, HOLE]),
        _feature([[SQUARE]], "MultiPolygon", height_m=3.5, material="concrete", slope_deg=40),
    ]}
    polygons = read_land_file(_write(tmp_path, document), 12.0, "vegetation")
    assert [(p.height_m, p.material, p.slope_deg) for p in polygons] == [(12.0, "vegetation", None),
                                                                        (3.5, "concrete", 40.0)]
    assert len(polygons[0].polygon.interiors) == 1
    assert polygons[0].where == "features[0].geometry.coordinates"
    assert polygons[1].where == "features[1].geometry.coordinates[0]"
    assert polygons[0].polygon.bounds == pytest.approx((10.47, 59.43, 10.48, 59.44))


def test_bare_geometry_and_single_feature_use_the_defaults(tmp_path):
    (bare,) = read_land_file(_write(tmp_path, {"type": "Polygon", "coordinates": [SQUARE]}))
    assert (bare.height_m, bare.material, bare.slope_deg, bare.where) == (10.0, "rock", None, "coordinates")
    multi = read_land_file(_write(tmp_path, _feature([[SQUARE], [HOLE]], "MultiPolygon")), where_prefix="land[1]")
    assert [p.where for p in multi] == ["land[1].geometry.coordinates[0]", "land[1].geometry.coordinates[1]"]


def test_lonlat_file_to_mesh_end_to_end(tmp_path):
    (land,) = read_land_file(_write(tmp_path, {"type": "Polygon", "coordinates": [SQUARE, HOLE]}))
    mesh = _trimesh(to_local(land.polygon, FRAME), land.height_m)
    assert mesh.is_watertight
    assert ORIGIN == (59.43, 10.47) and mesh.bounds[0][:2] == pytest.approx([0.0, 0.0], abs=1.0)


def _bad_ring(ring):
    return {"type": "Polygon", "coordinates": [ring]}


BOWTIE = [[10.47, 59.43], [10.48, 59.44], [10.48, 59.43], [10.47, 59.44], [10.47, 59.43]]
OUTSIDE_HOLE = [[10.5, 59.5], [10.51, 59.5], [10.51, 59.51], [10.5, 59.51], [10.5, 59.5]]

BAD_FILES = [
    ("not json", "{not json", "line 1", "not JSON"),
    ("json, not geojson", json.dumps([1, 2]), "type", "not GeoJSON"),
    ("no type", {"features": []}, "type", "not GeoJSON"),
    ("unknown type", {"type": "Polygonn", "coordinates": [SQUARE]}, "type", "unknown geometry"),
    ("point", {"type": "Point", "coordinates": [10.47, 59.43]}, "type", "Polygon or MultiPolygon"),
    ("line feature", {"type": "FeatureCollection", "features": [_feature(SQUARE, "LineString")]},
     "features[0].geometry.type", "'LineString'"),
    ("empty collection", {"type": "FeatureCollection", "features": []}, "(file)", "no land polygons"),
    ("null geometry", {"type": "Feature", "properties": None, "geometry": None}, "geometry", "not null"),
    ("unclosed ring", _bad_ring(SQUARE[:-1] + [[10.471, 59.43]]), "coordinates[0]", "not closed"),
    ("three positions", _bad_ring([SQUARE[0], SQUARE[1], SQUARE[0]]), "coordinates[0]", "at least 4"),
    ("self-intersecting", _bad_ring(BOWTIE), "coordinates[0]", "Self-intersection"),
    ("hole outside", {"type": "Polygon", "coordinates": [SQUARE, OUTSIDE_HOLE]}, "coordinates", "invalid polygon"),
    ("lon out of range", _bad_ring([[190.0, 59.43]] + SQUARE[1:-1] + [[190.0, 59.43]]), "coordinates[0][0]",
     "outside lon"),
    ("lat out of range", _bad_ring(SQUARE[:2] + [[10.48, 95.0]] + SQUARE[3:]), "coordinates[0][2]", "outside lon"),
    ("nan coordinate", '{"type": "Polygon", "coordinates": [[[NaN, 59.43], [10.48, 59.43], [10.48, 59.44], '
     '[NaN, 59.43]]]}', "coordinates[0][0]", "non-finite"),
    ("string coordinate", _bad_ring([["10.47", 59.43]] + SQUARE[1:]), "coordinates[0][0]", "[lon, lat] numbers"),
    ("negative height",
     {"type": "FeatureCollection", "features": [_feature([SQUARE]), _feature([SQUARE], height_m=-1)]},
     "features[1].properties.height_m", "height must be in"),
    ("infinite height", '{"type": "Feature", "properties": {"height_m": Infinity}, '
     '"geometry": {"type": "Polygon", "coordinates": [' + json.dumps(SQUARE) + ']}}',
     "properties.height_m", "finite"),
    ("unknown material", _feature([SQUARE], material="cheese"), "properties.material", "unknown land material"),
    ("zero slope", _feature([SQUARE], slope_deg=0), "properties.slope_deg", "(0, 90]"),
    ("steep slope", _feature([SQUARE], slope_deg=95), "properties.slope_deg", "(0, 90]"),
    ("projected crs", {"type": "Polygon", "coordinates": [SQUARE],
                       "crs": {"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::25832"}}}, "crs", "WGS84"),
]


@pytest.mark.parametrize("document, where, what", [case[1:] for case in BAD_FILES], ids=[c[0] for c in BAD_FILES])
def test_bad_land_files_raise_one_line_input_errors(tmp_path, document, where, what):
    path = _write(tmp_path, document)
    with pytest.raises(InputError) as info:
        read_land_file(path, where_prefix="")
    assert (info.value.file, info.value.where) == (path, where)
    assert what in info.value.what and "\n" not in str(info.value)


def test_where_prefix_and_file_size_guard(tmp_path, monkeypatch):
    path = _write(tmp_path, _feature([SQUARE], material="cheese"))
    with pytest.raises(InputError) as info:
        read_land_file(path, where_prefix="land[2]")
    assert info.value.where == "land[2].properties.material"
    monkeypatch.setattr("raysim.land.geojson.MAX_LAND_FILE_BYTES", 10)
    with pytest.raises(InputError, match="may be at most 10 B"):
        read_land_file(path)
    with pytest.raises(InputError, match="directory"):
        read_land_file(tmp_path)

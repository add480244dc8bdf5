"""Tests of raysim.meshes: generated bodies and mesh loading."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from raysim.materials import MATERIALS, material_index
from raysim.meshes import (
    OWN_SHIP_MAX_HEIGHT_M,
    BodyMesh,
    MeshError,
    buoy,
    default_beam_m,
    iceberg,
    load_mesh,
    own_ship,
    pier,
    ship_hull,
)


def horizontal_max_above_water(mesh: BodyMesh) -> float:
    """Largest distance from the z axis of the vertices at or above the waterline."""
    above = mesh.vertices_m[mesh.vertices_m[:, 2] >= 0.0]
    return float(np.hypot(above[:, 0], above[:, 1]).max())


def assert_well_formed(mesh: BodyMesh) -> None:
    assert mesh.vertices_m.dtype == np.float64 and mesh.vertices_m.flags.c_contiguous
    assert mesh.faces.dtype == np.int64 and mesh.faces.flags.c_contiguous
    assert mesh.face_material.dtype == np.int16
    assert mesh.face_material.shape == (mesh.faces.shape[0],)
    assert mesh.faces.min() >= 0 and mesh.faces.max() < mesh.vertices_m.shape[0]
    assert np.all(np.isfinite(mesh.vertices_m))


def components_watertight(mesh: BodyMesh) -> bool:
    parts = mesh.to_trimesh().split(only_watertight=False)
    return all(part.is_watertight and part.volume > 0 for part in parts)


# --- BodyMesh ----------------------------------------------------------------------------------


def test_extents_above_water_of_a_sunken_octahedron():
    # Octahedron of unit radius lowered by 0.5 m: the top vertex is at z = 0.5, the four
    # equator vertices at z = -0.5; the waterline crosses the upper edges at their midpoints,
    # (+-0.5, 0, 0) and (0, +-0.5, 0). So above water: 1 m x 1 m, 0.5 m high.
    vertices = np.array(
        [[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], float
    ) - [0, 0, 0.5]
    faces = np.array(
        [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]]
    )
    mesh = BodyMesh(vertices, faces, np.zeros(8, np.int16), "octahedron")
    assert mesh.to_trimesh().is_watertight and mesh.to_trimesh().volume > 0
    assert mesh.extents_above_water_m() == pytest.approx((1.0, 1.0, 0.5))
    assert mesh.bounding_radius_m == pytest.approx(1.5)
    assert mesh.n_triangles == 8


def test_body_mesh_rejects_bad_arrays():
    vertices = np.zeros((3, 3))
    with pytest.raises(ValueError):
        BodyMesh(vertices, np.array([[0, 1, 3]]), np.zeros(1, np.int16), "bad index")
    with pytest.raises(ValueError):
        BodyMesh(vertices, np.array([[0, 1, 2]]), np.zeros(2, np.int16), "bad materials")
    with pytest.raises(ValueError):
        BodyMesh(vertices, np.array([[0, 1, 2]]), np.array([len(MATERIALS)]), "bad material")
    with pytest.raises(ValueError):
        BodyMesh(np.zeros((3, 2)), np.array([[0, 1, 2]]), np.zeros(1, np.int16), "bad shape")


def test_to_trimesh_keeps_order():
    mesh = buoy()
    tm = mesh.to_trimesh()
    np.testing.assert_array_equal(tm.faces, mesh.faces)
    np.testing.assert_array_equal(tm.vertices, mesh.vertices_m)


# --- icebergs ----------------------------------------------------------------------------------


@pytest.mark.parametrize("radius_m, height_m, seed", [(15, 8, 1), (40, 12, 2), (5, 6, 3)])
def test_iceberg_watertight_with_requested_size(radius_m, height_m, seed):
    berg = iceberg(radius_m, height_m, seed)
    assert_well_formed(berg)
    tm = berg.to_trimesh()
    assert tm.is_watertight
    assert tm.volume > 0
    assert np.all(berg.face_material == material_index("ice"))
    top = berg.vertices_m[:, 2].max()
    assert top == pytest.approx(height_m, rel=0.05)
    assert horizontal_max_above_water(berg) == pytest.approx(radius_m, rel=0.05)
    # Underwater part exists and is deeper than the height (draft ratio 3 by default).
    depth = -berg.vertices_m[:, 2].min()
    assert depth > height_m
    assert depth == pytest.approx(3.0 * height_m, rel=0.05)
    # Most of the volume is below the waterline: flatten everything above z = 0 onto the
    # waterline (a closed surface whose volume is, to within the straddling triangles, the
    # underwater volume).
    flattened = tm.vertices.copy()
    flattened[:, 2] = np.minimum(flattened[:, 2], 0.0)
    below = trimesh.Trimesh(flattened, tm.faces, process=False)
    assert below.volume > 0.5 * tm.volume


def test_iceberg_same_seed_identical_other_seed_different():
    a = iceberg(15, 8, seed=7)
    b = iceberg(15, 8, seed=7)
    c = iceberg(15, 8, seed=8)
    np.testing.assert_array_equal(a.vertices_m, b.vertices_m)
    np.testing.assert_array_equal(a.faces, b.faces)
    assert a.vertices_m.shape == c.vertices_m.shape
    assert np.abs(a.vertices_m - c.vertices_m).max() > 1.0


def test_iceberg_is_irregular_not_a_blob():
    # Undo the requested scaling (radius 15, height 15, draft 45) so that a plain
    # ellipsoidal blob would give unit radius everywhere: the berg's lumps make the radius
    # vary by more than 30 %.
    berg = iceberg(15, 15, seed=4)
    v = berg.vertices_m.copy()
    v[:, 2] = np.where(v[:, 2] >= 0, v[:, 2] / 15.0, v[:, 2] / 45.0)
    v[:, :2] /= 15.0
    r = np.linalg.norm(v, axis=1)
    assert r.max() / r.min() > 1.3


@pytest.mark.parametrize("seed", range(4))
def test_iceberg_is_smooth_and_star_shaped(seed):
    tm = iceberg(15, 8, seed).to_trimesh()
    # Adjacent faces never fold sharply (per-vertex noise would give angles near 180 deg).
    assert np.degrees(tm.face_adjacency_angles.max()) < 60.0
    assert np.degrees(np.median(tm.face_adjacency_angles)) < 5.0
    # Every face looks away from the origin: the mesh is star-shaped, no folds.
    centres = tm.triangles_center
    outward = np.einsum("ij,ij->i", centres, tm.face_normals)
    assert outward.min() > 0.0


def test_iceberg_subdivisions_and_validation():
    assert iceberg(10, 5, 0, subdivisions=3).n_triangles == 1280
    assert iceberg(10, 5, 0).n_triangles == 5120
    with pytest.raises(ValueError):
        iceberg(0, 5, 0)
    with pytest.raises(ValueError):
        iceberg(10, -1, 0)


def test_iceberg_draft_ratio():
    berg = iceberg(10, 4, seed=5, draft_ratio=5.0)
    assert -berg.vertices_m[:, 2].min() == pytest.approx(20.0, rel=1e-6)


# --- ships -------------------------------------------------------------------------------------


@pytest.mark.parametrize("length_m", [10.0, 30.0, 100.0])
def test_ship_hull_extents_plausible(length_m):
    ship = ship_hull(length_m)
    assert_well_formed(ship)
    length, beam, height = ship.extents_above_water_m()
    expected_beam = length_m / (3.2 + 0.03 * length_m)
    assert length == pytest.approx(length_m, rel=0.05)
    assert beam == pytest.approx(expected_beam, rel=0.10)
    assert beam == pytest.approx(default_beam_m(length_m), rel=0.10)
    assert 0.15 * length_m < height < 0.5 * length_m + 3.0
    assert ship.vertices_m[:, 2].min() < -0.3  # hull below water
    assert components_watertight(ship)
    assert ship.to_trimesh().volume > 0


def test_default_beam_examples():
    assert default_beam_m(10.9) == pytest.approx(3.1, abs=0.05)
    assert default_beam_m(30) == pytest.approx(7.3, abs=0.05)
    assert default_beam_m(100) == pytest.approx(16.1, abs=0.1)


def test_ship_hull_mast_present_or_absent():
    aluminium = material_index("aluminium")
    with_mast = ship_hull(100)
    without = ship_hull(100, mast=False)
    assert np.any(with_mast.face_material == aluminium)
    assert not np.any(without.face_material == aluminium)
    mast_top = with_mast.vertices_m[:, 2].max()
    assert 25.0 <= mast_top <= 35.0
    assert without.vertices_m[:, 2].max() < mast_top - 3.0
    mast_vertices = np.unique(with_mast.faces[with_mast.face_material == aluminium])
    assert with_mast.vertices_m[mast_vertices, 2].max() == pytest.approx(mast_top)


def test_ship_hull_materials_by_size():
    steel, grp = material_index("steel_painted"), material_index("grp")
    assert np.any(ship_hull(30).face_material == steel)
    assert not np.any(ship_hull(30).face_material == grp)
    assert np.any(ship_hull(10).face_material == grp)
    assert not np.any(ship_hull(10).face_material == steel)


@pytest.mark.parametrize("height_m", [12.0, 40.0])
def test_ship_hull_requested_height_and_beam(height_m):
    ship = ship_hull(60, beam_m=9.0, height_m=height_m)
    length, beam, height = ship.extents_above_water_m()
    assert height == pytest.approx(height_m, rel=1e-6)
    assert beam == pytest.approx(9.0, rel=1e-6)
    assert length == pytest.approx(60.0, rel=1e-6)


def test_own_ship_stays_below_sensor_mounts():
    ship = own_ship(10.9, 3.5)
    assert_well_formed(ship)
    assert ship.vertices_m[:, 2].max() <= OWN_SHIP_MAX_HEIGHT_M == 2.5
    length, beam, _ = ship.extents_above_water_m()
    assert length == pytest.approx(10.9, rel=0.05)
    assert beam == pytest.approx(3.5, rel=0.05)
    assert np.all(ship.face_material == material_index("grp"))
    assert components_watertight(ship)
    # A sensor at (1, 0, 3) is outside the mesh.
    assert not ship.to_trimesh().contains([[1.0, 0.0, 3.0]])[0]


# --- buoy and pier -----------------------------------------------------------------------------


def test_buoy_shape_and_retroreflective_band():
    b = buoy()
    assert_well_formed(b)
    tm = b.to_trimesh()
    assert tm.is_watertight and tm.volume > 0
    length, beam, height = b.extents_above_water_m()
    assert length == pytest.approx(1.0, rel=0.05) and beam == pytest.approx(1.0, rel=0.05)
    assert height == pytest.approx(2.5, rel=0.05)
    assert b.vertices_m[:, 2].min() == pytest.approx(-1.0, rel=0.05)
    retro = b.face_material == material_index("retroreflector")
    assert retro.sum() > 0
    band_z = b.vertices_m[b.faces[retro], 2]
    assert band_z.min() > 0.0  # the band is above water
    assert np.any(b.face_material == material_index("steel_painted"))


def test_pier_layout():
    p = pier(length_m=60, width_m=8, deck_height_m=2.0)
    assert_well_formed(p)
    v = p.vertices_m
    assert v[:, 0].min() == pytest.approx(0.0, abs=0.01)
    assert v[:, 0].max() == pytest.approx(60.0, abs=0.01)
    assert v[:, 2].max() == pytest.approx(2.0)
    assert np.all(np.abs(v[:, 1]) <= 4.0 + 0.5)
    assert components_watertight(p)
    assert np.any(p.face_material == material_index("concrete"))
    assert np.any(p.face_material == material_index("rubber"))
    assert not np.any(pier(fenders=False).face_material == material_index("rubber"))


# --- loading -----------------------------------------------------------------------------------


@pytest.mark.parametrize("suffix", [".stl", ".ply", ".obj", ".glb"])
def test_load_mesh_round_trip(tmp_path, suffix, capfd):
    original = iceberg(12, 6, seed=3, subdivisions=3)
    path = tmp_path / f"berg{suffix}"
    original.to_trimesh().export(path)
    loaded = load_mesh(path, material="snow")
    assert_well_formed(loaded)
    assert loaded.vertices_m.shape == original.vertices_m.shape
    assert loaded.n_triangles == original.n_triangles
    np.testing.assert_allclose(
        loaded.extents_above_water_m(), original.extents_above_water_m(), atol=1e-3
    )
    assert np.all(loaded.face_material == material_index("snow"))
    assert loaded.name == "berg"
    assert loaded.to_trimesh().is_watertight
    out, err = capfd.readouterr()
    assert out == "" and err == ""


def test_load_mesh_keeps_materials_of_material_named_geometries(tmp_path):
    original = buoy()
    path = tmp_path / "buoy.glb"
    original.to_scene().export(path)
    loaded = load_mesh(path)
    for name in ("steel_painted", "retroreflector"):
        index = material_index(name)
        assert np.sum(loaded.face_material == index) == np.sum(original.face_material == index)
    assert loaded.vertices_m.shape == original.vertices_m.shape
    assert loaded.to_trimesh().is_watertight


def test_shipped_assets_load(tmp_path):
    from pathlib import Path

    meshes_dir = Path(__file__).resolve().parents[2] / "meshes"
    odin = load_mesh(meshes_dir / "odin.glb")
    assert odin.extents_above_water_m() == pytest.approx((10.9, 3.5, 2.4), rel=1e-4)
    assert np.all(odin.face_material == material_index("grp"))
    dock = load_mesh(meshes_dir / "pier.glb")
    assert dock.extents_above_water_m()[0] == pytest.approx(60.0, rel=1e-4)
    for path in (meshes_dir / "odin.glb", meshes_dir / "pier.glb"):
        assert path.stat().st_size < 200_000


def test_load_mesh_unknown_material_name(tmp_path):
    path = tmp_path / "b.stl"
    buoy().to_trimesh().export(path)
    with pytest.raises(KeyError):
        load_mesh(path, material="unobtainium")


def _assert_mesh_error(path, capfd):
    with pytest.raises(MeshError) as info:
        load_mesh(path)
    error = info.value
    assert isinstance(error, ValueError)
    assert error.path == str(path)
    assert str(error) == error.message
    assert str(path) in error.message
    assert "\n" not in error.message
    out, err = capfd.readouterr()
    assert out == "" and err == ""
    return error


def test_load_mesh_missing_file(tmp_path, capfd):
    error = _assert_mesh_error(tmp_path / "nope.stl", capfd)
    assert "not found" in error.message


@pytest.mark.parametrize("suffix", [".stl", ".obj", ".ply", ".glb"])
def test_load_mesh_empty_file(tmp_path, suffix, capfd):
    path = tmp_path / f"empty{suffix}"
    path.write_bytes(b"")
    _assert_mesh_error(path, capfd)


@pytest.mark.parametrize("suffix", [".stl", ".obj", ".ply", ".glb", ".xyz"])
def test_load_mesh_garbage_file(tmp_path, suffix, capfd):
    path = tmp_path / f"garbage{suffix}"
    path.write_bytes(np.random.default_rng(0).integers(0, 256, 3000, dtype=np.uint8).tobytes())
    _assert_mesh_error(path, capfd)


def test_load_mesh_nan_vertex(tmp_path, capfd):
    path = tmp_path / "nan.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv nan 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n")
    error = _assert_mesh_error(path, capfd)
    assert "non-finite" in error.message


def test_load_mesh_point_cloud_has_no_triangles(tmp_path, capfd):
    path = tmp_path / "points.ply"
    trimesh.PointCloud(np.random.default_rng(1).normal(size=(20, 3))).export(path)
    error = _assert_mesh_error(path, capfd)
    assert "no triangles" in error.message

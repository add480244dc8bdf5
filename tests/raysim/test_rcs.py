"""SBR + PO radar cross-section: calibration against closed forms, and ``raysim rcs``."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
import trimesh

from raysim.cli import main
from raysim.rcs.engine import C_M_S, monostatic_rcs

LAMBDA_M = C_M_S / 9.41e9
SQRT_HALF = math.sqrt(0.5)

PLATE_V = np.array([[0, -0.5, -0.5], [0, 0.5, -0.5], [0, 0.5, 0.5], [0, -0.5, 0.5]], float)
PLATE_F = np.array([[0, 1, 2], [0, 2, 3]])
DIHEDRAL_V = np.array([[0, 0, -0.5], [0, 0, 0.5], [SQRT_HALF, SQRT_HALF, 0.5], [SQRT_HALF, SQRT_HALF, -0.5],
                       [SQRT_HALF, -SQRT_HALF, 0.5], [SQRT_HALF, -SQRT_HALF, -0.5]], float)
DIHEDRAL_F = np.array([[0, 1, 2], [0, 2, 3], [0, 1, 4], [0, 4, 5]])
TRIHEDRAL_V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
TRIHEDRAL_F = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 1]])


def _db(x: float) -> float:
    return 10.0 * math.log10(x)


@pytest.mark.parametrize("polarisation", ["HH", "VV"])
def test_flat_plate_normal_incidence(polarisation):
    sigma = monostatic_rcs(PLATE_V, PLATE_F, 0.0, polarisation=polarisation)
    assert abs(_db(sigma) - _db(4 * math.pi / LAMBDA_M**2)) < 2.0


def test_dihedral_broadside():
    sigma = monostatic_rcs(DIHEDRAL_V, DIHEDRAL_F, 0.0)
    assert abs(_db(sigma) - _db(8 * math.pi / LAMBDA_M**2)) < 2.0


def test_trihedral_on_axis():
    elevation = math.degrees(math.asin(1 / math.sqrt(3)))
    sigma = monostatic_rcs(TRIHEDRAL_V, TRIHEDRAL_F, -45.0, elevation)
    assert abs(_db(sigma) - _db(4 * math.pi / (3 * LAMBDA_M**2))) < 2.0


def test_plate_off_normal_is_far_below_the_peak():
    assert _db(monostatic_rcs(PLATE_V, PLATE_F, 10.0)) < _db(4 * math.pi / LAMBDA_M**2) - 15.0


def test_cross_polar_of_a_plate_is_negligible():
    assert monostatic_rcs(PLATE_V, PLATE_F, 0.0, polarisation="HV") < 1e-6


def test_sea_adds_the_hull_sea_dihedral():
    # a vertical 1 m x 1 m plate standing on the sea, seen at 1 deg elevation: plate + sea = dihedral
    wall = PLATE_V + [0.0, 0.0, 0.5]
    free = monostatic_rcs(wall, PLATE_F, 0.0, 1.0)
    sea = monostatic_rcs(wall, PLATE_F, 0.0, 1.0, sea=True)
    assert _db(sea) > _db(free) + 3.0


@pytest.fixture
def plate_file(tmp_path):
    path = tmp_path / "plate.stl"
    trimesh.Trimesh(PLATE_V, PLATE_F, process=False).export(path)
    return path


def test_command_writes_json(plate_file, tmp_path, capsys):
    out = tmp_path / "rcs.json"
    assert main(["rcs", str(plate_file), "--aspects", "8", "--json", str(out)]) == 0
    result = json.loads(out.read_text())
    assert result["aspect_deg"] == [0.0, 45.0, 90.0, 135.0, 180.0, 225.0, 270.0, 315.0]
    assert len(result["rcs_m2"]) == 8
    assert abs(_db(result["rcs_m2"][0]) - _db(4 * math.pi / LAMBDA_M**2)) < 2.0
    assert result["max_m2"] == max(result["rcs_m2"]) and result["min_m2"] == min(result["rcs_m2"])
    assert result["median_m2"] == pytest.approx(float(np.median(result["rcs_m2"])))
    assert "median" in capsys.readouterr().out


@pytest.mark.parametrize("extra, place", [
    (["--aspects", "0"], "--aspects"),
    (["--frequency-ghz", "nan"], "--frequency-ghz"),
    (["--elevation-deg", "95"], "--elevation-deg"),
    (["--range-m", "-1"], "--range-m"),
    (["--material", "unobtainium"], "--material"),
    (["--polarisation", "RL"], "--polarisation"),
    (["--sea", "--elevation-deg", "-5"], "--elevation-deg"),
])
def test_command_bad_options(plate_file, tmp_path, capsys, extra, place):
    out = tmp_path / "rcs.json"
    assert main(["rcs", str(plate_file), "--json", str(out), *extra]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error: command line: ") and place in err[0]
    assert not out.exists()


@pytest.mark.parametrize("content", [None, b"not a mesh at all"])
def test_command_bad_mesh(tmp_path, capsys, content):
    mesh = tmp_path / "broken.obj"
    if content is not None:
        mesh.write_bytes(content)
    out = tmp_path / "rcs.json"
    assert main(["rcs", str(mesh), "--json", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"error: {mesh}: ")
    assert not out.exists()

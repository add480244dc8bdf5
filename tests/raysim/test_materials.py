"""Tests of raysim.materials against independently computed numbers."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from raysim.materials import (
    MATERIALS,
    Material,
    fresnel_normal_reflectivity_db,
    material_index,
    material_table,
    specular_exponent_from_half_width_deg,
)

REQUIRED_NAMES = {
    "steel_painted", "aluminium", "ice", "snow", "grp", "wood", "concrete", "asphalt",
    "rubber", "retroreflector", "sea", "rock", "vegetation", "sand",
}


def by_name(name: str) -> Material:
    return MATERIALS[material_index(name)]


def test_all_required_materials_exist_with_unique_names():
    names = [m.name for m in MATERIALS]
    assert set(names) == REQUIRED_NAMES
    assert len(names) == len(set(names))


def test_material_index_matches_position_for_every_name():
    for position, material in enumerate(MATERIALS):
        assert material_index(material.name) == position


def test_unknown_material_raises_key_error_listing_valid_names():
    with pytest.raises(KeyError) as info:
        material_index("unobtainium")
    text = str(info.value)
    assert "unobtainium" in text
    for name in REQUIRED_NAMES:
        assert name in text


def test_ice_radar_reflectivity_is_about_minus_11_db():
    # Fresnel at normal incidence, er = 3.15: ((sqrt(3.15) - 1) / (sqrt(3.15) + 1))^2.
    root = 3.15 ** 0.5
    expected_db = 10 * math.log10(((root - 1) / (root + 1)) ** 2)  # -11.08 dB
    ice = by_name("ice")
    assert ice.relative_permittivity == pytest.approx(3.15)
    assert ice.radar_reflectivity_db == pytest.approx(expected_db, abs=1e-6)
    assert abs(ice.radar_reflectivity_db - (-11.0)) < 1.0


def test_fresnel_helper_against_hand_values():
    assert fresnel_normal_reflectivity_db(4.0) == pytest.approx(10 * math.log10(1 / 9))
    assert fresnel_normal_reflectivity_db(1.0) == -math.inf
    with pytest.raises(ValueError):
        fresnel_normal_reflectivity_db(0.0)


def test_sea_is_dark_at_905nm_and_fresnel_at_x_band():
    sea = by_name("sea")
    assert sea.reflectance_905nm == pytest.approx(0.02)
    root = math.sqrt(sea.relative_permittivity)
    assert sea.radar_reflectivity_db == pytest.approx(
        10 * math.log10(((root - 1) / (root + 1)) ** 2)
    )
    assert -4.0 < sea.radar_reflectivity_db < -1.0  # er about 60 gives about -2.3 dB


def test_reference_reflectances_at_905nm():
    assert 0.59 <= by_name("aluminium").reflectance_905nm <= 0.61
    assert by_name("asphalt").reflectance_905nm == pytest.approx(0.28)
    assert 0.3 <= by_name("ice").reflectance_905nm <= 0.5
    assert by_name("rubber").reflectance_905nm < by_name("concrete").reflectance_905nm
    for material in MATERIALS:
        assert 0.0 <= material.reflectance_905nm <= 1.0


def test_metals_and_retroreflector_reflect_0_db():
    for name in ("steel_painted", "aluminium", "retroreflector"):
        material = by_name(name)
        assert material.radar_reflectivity_db == 0.0
        assert material.relative_permittivity is None
    for material in MATERIALS:
        assert material.radar_reflectivity_db <= 0.0


def test_grp_radar_reflectivity_about_minus_10_db():
    assert abs(by_name("grp").radar_reflectivity_db - (-10.0)) < 1.5


def test_only_the_retroreflector_is_retroreflective():
    flagged = {m.name for m in MATERIALS if m.retroreflective}
    assert flagged == {"retroreflector"}


def test_specular_exponent_half_power_and_ordering():
    n = specular_exponent_from_half_width_deg(20.0)
    assert math.cos(math.radians(20.0)) ** n == pytest.approx(0.5)
    assert by_name("aluminium").specular_exponent > by_name("ice").specular_exponent > 1.0
    assert by_name("steel_painted").radar_roughness_m > by_name("aluminium").radar_roughness_m
    assert by_name("snow").specular_exponent < by_name("ice").specular_exponent


def test_table_arrays_aligned_with_materials():
    table = material_table()
    expected_dtypes = {
        "reflectance_905nm": np.float32,
        "retroreflective": np.bool_,
        "radar_reflectivity_db": np.float32,
        "specular_exponent": np.float32,
        "radar_roughness_m": np.float32,
    }
    assert set(table) == set(expected_dtypes)
    for key, dtype in expected_dtypes.items():
        array = table[key]
        assert array.dtype == dtype
        assert array.shape == (len(MATERIALS),)
        for position, material in enumerate(MATERIALS):
            assert array[position] == pytest.approx(getattr(material, key), rel=1e-6)


def test_table_lookup_by_index_array():
    table = material_table()
    indices = np.array([material_index("ice"), material_index("sea"), material_index("ice")])
    np.testing.assert_allclose(table["reflectance_905nm"][indices], [0.40, 0.02, 0.40], rtol=1e-6)


def test_materials_are_frozen_and_sourced():
    with pytest.raises(dataclasses.FrozenInstanceError):
        MATERIALS[0].name = "other"  # type: ignore[misc]
    for material in MATERIALS:
        assert material.source.strip()
    assert "unverified" in by_name("snow").source
    assert "HELIOS" in by_name("aluminium").source


def test_physics_doc_lists_the_material_table():
    from pathlib import Path

    from raysim.materials import describe_markdown

    doc = (Path(__file__).resolve().parents[2] / "docs" / "physics.md").read_text(encoding="utf-8")
    assert describe_markdown() in doc, "docs/physics.md is out of date: paste raysim.materials.describe_markdown()"

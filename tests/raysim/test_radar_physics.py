"""Radar physics against the reference values of REFERENCE.md section 3 (first part of issue 4)."""

from __future__ import annotations

import numpy as np
import pytest

from raysim.sensors import radar_equation as req
from raysim.sensors import sea_clutter as sc


@pytest.mark.parametrize("sea_state,expected_db", [(0, -66.5), (2, -49.4), (3, -43.7), (5, -35.3)])
def test_nrl_sigma0_matches_the_check_values(sea_state, expected_db):
    assert sc.nrl_sigma0_db(1.0, 9.41, sea_state, "HH") == pytest.approx(expected_db, abs=0.15)


def test_nrl_sigma0_rises_with_sea_state_and_grazing_angle():
    psi = np.array([0.2, 0.5, 1.0, 3.0])
    for pol in ("HH", "VV"):
        by_state = np.array([sc.nrl_sigma0_db(psi, 9.41, ss, pol) for ss in range(7)])
        assert np.all(np.diff(by_state, axis=0) > 0)
        assert np.all(np.diff(by_state, axis=1) > 0)
    assert np.all(sc.nrl_sigma0_db(psi, 9.41, 3, "VV") > sc.nrl_sigma0_db(psi, 9.41, 3, "HH"))


def test_horizon_and_grazing_angles_over_a_four_thirds_earth():
    assert sc.radar_horizon_m(3.0) == pytest.approx(7140, abs=10)
    assert sc.grazing_angle_deg(3.0, 100.0) == pytest.approx(1.7, abs=0.02)
    assert sc.grazing_angle_deg(3.0, 1000.0) == pytest.approx(0.17, abs=0.005)
    assert np.isnan(sc.grazing_angle_deg(3.0, 8000.0))  # past the horizon
    assert sc.curvature_drop_m(2000.0) == pytest.approx(2000.0**2 / (2 * 8_494_667), rel=1e-6)


def test_radar_equation_reference_example():
    link = req.RadarLink()
    assert link.snr_db(1.0, req.NAUTICAL_MILE_M) == pytest.approx(5.0, abs=1.0)
    assert link.snr_db(1000.0, req.NAUTICAL_MILE_M) == pytest.approx(35.0, abs=1.0)
    # R^-4: twice the range, 12 dB less
    assert link.snr_db(1.0, 1000.0) - link.snr_db(1.0, 2000.0) == pytest.approx(40 * np.log10(2), abs=1e-9)


def test_two_way_gaussian_beam():
    width = np.radians(5.2)
    assert req.two_way_gain(0.0, width) == 1.0
    assert req.two_way_gain(width / 2, width) == pytest.approx(0.25, rel=1e-9)  # -3 dB one way, -6 dB two way


def test_rain_attenuation_and_backscatter():
    for rate, db in zip((1.0, 4.0, 16.0, 50.0), (0.0093, 0.056, 0.33, 1.44)):
        assert req.rain_attenuation_db_per_km(rate) == pytest.approx(db, rel=1e-9)
    rates = np.array([0.5, 2.0, 8.0, 30.0, 100.0])
    values = [req.rain_attenuation_db_per_km(r) for r in rates]
    assert np.all(np.diff(values) > 0) and values[0] < 0.0093 and values[-1] > 1.44
    assert req.rain_attenuation_db_per_km(0.0) == 0.0
    assert req.rain_reflectivity_m2_per_m3(4.0) == pytest.approx(5e-7, rel=0.3)


def test_k_shape_is_clamped_and_grows_with_cell_area():
    assert sc.k_shape(1.0, np.array([1.0, 1e3, 1e9])).tolist()[0] == pytest.approx(0.1)
    nu = sc.k_shape(1.0, np.array([1e3, 1e4, 1e5]), "VV")
    assert np.all(np.diff(nu) > 0) and nu.max() <= 20.0


def test_k_distributed_intensity_has_the_configured_mean_and_shape():
    rng = np.random.default_rng(5)
    for nu in (0.5, 2.0, 10.0):
        intensity = sc.k_distributed_intensity(np.full(400_000, 3.0), nu, rng)
        assert intensity.mean() == pytest.approx(3.0, rel=0.02)
        # K intensity: E[I^2] / E[I]^2 = 2 (1 + 1 / nu)
        assert (intensity**2).mean() / intensity.mean() ** 2 == pytest.approx(2 * (1 + 1 / nu), rel=0.06)


def test_texture_correlation_length():
    assert sc.texture_correlation_length_m(0) == 0.0
    # sea state 3: W = 6 m/s, upwind: (pi/2)(36/9.81) x 2
    assert sc.texture_correlation_length_m(3) == pytest.approx(np.pi / 2 * 36 / 9.81 * 2, rel=1e-9)

"""Geodesy: pyproj round trips and distances against independent geodesics."""

from __future__ import annotations

import numpy as np
import pytest
from pyproj import Geod

from raysim.geodesy import LocalFrame

ORIGIN = (59.4377744115633, 10.4716511800410)


def test_origin_maps_to_zero():
    frame = LocalFrame(*ORIGIN)
    x, y = frame.to_local(ORIGIN[0], ORIGIN[1])
    assert abs(x) < 1e-9 and abs(y) < 1e-9


def test_round_trip_is_exact_to_a_micrometre():
    frame = LocalFrame(*ORIGIN)
    rng = np.random.default_rng(3)
    lat = ORIGIN[0] + rng.uniform(-0.2, 0.2, 1000)
    lon = ORIGIN[1] + rng.uniform(-0.4, 0.4, 1000)
    x, y = frame.to_local(lat, lon)
    lat2, lon2 = frame.to_geodetic(x, y)
    assert np.max(np.abs(lat2 - lat)) < 1e-11 and np.max(np.abs(lon2 - lon)) < 1e-11
    x2, y2 = frame.to_local(*frame.to_geodetic(x, y))
    assert np.max(np.abs(x2 - x)) < 1e-6 and np.max(np.abs(y2 - y)) < 1e-6


def test_distances_and_bearings_match_the_ellipsoid_geodesic():
    frame = LocalFrame(*ORIGIN)
    geod = Geod(ellps="WGS84")
    rng = np.random.default_rng(4)
    lat = ORIGIN[0] + rng.uniform(-0.02, 0.02, 200)  # within about 2 km
    lon = ORIGIN[1] + rng.uniform(-0.04, 0.04, 200)
    x, y = frame.to_local(lat, lon)
    azimuth, _, distance = geod.inv(np.full(200, ORIGIN[1]), np.full(200, ORIGIN[0]), lon, lat)
    assert np.max(np.abs(np.hypot(x, y) - distance)) < 0.01  # 1 cm over 2 km
    bearing = np.degrees(np.arctan2(x, y))
    assert np.max(np.abs((bearing - azimuth + 180) % 360 - 180)) < 0.02  # meridian convergence only


def test_one_minute_of_latitude_is_about_one_nautical_mile():
    frame = LocalFrame(*ORIGIN)
    _, y = frame.to_local(ORIGIN[0] + 1 / 60, ORIGIN[1])
    # meridian radius of curvature M = a (1 - e^2) / (1 - e^2 sin^2 lat)^1.5 (WGS84); a minute is M pi / 10800
    a, e2 = 6378137.0, 0.00669437999014
    lat = np.radians(ORIGIN[0] + 1 / 120)
    minute = a * (1 - e2) / (1 - e2 * np.sin(lat) ** 2) ** 1.5 * np.pi / 10800
    assert y == pytest.approx(minute, abs=0.01)

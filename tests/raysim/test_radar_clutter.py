"""Sea clutter (issue 19): GIT wind direction of the mean, Ward's K shape per cell, crest-aligned texture."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest
import yaml

from raysim.materials import material_index
from raysim.scenario import load_scenario
from raysim.sensors import radar_physics as rp
from raysim.sensors.carrier import CarrierScene
from raysim.sensors.radar import RadarRenderer
from raysim.sensors.radar_clutter import SeaClutter
from raysim.sensors.radar_texture import SeaTexture
from raysim.world import World
from tests.raysim.helpers import scenario

SPOKES = 512
#: Sensor -> world rotation of an antenna on a ship heading north (FLU -> ENU): azimuth a looks at bearing a.
HEADING_NORTH = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])


def sector(spokes, bearing_deg, half_deg):
    """Spokes whose bearing is within +-half_deg of bearing_deg."""
    az = np.arange(spokes) * 360.0 / spokes
    return np.flatnonzero(np.abs((az - bearing_deg + 180.0) % 360.0 - 180.0) <= half_deg)


def test_git_factor_upwind_over_downwind_and_its_mean_over_directions():
    # GIT (Horst, Dyer & Tuley 1978): exp(2 a), a = 0.2 (1 - 2.8 psi)(lambda + 0.015)^-0.4, at 9.41 GHz
    a_db, mean_db = rp.git_wind_direction_db(np.array([0.5]))
    a = 0.2 * (1 - 2.8 * math.radians(0.5)) * (299_792_458.0 / 9.41e9 + 0.015) ** -0.4
    assert 2 * a_db[0] == pytest.approx(20 * a / math.log(10), rel=1e-9)
    assert 4.0 < 2 * a_db[0] < 7.0
    phi = np.linspace(0, 2 * np.pi, 3600, endpoint=False)
    factor = 10 ** ((a_db[0] * np.cos(phi) - mean_db[0]) / 10)
    assert factor.mean() == pytest.approx(1.0, abs=1e-9)  # NRL's direction-averaged level is kept


def test_clutter_400_to_900_m_upwind_stands_4_to_7_db_over_downwind(tmp_path):
    data = scenario(tmp_path, environment={"sea_state": 4, "wind_speed_mps": 9, "wind_from_deg": 60.0}, duration=30.0)
    data["sensors"] = {"lidar": {"enabled": False},
                       "radar": {"spokes": SPOKES, "samples": 512, "range_m": 1852.0, "mount": {"z_m": 4.0},
                                 "sea_clutter_control_db": 0.0}}
    path = tmp_path / "git.yaml"
    path.write_text(yaml.safe_dump(data))
    world = World(load_scenario(path))
    r = RadarRenderer(world, CarrierScene(world.scene_objects(), sea_material=material_index("sea")))
    band = (r.range_m >= 400) & (r.range_m <= 900)
    up, down = sector(SPOKES, 60.0, 20.0), sector(SPOKES, 240.0, 20.0)
    sums = np.zeros(2)
    for rev in range(0, 12, 3):  # texture decorrelated between them (key frames 5.4 s apart)
        c = r.revolution(rev).clutter
        sums += [c[up][:, band].mean(), c[down][:, band].mean()]
    diff_db = 10 * math.log10(sums[0] / sums[1])
    a_db, _ = rp.git_wind_direction_db(rp.grazing_angle_deg(4.0, 650.0))
    # the GIT factor averaged over the +-20 deg sectors: 2 a sin(20 deg)/(20 deg) ~ 5.6 dB; the K texture scatters it
    assert 4.0 <= diff_db <= 7.0
    assert diff_db == pytest.approx(2 * float(a_db) * 0.98, abs=1.0)


def k_shape(x):
    """K shape from intensities of mean 1 (exponential speckle): <x ln x>/<x> - <ln x> = 1 + 1/nu.

    Blacknell & Tough, "Parameter estimation for the K-distribution based on [z log(z)]", IEE Proc. Radar Sonar
    Navig. 148(6), 2001.
    """
    x = x[x > 0]
    return 1.0 / (np.mean(x * np.log(x)) / np.mean(x) - np.mean(np.log(x)) - 1.0)


def test_fitted_k_shape_follows_wards_relation_with_range_and_look_direction():
    # VV (k_pol 1.39): Ward's nu stays inside the [0.1, 20] clamp at every look direction; 3 NM scale, 4 m antenna
    spokes, samples, range_m = 1024, 1024, 5556.0
    rng = np.linspace(0.0, range_m, samples)
    params = SimpleNamespace(f_ghz=rp.FREQUENCY_GHZ, beam_az_deg=rp.BEAM_AZ_DEG, beam_el_deg=rp.BEAM_EL_DEG,
                             polarisation="VV")
    sc = SeaClutter(rng, spokes, max(rng[1], rp.RANGE_RESOLUTION_M), params, 4, 0.0, 7, {})
    az = np.arange(spokes) * 360.0 / spokes
    rot = np.broadcast_to(HEADING_NORTH, (spokes, 3, 3))
    pos = np.zeros((spokes, 3))
    h = np.full(spokes, 4.0)
    mean = np.repeat(sc.mean_rows(rot[sc.rows], az[sc.rows], h, 4.0)[0], sc.sub, axis=0)
    x = []
    for k in range(8):  # 6.5 s apart: new key frames, the tile moved on
        clutter, _ = sc.render(k, np.full(spokes, 6.5 * k), rot, pos, az, np.zeros(spokes), h, np.full(spokes, np.inf))
        x.append(np.divide(clutter, mean, out=np.zeros_like(clutter, dtype=float), where=mean > 0))  # no mean: no cell
    x = np.stack(x)
    psi = rp.grazing_angle_deg(4.0, rng)
    area = rp.clutter_cell_area_m2(rng, psi, sc.beam_eq_rad, sc.cell_m)
    fitted, predicted = {}, {}
    for look, bearings in {"up/down swell": (0.0, 180.0), "cross swell": (90.0, 270.0)}.items():
        rows = np.concatenate([sector(spokes, b, 15.0) for b in bearings])
        for name, (r0, r1) in {"near": (800.0, 1200.0), "far": (4500.0, 5400.0)}.items():
            cols = (rng >= r0) & (rng <= r1)
            fitted[look, name] = k_shape(x[:, rows][:, :, cols])
            nu = rp.ward_shape_nu(psi[None, cols], area[None, cols], "VV", az[rows, None])
            predicted[look, name] = 1.0 / np.mean(1.0 / nu)  # the estimator's 1 + 1/nu averages 1/nu over cells
    for key in fitted:
        assert fitted[key] == pytest.approx(predicted[key], rel=0.3), (key, fitted, predicted)
    # look direction: Ward's cos(2 theta_sw)/3 term, 10^(2/3) = 4.6 between across and along the swell
    for name in ("near", "far"):
        f = math.log(fitted["cross swell", name] / fitted["up/down swell", name])
        p = math.log(predicted["cross swell", name] / predicted["up/down swell", name])
        assert p / 2 < f < 2 * p
    # range: psi^(2/3) A_c^(5/8) falls beyond 1 km (the 4/3-earth grazing angle drops faster than 1/R)
    for look in ("up/down swell", "cross swell"):
        f = math.log(fitted[look, "far"] / fitted[look, "near"])
        p = math.log(predicted[look, "far"] / predicted[look, "near"])
        assert p < 0 and 2 * p < f < p / 2


def test_texture_is_longer_along_the_wave_crests_than_along_the_wind():
    tex = SeaTexture(seed=5, sea_state=4, wind_from_deg=0.0)  # wind from the north: crests run east-west
    e, n = np.meshgrid(np.arange(0.0, 1200.0, 1.0), np.arange(0.0, 1200.0, 1.0))
    z = tex.sample(e, n, 0.0)
    b = (math.pi / 2) * 8.5**2 / rp.G_MPS2  # REF 3.8 length at sea state 4 (W = 8.5 m/s)
    lag = int(round(b))
    along_wind = np.mean(z[lag:, :] * z[:-lag, :]) / z.var()  # rows are north
    along_crest = np.mean(z[:, lag:] * z[:, :-lag]) / z.var()
    assert along_crest > along_wind + 0.2
    # Gaussian correlation exp(-d^2 / (2 L^2)): L = b along the wind, 2 b along the crests
    assert along_wind == pytest.approx(math.exp(-0.5), abs=0.1)
    assert along_crest == pytest.approx(math.exp(-0.125), abs=0.1)

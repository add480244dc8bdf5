"""Rain cells of the radar (issue 19): EXCELL cells drifting with the wind, path attenuation through them."""

from __future__ import annotations

import numpy as np
import pytest
import yaml
from scipy.integrate import quad

from raysim.materials import material_index
from raysim.scenario import load_scenario
from raysim.sensors import radar_physics as phys
from raysim.sensors.carrier import CarrierScene
from raysim.sensors.radar import RadarRenderer
from raysim.sensors.radar_rain import RainField, two_way_path_loss_db
from raysim.world import World
from tests.raysim.helpers import box_file, latlon, scenario

SPOKES, SAMPLES = 512, 512


def rain_world(tmp_path, environment, obstacles=(), name="r", range_m=1852.0):
    data = scenario(tmp_path, obstacles=obstacles, environment=environment, duration=40.0)
    data["sensors"] = {"lidar": {"enabled": False},
                       "radar": {"spokes": SPOKES, "samples": SAMPLES, "range_m": range_m, "mount": {"z_m": 4.0},
                                 "sea_clutter_control_db": 0.0}}
    path = tmp_path / f"{name}.yaml"
    path.write_text(yaml.safe_dump(data))
    world = World(load_scenario(path))
    return RadarRenderer(world, CarrierScene(world.scene_objects(), sea_material=material_index("sea")))


def cell(x_m, y_m, radius_m, rate):
    return {"position": latlon(x_m, y_m), "radius_m": radius_m, "rate_mm_per_h": rate}


def calm(**kw):
    return {"sea_state": 0, "wind_speed_mps": 0.0, **kw}


def test_path_loss_is_the_numeric_integral_of_the_itu_attenuation_through_an_excell_cell():
    dr, n = 2.0, 1500
    s = np.arange(n) * dr
    centre, r0, peak, bg = 1200.0, 250.0, 120.0, 2.0
    rate = bg + peak * np.exp(-np.abs(s - centre) / r0)
    loss_db = two_way_path_loss_db(phys.rain_attenuation_db_per_km(rate), dr)
    for r in (600.0, 1200.0, 1900.0, 2998.0):
        one_way, _ = quad(lambda x: float(phys.rain_attenuation_db_per_km(bg + peak * np.exp(-abs(x - centre) / r0))),
                          0.0, r, points=[centre] if r > centre else None, limit=200)
        assert loss_db[int(round(r / dr))] == pytest.approx(2.0 * one_way / 1000.0, rel=2e-3)
    # uniform rain: exactly 2 gamma r (REF 3.9), as the uniform model had it
    uniform = two_way_path_loss_db(np.full(n, 1.44), dr)
    assert uniform == pytest.approx(2.0 * 1.44 * s / 1000.0, abs=1e-9)


def test_uniform_background_alone_reproduces_the_uniform_model(tmp_path):
    r = rain_world(tmp_path, calm(rain_mm_per_h=8.0))
    assert not r.rain.field.has_cells
    gamma = float(phys.rain_attenuation_db_per_km(8.0))
    old_loss = phys.undb(-2.0 * gamma / 1000.0 * r.r64)
    loss, clutter = r.rain.revolution(r.seed, 0, *_geometry(r, 0))
    assert loss[0] == pytest.approx(old_loss, rel=1e-6)
    old_mean = phys.snr(phys.rain_eta_m2_per_m3(8.0) * r.r64 * r.beam_eq_rad * r.cell_m
                        * np.minimum(r.r64 * r.el_eq_rad / 2.0, r.p.rain_height_m), r.r64, **r.snr_kw)
    assert clutter.mean(axis=0)[10:] == pytest.approx(old_mean[10:], rel=0.25)  # 512 exponential draws per range
    # the general (cell) path on a uniform field gives the same loss beyond the first sample
    general = r.rain.path_loss(np.full((1, SAMPLES), 8.0, np.float32))[0]
    assert general[1:] == pytest.approx(old_loss[1:], rel=1e-5)


def _geometry(r, rev):
    t, azimuth, poses, _rot, pos, *_ = r.rays(rev)
    from raysim.pose import heading_deg_from_yaw

    return t, pos, heading_deg_from_yaw(poses.yaw_rad) + azimuth


def test_a_cell_echoes_in_its_direction_and_not_elsewhere(tmp_path):
    r = rain_world(tmp_path, calm(rain_cells=[cell(1000.0, 0.0, 300.0, 100.0)]))
    rev = r.revolution(0)
    bins = slice(int(800 / r.dr), int(1200 / r.dr))
    east = rev.echo[np.arange(SPOKES // 4 - 10, SPOKES // 4 + 11)][:, bins].astype(float)
    west = rev.echo[np.arange(3 * SPOKES // 4 - 10, 3 * SPOKES // 4 + 11)][:, bins].astype(float)
    assert east.mean() > 2.0  # 100 mm/h at 1 km: eta V about 20 dB over noise, exponentially speckled
    assert west.max() <= 1  # noise only (level 1: 9.6 dB, Pfa about 1e-4)


def test_a_target_behind_a_heavy_cell_is_attenuated_by_the_path_integral(tmp_path):
    # a 6 m steel cube turned 45 deg: about 40 dB over noise, well below the receiver's saturation
    mesh = box_file(tmp_path, "post", (6.0, 6.0, 6.0), (0.0, 0.0, 2.0))
    post = {"name": "post", "kind": "mesh", "mesh": mesh, "material": "steel_painted", "position": latlon(0.0, 1700.0),
            "heading_deg": 45.0}
    peak_db = []
    for cells, name in (([], "dry"), ([cell(0.0, 900.0, 300.0, 150.0)], "wet")):
        r = rain_world(tmp_path, calm(rain_cells=cells), obstacles=[post], name=name)
        rev = r.revolution(0)
        near = (np.arange(-2, 3)) % SPOKES
        peak_db.append(float(rev.snr_db[near][:, int(1690 / r.dr): int(1712 / r.dr)].max()))
    assert peak_db[0] < 60.0  # below the receiver's saturation: the drop is the attenuation alone
    one_way, _ = quad(lambda x: float(phys.rain_attenuation_db_per_km(150.0 * np.exp(-abs(x - 900.0) / 300.0))),
                      0.0, 1700.0, points=[900.0], limit=200)
    assert 2 * one_way / 1000 > 4.0  # a heavy cell: several dB
    assert peak_db[0] - peak_db[1] == pytest.approx(2 * one_way / 1000, abs=0.5)


def test_cells_drift_with_the_wind(tmp_path):
    wind = 10.0  # from the west: the cell moves east
    r = rain_world(tmp_path, {"sea_state": 0, "wind_speed_mps": wind, "wind_from_deg": 270.0,
                              "rain_cells": [cell(0.0, 1000.0, 150.0, 40.0)]})
    assert isinstance(r.rain.field, RainField)
    centroids = []
    revs = (0, 12)  # 12 x 2.5 s = 30 s apart
    for rev in revs:
        t, pos, bearing = _geometry(r, rev)
        _loss, clutter = r.rain.revolution(r.seed, rev, t, pos, bearing)
        eta = clutter / r.rain.volume_snr[None, :]  # proportional to R^1.6: the cell's own shape
        b = np.radians(bearing)[:, None]
        east = pos[:, 0, None] + np.sin(b) * r.range_m[None, :]
        north = pos[:, 1, None] + np.cos(b) * r.range_m[None, :]
        w = eta * (r.range_m[None, :] > 200)
        centroids.append(((w * east).sum() / w.sum(), (w * north).sum() / w.sum()))
        centroids[-1] += (float(t[t.size // 2]),)
    dt = centroids[1][2] - centroids[0][2]
    assert dt == pytest.approx(30.0, abs=0.01)
    assert centroids[1][0] - centroids[0][0] == pytest.approx(wind * dt, rel=0.1)
    assert abs(centroids[1][1] - centroids[0][1]) < 15.0

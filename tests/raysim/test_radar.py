"""Marine radar sweeps (first cut of issue 4): targets, shadow, clutter, rain, outputs."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from raysim.cli import main
from raysim.materials import material_index
from raysim.scenario import load_scenario
from raysim.sensors.carrier import CarrierScene
from raysim.sensors.radar import RadarRenderer
from raysim.world import World
from tests.raysim.test_lidar import box_file, latlon, scenario

SPOKES, SAMPLES = 512, 512


def radar_world(tmp_path, obstacles=(), ships=(), environment=None, name="r", range_m=1852.0):
    data = scenario(tmp_path, obstacles=obstacles, ships=ships, environment=environment, duration=5.0)
    data["sensors"] = {"lidar": {"enabled": False},
                       "radar": {"spokes": SPOKES, "samples": SAMPLES, "range_m": range_m, "mount": {"z_m": 4.0}}}
    path = tmp_path / f"{name}.yaml"
    path.write_text(yaml.safe_dump(data))
    world = World(load_scenario(path))
    return RadarRenderer(world, CarrierScene(world.scene_objects(), sea_material=material_index("sea"))), path


def hull(tmp_path, name, bearing_deg, distance_m, length=40.0, height=12.0):
    x = distance_m * np.sin(np.radians(bearing_deg))
    y = distance_m * np.cos(np.radians(bearing_deg))
    mesh = box_file(tmp_path, name, (length, 8.0, height + 3.0), (0.0, 0.0, (height - 3.0) / 2))
    return {"name": name, "kind": "mesh", "mesh": mesh, "material": "steel_painted", "position": latlon(x, y),
            "heading_deg": (bearing_deg + 90.0) % 360.0}  # broadside to the radar


def spoke_of(bearing_deg):
    return int(round(bearing_deg / 360.0 * SPOKES)) % SPOKES


def around(bearing_deg, half_spokes):
    """Spoke indices within +-half_spokes of a bearing (wrapping)."""
    return (spoke_of(bearing_deg) + np.arange(-half_spokes, half_spokes + 1)) % SPOKES


def test_a_hull_echoes_at_its_range_and_bearing_smeared_by_the_beam(tmp_path):
    renderer, _ = radar_world(tmp_path, obstacles=[hull(tmp_path, "target", 45.0, 900.0)],
                              environment={"sea_state": 0, "wind_speed_mps": 0})
    sweep = renderer.render_revolution(0)
    echo = sweep["echo"].astype(int)
    strong = np.argwhere(echo >= 10)
    assert strong.size
    rng = sweep["range_m"][strong[:, 1]]
    assert np.all(np.abs(rng - 896.0) < 3 * renderer.dr + 4.0)  # the near face at 896 m, within the range spread
    spokes = strong[:, 0]
    centre = spoke_of(45.0)
    offset = (spokes - centre + SPOKES // 2) % SPOKES - SPOKES // 2
    width_deg = (offset.max() - offset.min() + 1) * 360.0 / SPOKES
    assert abs(np.median(offset)) * 360.0 / SPOKES < 1.0  # centred on the bearing
    target_deg = np.degrees(40.0 / 900.0)  # the hull's own angular length
    assert target_deg < width_deg < target_deg + 3 * 5.2  # smeared by about the beamwidth
    far = echo[:, SAMPLES // 2 + 100 :]
    assert far.max() <= 3  # nothing but noise elsewhere far out


def test_a_berg_behind_a_tall_hull_is_hidden(tmp_path):
    berg = {"name": "berg", "kind": "iceberg", "position": latlon(0.0, 1200.0), "radius_m": 15, "height_m": 6}
    open_renderer, _ = radar_world(tmp_path, obstacles=[berg], environment={"sea_state": 0, "wind_speed_mps": 0}, name="open")
    hidden_renderer, _ = radar_world(tmp_path, obstacles=[hull(tmp_path, "wall", 0.0, 600.0, length=120.0, height=25.0), berg],
                                     environment={"sea_state": 0, "wind_speed_mps": 0}, name="hidden")
    berg_bins = slice(int(1170 / (1852 / SAMPLES)), int(1230 / (1852 / SAMPLES)))

    def peak(renderer):
        return int(renderer.render_revolution(0)["echo"][around(0.0, 4)][:, berg_bins].max())

    assert peak(open_renderer) >= 6
    assert peak(hidden_renderer) <= 2


def test_sea_clutter_falls_with_range_rises_with_sea_state_and_is_absent_behind_a_hull(tmp_path):
    means = {}
    for state in (2, 5):
        renderer, _ = radar_world(tmp_path, environment={"sea_state": state, "wind_speed_mps": 5}, name=f"ss{state}")
        e = renderer.render_revolution(0)["echo"].astype(float)
        means[state] = e.mean(axis=0)
    near, mid = slice(10, 40), slice(100, 160)
    assert means[5][near].mean() > means[5][mid].mean()  # falls with range
    assert means[5][mid].mean() > means[2][mid].mean()  # rises with sea state
    renderer, _ = radar_world(tmp_path, obstacles=[hull(tmp_path, "blocker", 90.0, 150.0, length=80.0, height=15.0)],
                              environment={"sea_state": 5, "wind_speed_mps": 12}, name="shadow")
    e = renderer.render_revolution(0)["echo"].astype(float)
    behind = e[around(90.0, 2)][:, int(250 / renderer.dr) : int(500 / renderer.dr)]
    beside = e[around(270.0, 2)][:, int(250 / renderer.dr) : int(500 / renderer.dr)]
    assert beside.mean() > 2 * behind.mean() + 0.5


def test_nrl_level_of_the_clutter_for_a_clean_geometry(tmp_path):
    renderer, _ = radar_world(tmp_path, environment={"sea_state": 3, "wind_speed_mps": 7}, name="nrl")
    # at the range where the grazing angle is 1 deg, the model's mean equals the NRL reference value
    # (-43.7 dB, REFERENCE.md) x cell area R theta dR sec(psi) through the radar equation, all written out here
    r = np.asarray(renderer.range_m, dtype=float)
    re = 4.0 / 3.0 * 6_371_000.0
    with np.errstate(divide="ignore", invalid="ignore"):
        psi = np.degrees(np.arcsin(4.0 / r + 16.0 / (2 * re * r) - r / (2 * re)))
    i = int(np.nanargmin(np.abs(psi - 1.0)))
    area = r[i] * np.radians(5.2) * max(renderer.dr, 2.5) / np.cos(np.radians(psi[i]))
    lam = 299_792_458.0 / 9.41e9
    kt0 = 10 ** ((-174.0 - 30.0) / 10)
    snr = (0.1 * (10 ** 2.3) ** 2 * lam**2 * 10 ** (-43.7 / 10) * area * 1e-3) / ((4 * np.pi) ** 3 * r[i] ** 4 * kt0 * 10 ** 0.5 * 10 ** 0.6)
    assert renderer._clutter_mean_db[i] == pytest.approx(10 * np.log10(snr), abs=0.5)


def test_rain_attenuates_far_echoes_by_the_itu_two_way_loss(tmp_path):
    target = hull(tmp_path, "far", 0.0, 1700.0, length=30.0, height=6.0)
    peaks_db, echoes = [], []
    for rain, name in ((0.0, "dry"), (50.0, "wet")):
        renderer, _ = radar_world(tmp_path, obstacles=[target], name=name,
                                  environment={"sea_state": 0, "wind_speed_mps": 0, "rain_mm_per_h": rain}, range_m=1852.0)
        rev = renderer.revolution(0)
        bins = slice(int(1680 / renderer.dr), int(1720 / renderer.dr))
        peaks_db.append(float(rev.snr_db[around(0.0, 2)][:, bins].max()))
    # 50 mm/h: 1.44 dB/km one way (REF 3.9), 2 x 1.7 km = 4.9 dB; the target dominates its cell
    assert peaks_db[0] - peaks_db[1] == pytest.approx(2 * 1.44 * 1.696, abs=0.3)


def test_a_small_target_beyond_the_horizon_is_invisible(tmp_path):
    buoy = {"name": "far_buoy", "kind": "buoy", "position": latlon(0.0, 9000.0)}
    renderer, _ = radar_world(tmp_path, obstacles=[buoy], environment={"sea_state": 0, "wind_speed_mps": 0},
                              name="horizon", range_m=11112.0)
    e = renderer.render_revolution(0)["echo"]
    bins = slice(int(8900 / renderer.dr), int(9100 / renderer.dr))
    assert e[around(0.0, 3)][:, bins].max() <= 2


def test_render_writes_sweeps_and_ppi_deterministically(tmp_path):
    _, path = radar_world(tmp_path, obstacles=[hull(tmp_path, "t", 30.0, 500.0)], environment={"sea_state": 3, "wind_speed_mps": 8})
    outs = []
    for name in ("a", "b"):
        out = tmp_path / name
        assert main(["render", str(path), "-o", str(out), "--sensors", "radar", "--no-progress"]) == 0
        outs.append(out)
    sweep = np.load(outs[0] / "radar" / "sweeps" / "000000.npz")
    assert sweep["echo"].shape == (SPOKES, SAMPLES) and sweep["echo"].dtype == np.uint8 and sweep["echo"].max() <= 15
    assert sweep["azimuth_deg"].shape == (SPOKES,) and sweep["time"].shape == (SPOKES,) and sweep["range_m"].shape == (SAMPLES,)
    assert np.allclose(np.diff(sweep["time"]), 2.5 / SPOKES)
    assert (outs[0] / "radar" / "ppi" / "000000.png").stat().st_size > 1000
    for rel in ("radar/sweeps/000000.npz", "radar/sweeps/000001.npz", "radar/ppi/000000.png"):
        assert (outs[0] / rel).read_bytes() == (outs[1] / rel).read_bytes()


# ---------------------------------------------------------------- raysim.sensors.radar_physics (analytic checks)

from raysim.sensors import radar_physics as rp  # noqa: E402


@pytest.mark.parametrize("ss, expected", [(0, -66.5), (2, -49.4), (3, -43.7), (5, -35.3)])
def test_nrl_check_values_hh(ss, expected):
    assert float(rp.nrl_sigma0_db(1.0, 9.41, ss, "HH")) == pytest.approx(expected, abs=0.5)


def test_radar_equation_example_and_geometry():
    assert float(rp.snr_db(1.0, 1852.0)) == pytest.approx(5.0, abs=1.0)
    assert float(rp.snr_db(1000.0, 1852.0)) == pytest.approx(35.0, abs=1.0)
    assert float(rp.horizon_m(3.0)) == pytest.approx(7100.0, rel=0.02)
    assert rp.grazing_angle_deg(3.0, [100.0, 1000.0]) == pytest.approx([1.7, 0.17], abs=0.02)
    assert np.isnan(rp.grazing_angle_deg(3.0, 20_000.0))
    assert float(rp.two_way_gain(2.6, 5.2)) == pytest.approx(0.25, rel=1e-6)  # -3 dB one way at the half width


def test_rain_tables_and_backscatter():
    assert rp.rain_attenuation_db_per_km([1, 4, 16, 50]) == pytest.approx([0.0093, 0.056, 0.33, 1.44], rel=1e-9)
    assert 0.056 < float(rp.rain_attenuation_db_per_km(8.0)) < 0.33
    assert float(rp.rain_attenuation_db_per_km(0.0)) == 0.0
    assert float(rp.rain_eta_m2_per_m3(4.0)) == pytest.approx(5e-7, rel=0.1)


def test_gamma_texture_has_unit_mean_and_the_shape_variance():
    g = rp.GammaQuantiles()
    z = np.random.default_rng(0).standard_normal(400_000)
    for nu in (0.5, 2.0, 10.0):
        x = g(z, np.full(z.size, np.log(nu)))
        assert x.mean() == pytest.approx(1.0, abs=0.02)
        assert x.var() == pytest.approx(1.0 / nu, rel=0.08)
    assert float(rp.ward_shape_nu(1e-6, 1.0)) == rp.NU_MIN and float(rp.ward_shape_nu(60.0, 1e6)) == rp.NU_MAX


def test_quantisation_uses_fixed_levels_not_the_spoke_maximum():
    weak = rp.quantise(np.array([0.0, 9.7, 12.7, 60.0]), 6.6, 3.0)
    assert weak.tolist() == [0, 1, 2, 15]
    assert rp.quantise(np.array([9.7]), 6.6, 3.0)[0] == 1  # alone in its spoke it is still level 1
    assert float(rp.stc_gain_db(np.array([10.0]), 20.0, 4.0, 100.0)[0]) == pytest.approx(-60.0)
    assert float(rp.stc_gain_db(np.array([1000.0]), 20.0, 4.0, 100.0)[0]) == 0.0


def test_a_low_wide_target_beyond_the_horizon_is_visible_only_on_a_flat_earth(tmp_path):
    # 1 m antenna: horizon 4.1 km; a 0.5 m tall target adds 2.9 km: hidden at 7.5 km over the 4/3 earth
    from raysim.sensors.radar import RadarParams

    target = {"name": "low", "kind": "mesh", "material": "steel_painted", "position": latlon(0.0, 7500.0),
              "mesh": box_file(tmp_path, "low", (4.0, 400.0, 1.5), (0.0, 0.0, -0.25)), "heading_deg": 0.0}
    data = scenario(tmp_path, obstacles=[target], environment={"sea_state": 0, "wind_speed_mps": 0}, duration=5.0)
    data["own_ship"]["mesh"] = box_file(tmp_path, "point", (0.2, 0.2, 0.2), (0, 0, -5))  # no hull in the way
    data["sensors"] = {"lidar": {"enabled": False},
                       "radar": {"spokes": SPOKES, "samples": SAMPLES, "range_m": 8000.0, "mount": {"z_m": 1.0}}}
    path = tmp_path / "curv.yaml"
    path.write_text(yaml.safe_dump(data))
    world = World(load_scenario(path))
    scene = CarrierScene(world.scene_objects(), sea_material=material_index("sea"))
    peaks = {}
    for curved in (True, False):
        # multipath off: at 0.5 m over the sea at 7.5 km it would null the echo (F^4 ~ -63 dB), hiding what is tested
        r = RadarRenderer(world, scene, RadarParams(earth_curvature=curved, multipath=False))
        bins = slice(int(7400 / r.dr), int(7600 / r.dr))
        peaks[curved] = int(r.render_revolution(0)["echo"][around(0.0, 3)][:, bins].max())
    assert peaks[False] >= 4
    assert peaks[True] <= 1

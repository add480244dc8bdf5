"""The radar's object echoes as an operator sees them: sidelobe arcs of strong targets, scintillation (issue 19)."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from raysim.materials import material_index
from raysim.scenario import load_scenario
from raysim.sensors import radar_physics as rp
from raysim.sensors.carrier import CarrierScene
from raysim.sensors.radar import RadarParams, RadarRenderer
from raysim.world import World
from tests.raysim.helpers import box_file, latlon, scenario

SPOKES, SAMPLES = 1024, 512


def renderer(tmp_path, name, obstacles=(), ships=(), environment=None, range_m=600.0, duration=5.0, **params):
    data = scenario(tmp_path, obstacles=obstacles, ships=ships, duration=duration,
                    environment=environment or {"sea_state": 0, "wind_speed_mps": 0})
    data["sensors"] = {"lidar": {"enabled": False},
                       "radar": {"spokes": SPOKES, "samples": SAMPLES, "range_m": range_m, "mount": {"z_m": 4.0}}}
    path = tmp_path / f"{name}.yaml"
    path.write_text(yaml.safe_dump(data))
    world = World(load_scenario(path))
    scene = CarrierScene(world.scene_objects(), sea_material=material_index("sea"))
    base = RadarParams.from_config(world.scenario.sensors.radar)
    return RadarRenderer(world, scene, RadarParams(**{**base.__dict__, **params}))


def wall(tmp_path, name, width_m, height_m, distance_m):
    """A steel plate standing on the sea, facing the radar due north: with its sea image a dihedral of
    RCS 16 pi (w h)^2 / lambda^2 (tests/raysim/test_radar.py checks that form within 2 dB)."""
    mesh = box_file(tmp_path, name, (width_m, 0.05, height_m), (0.0, 0.0, height_m / 2))
    return {"name": name, "kind": "mesh", "mesh": mesh, "material": "aluminium", "position": latlon(0.0, distance_m),
            "heading_deg": 90.0}


def wall_for_rcs(tmp_path, name, rcs_m2, distance_m, aspect=2.0):
    """A wall (width = aspect x height) whose dihedral RCS is ``rcs_m2``."""
    area = np.sqrt(rcs_m2 * rp.wavelength_m() ** 2 / (16 * np.pi))
    height = np.sqrt(area / aspect)
    return wall(tmp_path, name, aspect * height, height, distance_m)


def sidelobe_fraction(r, distance_m, lo_deg=6.0, hi_deg=20.0):
    """Share of the spokes lo-hi deg either side of north with video level >= 1 at the target's range (+-1 sample),
    and the peak object echo there, dB over noise."""
    rev = r.revolution(0)
    j = int(round(distance_m / r.dr))
    level = rev.echo[:, j - 1: j + 2].max(axis=1)
    offset_deg = (np.arange(SPOKES) * 360.0 / SPOKES + 180.0) % 360.0 - 180.0
    side = (np.abs(offset_deg) >= lo_deg) & (np.abs(offset_deg) <= hi_deg)
    peak_db = 10 * np.log10(rev.target_snr[:, j - 2: j + 3].max())
    return float(np.mean(level[side] >= 1)), peak_db


def test_a_strong_target_paints_its_sidelobe_arc_and_a_weak_one_does_not(tmp_path):
    fine = dict(resolve_m=0.1, elevation_max_deg=1.0, elevation_min_deg=-2.0)
    strong = renderer(tmp_path, "strong", obstacles=[wall_for_rcs(tmp_path, "ship", 1e4, 300.0)], **fine)
    berg = {"name": "berg", "kind": "iceberg", "position": latlon(0.0, 300.0), "radius_m": 3.0, "height_m": 1.5}
    weak = renderer(tmp_path, "weak", obstacles=[berg], **fine)
    strong_share, strong_db = sidelobe_fraction(strong, 300.0)
    weak_share, weak_db = sidelobe_fraction(weak, 300.0)
    # the targets are what they say: their peak echo is the radar equation's for 1e4 and 10 m^2 (within 3 dB); the
    # 10 m^2 target is a generated growler, 3 m in radius and 1.5 m high
    assert strong_db == pytest.approx(float(rp.snr_db(1e4, 300.0)), abs=3.0)
    assert weak_db == pytest.approx(float(rp.snr_db(10.0, 300.0)), abs=3.0)
    assert strong_share >= 0.8
    assert weak_share <= 0.2


def test_the_gaussian_beam_of_the_old_model_paints_no_arc_beyond_its_main_lobe(tmp_path):
    fine = dict(resolve_m=0.1, elevation_max_deg=1.0, elevation_min_deg=-2.0, sidelobe_db=None)
    strong = renderer(tmp_path, "gauss", obstacles=[wall_for_rcs(tmp_path, "ship", 1e4, 300.0)], **fine)
    # two-way -89 dB at 10 deg: the main lobe's skirt reaches 6-9 deg, nothing paints from 10 deg out
    assert sidelobe_fraction(strong, 300.0, 10.0, 20.0)[0] < 0.02


def test_a_ships_peak_echo_scintillates_from_scan_to_scan(tmp_path):
    # a 30 m ship crossing at 600 m in sea state 1: the aspect, the own antenna's height and the patches the rays
    # sample change between scans, and the coherent sum of the phases fluctuates (Swerling 1: 5.6 dB standard
    # deviation of the per-scan peak in dB; the steady single-bounce model of the first round spread 2.3-2.6 dB)
    ship = {"name": "ship", "length_m": 30.0, "speed_kn": 8.0,
            "waypoints": [latlon(-300.0, 600.0), latlon(300.0, 900.0)]}
    r = renderer(tmp_path, "scint", ships=[ship], environment={"sea_state": 1, "wind_speed_mps": 6}, range_m=1852.0,
                 duration=52.0)
    peaks_db = np.array([10 * np.log10(r.revolution(rev).target_snr.max()) for rev in range(20)])
    assert np.std(peaks_db) >= 4.0


def test_a_second_bounce_returning_from_off_the_beam_is_received_through_the_sidelobe(tmp_path, monkeypatch):
    """Two plates 200 m apart at bearings 0 and 45 deg, turned so that a ray going north bounces off the first to the
    second and from there straight back to the antenna (and the reverse path): the echo is placed on the incident
    ray's spoke at half the path (341 m), but returns from 45 deg off it, so it is received with the one-way gain
    there, |g_h(45 deg)|, not the main lobe's (a quay seen across a basin from another quay)."""
    def plate(name, east_m, north_m, heading_deg):
        mesh = box_file(tmp_path, name, (10.0, 0.05, 8.0), (0.0, 0.0, 4.0))
        return {"name": name, "kind": "mesh", "mesh": mesh, "material": "aluminium",
                "position": latlon(east_m, north_m), "heading_deg": heading_deg}

    def ghost_db(name):
        r = renderer(tmp_path, name, obstacles=[plate("a", 0.0, 200.0, 45.0), plate("b", 200.0, 200.0, 157.5)],
                     resolve_m=0.5, elevation_max_deg=1.0, elevation_min_deg=-1.0)
        j = int(round((200.0 + 200.0 + 200.0 * np.sqrt(2.0)) / 2.0 / r.dr))
        return 10 * np.log10(r.revolution(0).target_snr[:, j - 6: j + 7].max()), r.pattern

    received, pattern = ghost_db("through_sidelobe")
    from raysim.sensors import radar_targets
    monkeypatch.setattr(radar_targets.TargetEchoes, "_return_gain", lambda self, d, s: np.ones(len(d), complex))
    main_lobe, _ = ghost_db("as_if_main_lobe")
    sidelobe_db = 20 * np.log10(abs(pattern.horizontal_voltage(np.array(45.0))))
    assert sidelobe_db < -20.0
    assert received - main_lobe == pytest.approx(sidelobe_db, abs=2.0)

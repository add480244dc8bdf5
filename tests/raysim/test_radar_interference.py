"""Mutual radar interference (issue 19): dotted spiral arcs from another radar, and interference rejection."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from raysim.materials import material_index
from raysim.scenario import load_scenario
from raysim.sensors import radar_physics as phys
from raysim.sensors.carrier import CarrierScene
from raysim.sensors.radar import RadarRenderer
from raysim.sensors.radar_interference import OWN_SWEEP_REPETITION_S, one_way_pattern_db, reject
from raysim.world import World
from tests.raysim.helpers import box_file, latlon, scenario

SPOKES, SAMPLES, RANGE_M = 2048, 1024, 5556.0
#: The other radar's period: our sweep repetition plus 1 us, so its pulses walk 150 m per pulse.
DELTA_S = 1e-6
PRF_HZ = 1.0 / (OWN_SWEEP_REPETITION_S + DELTA_S)


def world(tmp_path, interference=(), rejection="off", obstacles=(), name="r"):
    data = scenario(tmp_path, obstacles=obstacles, environment={"sea_state": 0, "wind_speed_mps": 0.0}, duration=5.0)
    data["sensors"] = {"lidar": {"enabled": False},
                       "radar": {"spokes": SPOKES, "samples": SAMPLES, "range_m": RANGE_M, "mount": {"z_m": 4.0},
                                 "interference": list(interference), "interference_rejection": rejection}}
    path = tmp_path / f"{name}.yaml"
    path.write_text(yaml.safe_dump(data))
    w = World(load_scenario(path))
    return RadarRenderer(w, CarrierScene(w.scene_objects(), sea_material=material_index("sea")))


OTHER = {"position": latlon(2000.0, 0.0), "prf_hz": PRF_HZ, "rpm": 25.0, "level_db": 100.0}


def target(tmp_path):
    mesh = box_file(tmp_path, "post", (6.0, 6.0, 6.0), (0.0, 0.0, 2.0))
    return {"name": "post", "kind": "mesh", "mesh": mesh, "material": "steel_painted",
            "position": latlon(0.0, 3000.0), "heading_deg": 45.0}


def test_pattern_has_the_iec_sidelobe_floor():
    assert one_way_pattern_db(0.0, 5.2) == 0.0
    assert one_way_pattern_db(2.6, 5.2) == pytest.approx(-3.0, abs=0.02)
    assert one_way_pattern_db(8.0, 5.2) == -23.0 and one_way_pattern_db(-150.0, 5.2) == -30.0
    assert one_way_pattern_db(350.0, 5.2) == one_way_pattern_db(-10.0, 5.2)


def test_rejection_keeps_correlated_echoes_and_drops_single_spoke_dots():
    echo = np.zeros((8, 20), np.uint8)
    echo[2:6, 10] = 9  # an echo on 4 consecutive spokes
    echo[1, 3] = 12  # a dot on one spoke
    echo[4, 15], echo[5, 16] = 7, 7  # a walk of 1 sample between two spokes
    assert np.array_equal(reject(echo, "off"), echo)
    low, med, high = reject(echo, "low"), reject(echo, "medium"), reject(echo, "high")
    assert low[1, 3] == med[1, 3] == high[1, 3] == 0
    assert np.all(low[2:6, 10] == 9) and np.all(med[3:5, 10] == 9) and np.all(high[3:5, 10] == 9)
    assert med[2, 10] == 0 and med[5, 10] == 0  # medium: both neighbours must hold it
    assert low[4, 15] == 7 and low[5, 16] == 7 and high[4, 15] == 0  # within 1 sample: low keeps, high drops


def test_interference_draws_arcs_that_walk_at_the_analytic_rate(tmp_path):
    r = world(tmp_path, [OTHER])
    rev = r.revolution(0)
    dots = np.argwhere(rev.echo >= 8)
    assert dots.shape[0] > 100  # no target, no sea: every bright sample is interference
    # each pulse is one dash (its 12 m, about 2 samples): as many dashes as pulses land in our listening window
    bright = rev.echo >= 8
    starts = np.argwhere(bright[:, 1:] & ~bright[:, :-1])
    starts[:, 1] += 1
    listen = 2 * RANGE_M / phys.C_MPS / OWN_SWEEP_REPETITION_S
    expected = r.rev_s * PRF_HZ * listen
    assert 0.8 * expected < starts.shape[0] < 1.2 * expected
    # in time order, an arc's dashes move out by c/2 x delta per pulse (the two periods' difference)
    step_samples = 0.5 * phys.C_MPS * DELTA_S / r.dr
    d = np.diff(starts[:, 1])
    same_arc = (np.diff(starts[:, 0]) <= 2) & (d > 0)
    assert same_arc.sum() > 0.7 * starts.shape[0]
    assert np.all(np.abs(d[same_arc] - step_samples) <= 1.0)
    # so each arc is a spiral: range grows linearly with azimuth at step x pulses per spoke
    breaks = np.flatnonzero(~same_arc) + 1
    slopes = [np.polyfit(a[:, 0], a[:, 1], 1)[0] for a in np.split(starts, breaks) if len(a) >= 10]
    assert len(slopes) >= 2
    assert np.median(slopes) == pytest.approx(step_samples * r.rev_s / SPOKES * PRF_HZ, rel=0.1)


def test_rejection_removes_the_arcs_and_keeps_a_target(tmp_path):
    post = target(tmp_path)
    off = world(tmp_path, [OTHER], "off", [post], name="off").revolution(0)
    on = world(tmp_path, [OTHER], "medium", [post], name="on").revolution(0)
    clean = world(tmp_path, [], "off", [post], name="clean").revolution(0)
    away = np.ones(SPOKES, bool)
    away[np.r_[0:40, SPOKES - 40:SPOKES]] = False  # spokes without the target (at bearing 0)
    bright_off = int((off.echo[away] >= 8).sum())
    bright_on = int((on.echo[away] >= 8).sum())
    assert bright_off > 100 and bright_on <= 0.05 * bright_off
    bins = slice(int(2980 / off.range_m[1]), int(3020 / off.range_m[1]))
    near = np.r_[0:5, SPOKES - 5:SPOKES]
    assert int(clean.echo[near][:, bins].max()) >= 5
    assert int(on.echo[near][:, bins].max()) == int(clean.echo[near][:, bins].max())


def test_no_interference_by_default(tmp_path):
    r = world(tmp_path)
    assert r.cfg.interference == () and r.cfg.interference_rejection == "off"
    assert not r.interference.active

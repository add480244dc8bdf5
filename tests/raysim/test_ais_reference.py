"""A transponder's reference point (its GNSS antenna) off the hull's centre: the positions it reports and the
dimensions A-D of its static data (ITU-R M.1371-5, message 5 "overall dimension/reference for position")."""

from __future__ import annotations

import numpy as np
import pytest
from pyais import decode, encode_dict

from raysim.cli import main
from raysim.pose import yaw_from_heading_deg
from tests.raysim.test_ais import FRAME, scenario_dict, ship, transmissions, world_of

QUIET = {name: 0.0 for name in (
    "position_measure_variance_m2", "cog_measure_variance_deg2", "track_measure_variance_deg2",
    "rot_measure_variance_deg2_pr_min2", "sog_measure_variance_knots2", "position_bias_variance_m2",
    "cog_bias_variance_deg2", "track_bias_variance_deg2", "rot_bias_variance_deg2_pr_min2", "sog_bias_variance_knots2")}


def _antenna_and_reports(write_scenario, course_deg, ais_class="A", reference=(100.0, 5.0)):
    data = scenario_dict([ship("aft_bridge", 257000501, 10.0, course_deg=course_deg, length_m=120.0,
                               ais_class=ais_class, reference_point_m=list(reference))], 120.0, noise=QUIET)
    world = world_of(write_scenario, data, f"ref_{ais_class}_{course_deg:g}.yaml")
    obj, messages = transmissions(world, "aft_bridge")
    return world, obj, messages


@pytest.mark.parametrize("course_deg", [90.0, 0.0, 225.0])
def test_reported_positions_are_the_antennas_not_the_centres(write_scenario, course_deg):
    world, obj, messages = _antenna_and_reports(write_scenario, course_deg)
    reports = [m for m in messages if m.data["msg_type"] in (1, 3)]
    t = np.array([m.t_s for m in reports])
    centre = obj.motion.poses(t).position_m[:, :2]  # a generated hull's centre is its body origin
    psi = np.radians(course_deg)
    forward, port = np.array([np.sin(psi), np.cos(psi)]), np.array([-np.cos(psi), np.sin(psi)])
    # 120 m long: 100 m from the bow is 40 m aft of the centre; 5 m from the port side is beam / 2 - 5 m to port
    antenna = centre - 40.0 * forward + (obj.beam_m / 2.0 - 5.0) * port
    x, y = FRAME.to_local(np.array([m.data["lat"] for m in reports]), np.array([m.data["lon"] for m in reports]))
    np.testing.assert_allclose(np.stack([x, y], axis=1), antenna, atol=0.3)  # 1/10000 min of arc: 0.19 m
    assert np.allclose(obj.motion.poses(t).yaw_rad, yaw_from_heading_deg(course_deg))


@pytest.mark.parametrize("ais_class, msg_type", [("A", 5), ("B", 24)])
def test_static_data_place_the_reference_point(write_scenario, ais_class, msg_type):
    world, obj, messages = _antenna_and_reports(write_scenario, 90.0, ais_class)
    static = [m.data for m in messages if m.data["msg_type"] == msg_type and m.data.get("partno", 1) == 1]
    assert static
    decoded = decode(*encode_dict(static[0], talker_id="AI", radio_channel="A"))
    assert (decoded.to_bow, decoded.to_stern, decoded.to_port) == (100, 20, 5)
    assert decoded.to_starboard == round(obj.beam_m - 5.0)


def test_without_a_reference_point_the_antenna_stands_amidships(write_scenario):
    data = scenario_dict([ship("plain", 257000502, 10.0, length_m=120.0)], 60.0, noise=QUIET)
    world = world_of(write_scenario, data, "plain.yaml")
    obj, messages = transmissions(world, "plain")
    reports = [m for m in messages if m.data["msg_type"] in (1, 3)]
    t = np.array([m.t_s for m in reports])
    x, y = FRAME.to_local(np.array([m.data["lat"] for m in reports]), np.array([m.data["lon"] for m in reports]))
    np.testing.assert_allclose(np.stack([x, y], axis=1), obj.motion.poses(t).position_m[:, :2], atol=0.3)
    static = next(m.data for m in messages if m.data["msg_type"] == 5)
    assert static["to_bow"] == static["to_stern"] == 60


@pytest.mark.parametrize("reference, expected", [
    ([130.0, 5.0], "ships[0].ais.reference_point_m: [130, 5] m lies off the hull"),
    ([10.0, -1.0], "ships[0].ais.reference_point_m[1]"),
])
def test_a_reference_point_off_the_hull_is_refused(write_scenario, tmp_path, capsys, reference, expected):
    data = scenario_dict([ship("bad", 257000503, 10.0, length_m=120.0, reference_point_m=reference)], 60.0)
    path = write_scenario(data, "bad_reference.yaml")
    assert main(["render", str(path), "-o", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert expected in err and "Traceback" not in err
    assert not (tmp_path / "out").exists()

"""AIS reports moved from the reference point (the GNSS antenna) to the hull's centre: tdm.frontend.ais_reference."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tdm.ais_tracker import AisTracker, AisTrackerConfig
from tdm.detections import AisReport, ReadStats
from tdm.frames import EnuFrame
from tdm.frontend.ais import read_ais
from tdm.frontend.ais_reference import COG_AS_HEADING_MIN_SOG_MPS, centre_offsets, centred_reports

from tests.tdm.test_frontend_ais import START, tagged, type1, vdm, write_lines

NAN = float("nan")


def _offsets(heading, cog, sog, a, b, c, d):
    offset, extra = centre_offsets(*(np.array([v], dtype=float) for v in (heading, cog, sog, a, b, c, d)))
    return offset[0], float(extra[0])


@pytest.mark.parametrize("heading_deg, expected_m", [
    (90.0, [40.0, -5.0]),  # heading east: 40 m ahead is east, 5 m to starboard is south
    (0.0, [5.0, 40.0]),  # heading north: ahead is north, starboard is east
    (180.0, [-5.0, -40.0]),
    (225.0, [(-40.0 - 5.0) / math.sqrt(2.0), (-40.0 + 5.0) / math.sqrt(2.0)]),  # starboard of south-west: north-west
])
def test_the_centre_lies_half_the_difference_of_the_dimensions_from_the_antenna(heading_deg, expected_m):
    # a 120 x 20 m ship with its antenna 100 m from the bow and 5 m from the port side: its centre is 40 m ahead
    # of the antenna and 5 m to starboard
    offset, extra = _offsets(heading_deg, NAN, NAN, 100.0, 20.0, 5.0, 15.0)
    np.testing.assert_allclose(offset, expected_m, atol=1e-9)
    assert extra == 0.0


def test_the_course_stands_in_for_a_missing_heading_only_when_the_ship_makes_way():
    offset, extra = _offsets(NAN, 90.0, COG_AS_HEADING_MIN_SOG_MPS + 1.0, 100.0, 20.0, 5.0, 15.0)
    np.testing.assert_allclose(offset, [40.0, -5.0], atol=1e-9)
    assert extra == 0.0
    offset, extra = _offsets(NAN, 90.0, COG_AS_HEADING_MIN_SOG_MPS / 2.0, 100.0, 20.0, 5.0, 15.0)
    np.testing.assert_array_equal(offset, [0.0, 0.0])
    assert extra == pytest.approx((40.0 ** 2 + 5.0 ** 2) / 2.0)  # uniform on the circle of radius 40.3 m


def test_dimensions_without_a_reference_point_spread_it_over_the_hull():
    # ITU-R M.1371-5: reference point not available, dimensions available -> A = C = 0, B and D the dimensions
    offset, extra = _offsets(45.0, NAN, NAN, 0.0, 120.0, 0.0, 20.0)
    np.testing.assert_array_equal(offset, [0.0, 0.0])
    assert extra == pytest.approx((120.0 ** 2 + 20.0 ** 2) / 24.0)


@pytest.mark.parametrize("dims", [(0.0, 0.0, 0.0, 0.0), (NAN, NAN, NAN, NAN), (60.0, 60.0, 10.0, 10.0)])
def test_no_dimensions_or_an_antenna_amidships_leave_the_report_as_it_is(dims):
    offset, extra = _offsets(30.0, 30.0, 5.0, *dims)
    np.testing.assert_array_equal(offset, [0.0, 0.0])
    assert extra == 0.0


def _report(t_s, mmsi=257000001, heading_deg=90.0):
    return AisReport(t_s, mmsi, np.array([100.0, 200.0]), 90.0, 5.0, heading_deg, 0.0, 1)


def test_only_static_data_received_before_a_report_move_it_and_the_latest_holds():
    references = {257000001: [(10.0, 100.0, 20.0, 10.0, 10.0), (30.0, 80.0, 40.0, 10.0, 10.0)],
                  257000099: [(0.0, 100.0, 20.0, 10.0, 10.0)]}  # another ship's
    reports = [_report(5.0), _report(10.0), _report(20.0), _report(40.0), _report(50.0, mmsi=257000002)]
    out = centred_reports(reports, references)
    east = [r.position_m[0] for r in out]
    assert east == pytest.approx([100.0, 140.0, 140.0, 120.0, 100.0])
    assert out[0] is reports[0] and out[-1] is reports[-1]  # not moved: the same objects
    assert all(r.position_m[1] == pytest.approx(200.0) for r in out)
    assert reports[1].position_m[0] == 100.0  # the input is left as it was


def test_read_ais_puts_a_ship_with_its_antenna_aft_at_its_centre(tmp_path):
    frame = EnuFrame(59.44, 10.47)
    static5 = {"msg_type": 5, "mmsi": 257000009, "shipname": "AFT BRIDGE", "ship_type": 70, "to_bow": 100,
               "to_stern": 20, "to_port": 10, "to_starboard": 10, "epfd": 1, "hour": 24, "minute": 60}
    lines = [tagged(int(START) + 5, vdm(type1(heading=90))[0])]
    lines += [tagged(int(START) + 10, s) for s in vdm(static5, seq_id=1)]
    lines += [tagged(int(START) + 15, vdm(type1(heading=90))[0]),
              tagged(int(START) + 20, vdm(type1(heading=511, course=90.0, speed=10.0))[0]),  # COG stands in
              tagged(int(START) + 25, vdm(type1(heading=511, course=90.0, speed=0.5))[0])]  # drifting: not moved
    reports, static = read_ais(write_lines(tmp_path / "ais.nmea", lines), frame, START, ReadStats())
    antenna = np.array(frame.to_enu(59.44, 10.48), dtype=float).ravel()
    assert (static[257000009].to_bow_m, static[257000009].to_stern_m) == (100.0, 20.0)
    np.testing.assert_allclose(reports[0].position_m, antenna, atol=0.2)  # before the static data
    np.testing.assert_allclose(reports[1].position_m, antenna + [40.0, 0.0], atol=0.2)
    np.testing.assert_allclose(reports[2].position_m, antenna + [40.0, 0.0], atol=0.2)
    np.testing.assert_allclose(reports[3].position_m, antenna, atol=0.2)
    assert [r.position_extra_var_m2 for r in reports] == pytest.approx([0.0, 0.0, 0.0, 40.0 ** 2 / 2.0])


def test_the_tracker_takes_an_unplaced_reference_point_as_noise():
    config = AisTrackerConfig()
    plain, unplaced = AisTracker(config), AisTracker(config)
    report = _report(1.0)
    plain.process(report)
    unplaced.process(AisReport(**{**report.__dict__, "position_extra_var_m2": 800.0}))
    var_plain = plain.tracks[report.mmsi].p[0, 0]
    var_unplaced = unplaced.tracks[report.mmsi].p[0, 0]
    assert var_plain == pytest.approx(config.position_var_m2)
    assert var_unplaced == pytest.approx(config.position_var_m2 + 800.0)


def test_the_first_report_placed_at_the_centre_moves_the_track_there():
    """A report sent before the static data is of the antenna; the next one, placed 40 m ahead at the centre, moves
    the track by that much at once, where a filter fed the step would take it for motion and lag."""
    tracker = AisTracker(AisTrackerConfig())
    antenna = AisReport(0.0, 257000001, np.array([0.0, 0.0]), 90.0, 5.0, 90.0, 0.0, 1)
    tracker.process(antenna)
    centred = AisReport(10.0, 257000001, np.array([50.0 + 40.0, 0.0]), 90.0, 5.0, 90.0, 0.0, 1,
                        centre_offset_m=np.array([40.0, 0.0]))
    tracker.process(centred)
    track = tracker.tracks[257000001]
    assert track.x[0] == pytest.approx(90.0, abs=0.5)
    assert track.x[3] == pytest.approx(5.0, abs=0.2)  # the speed is not thrown by the step
    tracker.process(AisReport(20.0, 257000001, np.array([100.0 + 40.0, 0.0]), 90.0, 5.0, 90.0, 0.0, 1,
                              centre_offset_m=np.array([40.0, 0.0])))
    assert tracker.tracks[257000001].x[0] == pytest.approx(140.0, abs=0.5)  # moved once, not again

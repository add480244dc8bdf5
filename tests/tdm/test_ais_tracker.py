"""The AIS's tracker on synthetic reports with known truth."""

import numpy as np
import pytest

from groundfloor.units import KNOT_MPS

from tdm import ekf
from tdm.ais_tracker import AisTracker, AisTrackerConfig
from tdm.detections import AisReport


def test_ais_tracks_are_kept_by_mmsi():
    tracker = AisTracker(AisTrackerConfig())
    for k in range(10):
        t = 10.0 * k
        for mmsi, north in ((257000001, 0.0), (257000002, 500.0)):
            tracker.process(AisReport(t, mmsi, np.array([5.0 * t, north]), 90.0, 5.0, 90.0, 0.0, 1))
    tracks = {tr.mmsi: tr for tr in tracker.confirmed_tracks()}
    assert set(tracks) == {257000001, 257000002}
    assert tracks[257000002].x[ekf.N] == pytest.approx(500.0, abs=2.0)
    assert tracks[257000001].x[ekf.U] == pytest.approx(5.0, abs=0.2)
    tracker.expire(90.0 + 201.0)
    assert tracker.confirmed_tracks() == []


@pytest.mark.parametrize("range_m", [700.0, 1700.0, 5000.0, 10000.0])
def test_an_ais_track_starts_at_its_first_report(range_m):
    """Not pulled toward the ENU origin by a prior there (0.948 x the report before: 37 m off at 700 m)."""
    tracker = AisTracker(AisTrackerConfig())
    position = np.array([range_m * np.sin(np.radians(40.0)), range_m * np.cos(np.radians(40.0))])
    tracker.process(AisReport(3.0, 257000009, position, 120.0, 6.0, 121.0, 0.0, 1))
    (track,) = tracker.confirmed_tracks()
    assert np.hypot(*(track.x[:2] - position)) < 0.5
    assert np.degrees(track.x[2]) % 360.0 == pytest.approx(120.0)
    assert track.x[3] == pytest.approx(6.0)
    assert track.p[0, 0] == pytest.approx(AisTrackerConfig().position_var_m2)  # the report's own variance


def test_a_ship_at_anchor_or_moored_holds_its_position_between_reports():
    """A Class A ship's transponder reads 1.3 kn along its heading (GNSS noise); held, it reports every 3 minutes.

    Dead-reckoned at 1.3 kn (0.67 m/s) it would be 120 m off 3 minutes on. Held, its speed is the product of
    N(0.67, 0.40^2) and N(0, sigma^2) m/s: 0.67 sigma^2 / (sigma^2 + 0.158), 0.04 m/s at anchor (sigma 0.1 m/s)
    and 0.0004 m/s moored (sigma 0.01 m/s).
    """
    sog = 1.3 * KNOT_MPS
    sog_var = AisTrackerConfig().sog_var_kn2 * KNOT_MPS**2
    free = AisTrackerConfig(anchored_speed_sigma_mps=None, moored_speed_sigma_mps=None)
    found = {}
    for name, status, config in (("anchor", 1, AisTrackerConfig()), ("moored", 5, AisTrackerConfig()),
                                 ("free", 5, free)):
        tracker = AisTracker(config)
        tracker.process(AisReport(0.0, 257000700, np.array([200.0, 300.0]), 64.0, sog, 64.0, 0.0, 1, nav_status=status))
        track = tracker.tracks[257000700]
        x, p = track.predicted(179.0)
        found[name] = (track.x[ekf.U], np.hypot(*(x[:2] - [200.0, 300.0])), np.sqrt(np.trace(p[:2, :2])))
    assert found["anchor"][0] == pytest.approx(sog * 0.01 / (0.01 + sog_var))
    assert found["moored"][0] == pytest.approx(sog * 1e-4 / (1e-4 + sog_var))
    assert found["anchor"][1] < 10.0 and found["moored"][1] < 0.5 and found["free"][1] > 100.0  # drift, m
    # the uncertainty 3 minutes on: a ship swinging at anchor, one made fast, one under way
    assert found["moored"][2] < 6.0 < found["anchor"][2] < 60.0 < 600.0 < found["free"][2]
    # under way (status 0), a Class B report (no status: 15), or over 3 kn whatever the status says (a status
    # left at anchor by a ship under way), the reported speed is the speed
    for status, sog_mps in ((0, sog), (15, sog), (1, 4.0 * KNOT_MPS), (5, 4.0 * KNOT_MPS)):
        tracker = AisTracker(AisTrackerConfig())
        tracker.process(AisReport(0.0, 257000701, np.zeros(2), 64.0, sog_mps, 64.0, 0.0, 1, nav_status=status))
        assert tracker.tracks[257000701].x[ekf.U] == pytest.approx(sog_mps)
        assert tracker.tracks[257000701].process.speed_m2_per_s3 == AisTrackerConfig().process.speed_m2_per_s3


def report(t_s, status, sog_kn, position_m=(200.0, 300.0)):
    return AisReport(t_s, 257000800, np.asarray(position_m, dtype=float), 64.0, sog_kn * KNOT_MPS, 64.0, 0.0, 1,
                     nav_status=status)


def test_a_held_ship_stays_held_from_report_to_report_and_one_getting_under_way_is_tracked_as_such():
    tracker = AisTracker(AisTrackerConfig())
    tracker.process(report(0.0, 5, 1.3))
    tracker.process(report(180.0, 5, 0.9, (200.5, 300.2)))  # moored, 3 minutes on: the update path
    track = tracker.tracks[257000800]
    held_noise = track.process
    assert held_noise.speed_m2_per_s3 == pytest.approx(0.01**2 / 180.0)
    assert abs(track.x[ekf.U]) < 0.01 and track.p[ekf.U, ekf.U] < 0.01**2
    assert np.hypot(*(track.x[:2] - [200.5, 300.2])) < 1.0
    # it casts off: status 0 at 6 kn, reports every 10 s. Its speed is then as unknown as a new track's and the
    # step from the moored report is predicted as a ship under way, so the first report under way sets its speed
    under_way = []
    for k in range(1, 4):
        east = 200.5 + 6.0 * KNOT_MPS * 10.0 * k * np.sin(np.radians(64.0))
        north = 300.2 + 6.0 * KNOT_MPS * 10.0 * k * np.cos(np.radians(64.0))
        tracker.process(report(180.0 + 10.0 * k, 0, 6.0, (east, north)))
        under_way.append(track.x[ekf.U])
    assert track.process == AisTrackerConfig().process
    assert under_way[0] > 0.8 * 6.0 * KNOT_MPS
    assert under_way[-1] == pytest.approx(6.0 * KNOT_MPS, abs=0.3)
    # anchored again: held from that report on
    tracker.process(report(230.0, 1, 0.4, (east, north)))
    assert track.process.speed_m2_per_s3 == pytest.approx(0.1**2 / 180.0)
    assert abs(track.x[ekf.U]) < 0.1


def test_a_held_ship_without_a_sog_is_at_speed_zero_and_a_zero_sigma_is_refused():
    tracker = AisTracker(AisTrackerConfig())
    tracker.process(AisReport(0.0, 257000900, np.zeros(2), float("nan"), float("nan"), float("nan"), float("nan"), 1,
                              nav_status=1))
    track = tracker.tracks[257000900]
    assert track.x[ekf.U] == 0.0 and track.p[ekf.U, ekf.U] == pytest.approx(0.1**2)
    with pytest.raises(ValueError, match="moored_speed_sigma_mps must be > 0"):
        AisTrackerConfig(moored_speed_sigma_mps=0.0)


"""The AIS's tracker on synthetic reports with known truth."""

import numpy as np
import pytest

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

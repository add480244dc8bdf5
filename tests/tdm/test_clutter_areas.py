"""tdm.clutter_areas: the running map of free radar plots, and the tracker asking more of a track in clutter."""

import numpy as np
import pytest

from tdm.clutter_areas import ClutterAreas
from tdm.tracker import PositionTracker, TrackerConfig

from .test_tracker import scan


def test_the_map_averages_each_cells_free_plots_over_its_memory():
    areas = ClutterAreas(range_m=1000.0, cell_range_m=200.0, cell_deg=30.0, memory_scans=20.0, plots_per_scan=0.1)
    assert areas.rate.shape == (5, 12)
    own = np.array([100.0, -50.0])
    # two plots about 500 m off at compass 99 deg (range bin 2, sector 3), one beyond the map
    plots = own + np.array([[500.0, -80.0], [505.0, -85.0], [1500.0, 0.0]])
    areas.update(own, plots)
    assert areas.rate[2, 3] == pytest.approx(2.0 / 20.0) and areas.rate.sum() == pytest.approx(0.1)
    assert not areas.cluttered(own, plots[:1])[0]  # one scan: over the rate, but too soon to tell
    for _ in range(200):
        areas.update(own, plots)
    assert areas.rate[2, 3] == pytest.approx(2.0, rel=1e-4)  # the running mean reaches the count a scan
    probe = own + np.array([[450.0, -100.0], [-450.0, 0.0], [0.0, 450.0], [1500.0, 0.0]])
    assert areas.cluttered(own, probe).tolist() == [True, False, False, False]
    # the map is about the own ship: moved 1 km north, the same world point lies in another cell
    assert not areas.cluttered(own + [0.0, 1000.0], probe[:1])[0]
    for _ in range(100):  # quiet scans: the cell fades under the rate
        areas.update(own, np.zeros((0, 2)))
    assert not areas.cluttered(own, probe[:1])[0]
    with pytest.raises(ValueError):
        ClutterAreas(1000.0, 0.0, 30.0, 20.0, 0.1)


def _confirmed_after(cfg: TrackerConfig, strength_db: float, scans: int, target_at, clutter_at) -> bool:
    """A still target's plots (one a scan, 2.5 s apart, after 40 scans of clutter elsewhere or there)."""
    tracker = PositionTracker("radar", cfg)
    rng = np.random.default_rng(3)
    for k in range(40):  # clutter: three plots a scan scattered over 100 m about a point, never twice alike
        d = scan(2.5 * k, clutter_at + rng.uniform(-50.0, 50.0, (3, 2)))
        d.strength_db = np.full(3, 14.0)
        tracker.process(d, np.zeros(2))
    for k in range(40, 40 + scans):
        d = scan(2.5 * k, [target_at])
        d.strength_db = np.array([strength_db])
        tracker.process(d, np.zeros(2))
    near = [t for t in tracker.confirmed_tracks() if np.hypot(*(t.x[:2] - target_at)) < 10.0]
    return bool(near)


def test_in_a_clutter_area_a_track_needs_more_hits_and_elsewhere_as_many_as_before():
    base = dict(confirm_m=3, confirm_n=4, coast_s=10.0, position_floor_m2=0.0, max_range_m=1852.0,
                weak_below_db=13.0, strong_from_db=15.0)
    cfg = TrackerConfig(**base, clutter_extra_hits=1.5, clutter_plots_per_scan=0.1)
    upwind = np.array([650.0, 50.0])  # the clutter's cell: 600-800 m, compass 60-90 deg
    target_in = np.array([640.0, 80.0])
    target_out = np.array([-640.0, 80.0])  # the same range, the other side
    # strong plots (1.5 hits): two confirm in quiet water, three in the clutter
    assert _confirmed_after(cfg, 20.0, 2, target_out, upwind)
    assert not _confirmed_after(cfg, 20.0, 2, target_in, upwind) and _confirmed_after(cfg, 20.0, 3, target_in, upwind)
    # plots of middling strength (1 hit): three confirm in quiet water, never in the clutter (4 of 4.5)
    assert _confirmed_after(cfg, 14.0, 3, target_out, upwind)
    assert not _confirmed_after(cfg, 14.0, 6, target_in, upwind)
    # without the map the clutter changes nothing
    assert _confirmed_after(TrackerConfig(**base), 20.0, 2, target_in, upwind)

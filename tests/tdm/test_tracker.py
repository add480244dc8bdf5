"""Per-sensor trackers on synthetic detections with known truth."""

import itertools
from dataclasses import replace

import numpy as np
import pytest

from tdm import ekf
from tdm.detections import Detections
from tdm.tracker import PositionTracker, TrackerConfig


def scan(t, positions, sigma=1.0, area=50.0):
    positions = np.atleast_2d(np.asarray(positions, dtype=float)).reshape(-1, 2)
    n = len(positions)
    d = Detections.empty("radar", t)
    d.time_s = np.full(n, float(t))
    d.position_m = positions
    d.position_cov_m2 = np.tile(np.eye(2) * sigma**2, (n, 1, 1))
    d.cross_section_m2 = np.full(n, area)
    d.length_m = d.width_m = d.orientation_deg = d.range_m = np.zeros(n)
    d.height_m = np.full(n, np.nan)
    d.n_cells = np.ones(n, dtype=np.int64)
    return d


CFG = TrackerConfig(confirm_m=3, confirm_n=5, coast_s=5.0, position_floor_m2=0.0, max_range_m=1e4)


def test_a_straight_mover_is_confirmed_and_its_course_and_speed_found():
    rng = np.random.default_rng(0)
    tracker = PositionTracker("radar", CFG)
    course = np.radians(60.0)
    for k in range(60):
        t = k * 1.0
        truth = 5.0 * t * np.array([np.sin(course), np.cos(course)]) + [100, 200]
        tracker.process(scan(t, truth + rng.normal(size=2)), np.zeros(2))
        if k == 1:
            assert not tracker.confirmed_tracks()  # 2 hits: not yet 3 of 5
    (track,) = tracker.confirmed_tracks()
    assert track.x[ekf.U] == pytest.approx(5.0, abs=0.3)
    assert np.degrees(ekf.wrap_pi(track.x[ekf.PSI] - course)) == pytest.approx(0.0, abs=3.0)
    assert track.track_id == 1  # one track all along


def test_gnn_keeps_two_close_targets_apart():
    rng = np.random.default_rng(1)
    tracker = PositionTracker("radar", CFG)
    for k in range(40):
        t = float(k)
        a = np.array([0.0 + 4.0 * t, 0.0])  # eastbound
        b = np.array([0.0 + 4.0 * t, 30.0])  # parallel, 30 m north
        dets = np.array([b, a]) + rng.normal(size=(2, 2)) * 1.0
        tracker.process(scan(t, dets[rng.permutation(2)]), np.zeros(2))
    tracks = sorted(tracker.confirmed_tracks(), key=lambda tr: tr.x[ekf.N])
    assert len(tracks) == 2
    assert tracks[0].x[ekf.N] == pytest.approx(0.0, abs=3.0)
    assert tracks[1].x[ekf.N] == pytest.approx(30.0, abs=3.0)


def test_tracks_are_deleted_after_coasting_and_clutter_is_never_confirmed():
    rng = np.random.default_rng(2)
    tracker = PositionTracker("radar", CFG)
    for k in range(20):
        clutter = rng.uniform(-1000, 1000, size=(3, 2))  # fresh false plots every scan
        pts = np.vstack([[[500.0, 500.0]], clutter]) if k < 10 else clutter
        tracker.process(scan(float(k), pts), np.zeros(2))
        if k == 9:
            assert len(tracker.confirmed_tracks()) == 1
    assert tracker.confirmed_tracks() == []  # the object left 10 s ago (> coast 5 s); clutter never confirmed


def test_strong_plots_confirm_in_two_scans_and_marginal_ones_need_more():
    cfg = TrackerConfig(confirm_m=3, confirm_n=4, coast_s=10.0, position_floor_m2=0.0, max_range_m=1e4,
                        weak_below_db=13.0, strong_from_db=16.0)

    def confirmed_after(strength_db, scans):
        tracker = PositionTracker("radar", cfg)
        for k in range(scans):
            d = scan(2.5 * k, [[600.0, 0.0]])
            d.strength_db = np.array([strength_db])
            tracker.process(d, np.zeros(2))
        return bool(tracker.confirmed_tracks())

    assert confirmed_after(20.0, 2) and not confirmed_after(20.0, 1)  # 1.5 + 1.5
    assert confirmed_after(14.0, 3) and not confirmed_after(14.0, 2)  # 1 + 1 + 1
    assert not confirmed_after(11.0, 4)  # 4 x 0.5: barely over the clutter, never in 4 scans
    assert confirmed_after(11.0, 6) is False  # nor later: only the last 4 scans count
    plain = PositionTracker("radar", TrackerConfig(confirm_m=3, confirm_n=4, max_range_m=1e4))
    for k in range(3):  # without strengths (LiDAR) every hit counts 1
        plain.process(scan(float(k), [[600.0, 0.0]]), np.zeros(2))
    assert plain.confirmed_tracks()


def test_a_strong_plot_narrower_than_the_beam_counts_as_a_weak_hit():
    cfg = TrackerConfig(confirm_m=3, confirm_n=4, coast_s=10.0, position_floor_m2=0.0, max_range_m=1e4,
                        weak_below_db=13.0, strong_from_db=15.0, min_beam_fill=0.5)

    def confirmed_after(beam_fill, scans):
        tracker = PositionTracker("radar", cfg)
        for k in range(scans):
            d = scan(2.5 * k, [[600.0, 0.0]])
            d.strength_db, d.beam_fill = np.array([25.0]), np.array([beam_fill])
            tracker.process(d, np.zeros(2))
        return bool(tracker.confirmed_tracks())

    assert confirmed_after(1.0, 2)  # an echo through the antenna: 1.5 + 1.5
    assert not confirmed_after(0.2, 4)  # a sea spike, however strong: 4 x 0.5
    unchecked = TrackerConfig(**{**cfg.__dict__, "min_beam_fill": None})
    tracker = PositionTracker("radar", unchecked)
    for k in range(2):
        d = scan(2.5 * k, [[600.0, 0.0]])
        d.strength_db, d.beam_fill = np.array([25.0]), np.array([0.2])
        tracker.process(d, np.zeros(2))
    assert tracker.confirmed_tracks()


def test_misses_outside_the_sensor_range_do_not_count():
    cfg = TrackerConfig(confirm_m=3, confirm_n=5, coast_s=100.0, position_floor_m2=0.0, max_range_m=100.0)
    tracker = PositionTracker("lidar", cfg)
    for k in range(3):
        tracker.process(scan(float(k), [[90.0, 0.0]]), np.zeros(2))
    (track,) = tracker.confirmed_tracks()
    hits = list(track.hits)
    tracker.process(scan(3.0, np.zeros((0, 2))), np.array([-50.0, 0.0]))  # now 140 m away: out of view
    assert list(track.hits) == hits


def test_a_track_in_the_shadow_of_a_nearer_detection_records_no_miss_with_shadow_misses():
    """A tentative track behind a nearer object (its plot 20 m across, 1.1 deg off the plot's bearing, within the
    2.9 deg its half width covers at 200 m) gets no plot for three scans: with ``shadow_misses`` those scans are not
    misses, and it is confirmed on its next hit; without, the three misses end it (3 of 5 can no longer be reached)
    and the object starts again."""
    front, back = [0.0, 200.0], [6.0, 300.0]
    outcomes = {}
    for shadow in (False, True):
        cfg = replace(CFG, coast_s=20.0, shadow_misses=shadow)
        tracker = PositionTracker("radar", cfg)
        for k in range(2):
            tracker.process(scan(float(k), [front, back]), np.zeros(2))
        for k in range(2, 5):  # the back object hidden
            d = scan(float(k), [front])
            d.length_m, d.width_m = np.array([20.0]), np.array([20.0])
            tracker.process(d, np.zeros(2))
        behind = min(tracker.tracks, key=lambda t: abs(t.x[1] - back[1]))
        outcomes[shadow] = (list(behind.hits), behind.created_s)
        for k in range(5, 6):
            tracker.process(scan(float(k), [front, back]), np.zeros(2))
        outcomes[shadow] += (any(t.confirmed and abs(t.x[1] - back[1]) < 5.0 for t in tracker.tracks),)
    assert outcomes[True][:2] == ([1.0, 1.0], 0.0)  # no misses recorded behind the front object
    assert outcomes[True][2]  # the third hit confirms it
    assert not outcomes[False][2]  # the misses ended it: a new track on the back object, not yet confirmed


def test_a_track_reports_the_uncertainty_of_the_centre_behind_the_side_it_sees():
    """extent_sigma_fraction f: the reported position covariance grows by (f L)^2 per axis, the filter does not."""
    dets = scan(0.0, [[100.0, 200.0]], sigma=1.0)
    dets.length_m = np.array([20.0])
    plain = PositionTracker("radar", CFG)
    wide = PositionTracker("radar", replace(CFG, extent_sigma_fraction=0.25))
    for k in range(4):
        for tracker in (plain, wide):
            dets.time_s = np.full(1, float(k))
            tracker.process(dets, np.zeros(2))
    (a,), (b,) = plain.tracks, wide.tracks
    np.testing.assert_array_equal(a.p, b.p)  # the filter is the same
    x_a, p_a = a.reported(5.0)
    x_b, p_b = b.reported(5.0)
    np.testing.assert_array_equal(x_a, x_b)
    np.testing.assert_array_equal(p_a, a.predicted(5.0)[1])  # no extent term: reported = predicted
    assert a.length_m == pytest.approx(20.0)
    np.testing.assert_allclose(p_b[:2, :2] - p_a[:2, :2], (0.25 * 20.0) ** 2 * np.eye(2))
    np.testing.assert_array_equal(p_b[2:, 2:], p_a[2:, 2:])


def test_a_kept_prediction_is_the_fresh_one_and_is_dropped_when_the_track_changes():
    tracker = PositionTracker("lidar", TrackerConfig(max_range_m=1e4))
    for k in range(4):
        tracker.process(scan(k * 0.5, [[10.0 + 2.0 * k, 5.0]]), np.zeros(2))
    track = tracker.tracks[0]
    first = track.predicted(3.0)
    assert track.predicted(3.0) is first  # kept
    fresh = ekf.predict(track.x, track.p, 3.0 - track.t_s, track.process)
    assert first[0].tobytes() == fresh[0].tobytes() and first[1].tobytes() == fresh[1].tobytes()
    tracker.process(scan(2.0, [[18.0, 5.0]]), np.zeros(2))  # updated: a new state
    after = track.predicted(3.0)
    assert after is not first and not np.array_equal(after[1], first[1])
    fresh = ekf.predict(track.x, track.p, 3.0 - track.t_s, track.process)
    assert after[1].tobytes() == fresh[1].tobytes()


def _same_object_pairs_one_by_one(tracks, cfg):
    """The pair-by-pair form of tracker._same_object_pairs (the reference)."""
    out = []
    for i, j in itertools.combinations(range(len(tracks)), 2):
        a, b = tracks[i], tracks[j]
        xb = ekf.predict_mean(b.x, a.t_s - b.t_s)
        near = max(cfg.merge_distance_m, 0.5 * (a.length_m + b.length_m))
        alike = np.hypot(*(ekf.velocity_en(a.x) - ekf.velocity_en(b.x))) < cfg.merge_speed_mps
        if np.hypot(*(a.x[:2] - xb[:2])) < near and alike:
            out.append((i, j))
    return out


def test_one_object_pairs_found_all_at_once_are_those_found_pair_by_pair():
    """Also for tracks placed on the distance and speed limits to the last bits, and with NaN lengths."""
    from tdm.tracker import Track, _same_object_pairs

    cfg = TrackerConfig()
    rng = np.random.default_rng(9)
    n_pairs = n_edge = 0
    for _ in range(150):
        n = int(rng.integers(0, 14))
        tracks = []
        for k in range(n):
            x = np.array([*np.round(rng.normal(0, 15, 2) * 1024) / 1024, rng.uniform(-4, 4), rng.normal(0, 2),
                          rng.normal(0, 0.02), 50.0])
            t = float(rng.uniform(0, 1))
            length = float(rng.choice([np.nan, 5.0, 30.0]))
            if k and rng.uniform() < 0.5:  # on a limit of an earlier track
                a = tracks[int(rng.integers(0, k))]
                if rng.uniform() < 0.5:  # velocity merge_speed_mps off the earlier track's
                    va, angle = ekf.velocity_en(a.x), rng.uniform(0, 2 * np.pi)
                    v = va + cfg.merge_speed_mps * (1 + rng.choice([-1e-16, 0.0, 1e-16])) * np.array([np.sin(angle), np.cos(angle)])
                    x[ekf.PSI], x[ekf.U] = np.arctan2(v[0], v[1]), np.hypot(*v)
                    x[:2] = a.x[:2] + rng.normal(0, 2, 2)
                else:  # merge_distance_m off the earlier track's position at its time
                    length, x[ekf.U], t = 5.0, 0.0, a.t_s
                    if rng.uniform() < 0.5:  # exactly on the limit (positions on a 1/1024 m grid: exact sums)
                        near = max(cfg.merge_distance_m, 0.5 * (a.length_m + length))
                        x[:2] = a.x[:2] + near * np.array([1.0, 0.0])[::rng.choice([1, -1])]
                    else:
                        angle = rng.uniform(0, 2 * np.pi)
                        x[:2] = a.x[:2] + cfg.merge_distance_m * (1 + rng.choice([-1e-16, 0.0, 1e-16])) * \
                            np.array([np.sin(angle), np.cos(angle)])
                    x[ekf.PSI], x[ekf.U] = a.x[ekf.PSI], a.x[ekf.U]
                    n_edge += 1
            tracks.append(Track(k + 1, "radar", x, np.eye(6), t, t, t, confirmed=True, length_m=length))
        pairs = _same_object_pairs(tracks, cfg)
        assert pairs == _same_object_pairs_one_by_one(tracks, cfg)
        n_pairs += len(pairs)
    assert n_pairs > 50 and n_edge > 50


def test_one_plot_swollen_by_a_sidelobe_ring_moves_the_length_by_at_most_three_times():
    """harbour_approach seed 31: a pier's 60 m plots, once joined to a ring of sidelobes 1.8 km round."""
    dets = scan(0.0, [[100.0, 200.0]], sigma=1.0)
    tracker = PositionTracker("radar", CFG)
    for k, length_m in enumerate([60.0, 60.0, 60.0, 1800.0]):
        dets.time_s, dets.length_m = np.full(1, float(k)), np.array([length_m])
        tracker.process(dets, np.zeros(2))
    (track,) = tracker.tracks
    assert track.length_m == pytest.approx(0.8 * 60.0 + 0.2 * 180.0)  # not 0.8 x 60 + 0.2 x 1800 = 408 m


def test_a_radar_tracks_core_width_is_the_running_mean_of_its_plots_and_a_ring_moves_it_threefold_at_most():
    """A berg's plots' core widths scatter (glints); the track keeps their mean over its last CORE_WIDTH_UPDATES
    updates: 10 and 30 m alternating give 20 m, where the exponential smoothing of the length would swing with
    them. A track from plots without a core width (LiDAR) has none."""
    from tdm.tracker import CORE_WIDTH_UPDATES
    dets = scan(0.0, [[100.0, 200.0]], sigma=1.0)
    tracker = PositionTracker("radar", CFG)
    widths = [10.0, 30.0] * 10
    for k, width_m in enumerate(widths):
        dets.time_s, dets.core_width_m = np.full(1, float(k)), np.array([width_m])
        tracker.process(dets, np.zeros(2))
    (track,) = tracker.tracks
    assert len(widths) < CORE_WIDTH_UPDATES and track.core_width_m == pytest.approx(np.mean(widths))
    dets.time_s, dets.core_width_m = np.full(1, 20.0), np.array([1800.0])
    tracker.process(dets, np.zeros(2))
    assert track.core_width_m == pytest.approx((20.0 * 20 + 60.0) / 21)  # the ring counts as 3 x 20 m
    lidar = PositionTracker("lidar", CFG)
    lidar_dets = scan(0.0, [[100.0, 200.0]])
    lidar.process(lidar_dets, np.zeros(2))
    assert np.isnan(lidar.tracks[0].core_width_m)


def test_a_track_knows_whether_its_last_detection_lay_at_the_range_limit():
    """Detections.range_cut: the track is flagged while its latest detection is cut by the range limit, and carries the
    configured consider sigma; detections without the flag (radar) leave it unflagged."""
    tracker = PositionTracker("lidar", replace(CFG, range_cut_sigma_m=7.0))
    cut_flags = [True, True, False, True]
    for k, cut in enumerate(cut_flags):
        dets = scan(float(k), [[0.0, 99.0]])
        dets.sensor = "lidar"
        dets.range_cut = np.array([cut])
        tracker.process(dets, np.zeros(2))
        (track,) = tracker.tracks
        assert track.range_cut is cut and track.range_cut_sigma_m == 7.0
    radar = PositionTracker("radar", CFG)
    radar.process(scan(0.0, [[0.0, 99.0]]), np.zeros(2))
    assert radar.tracks[0].range_cut is False and radar.tracks[0].range_cut_sigma_m == 0.0


def test_a_lidar_track_reports_its_footprint_over_time():
    """footprint_width_fraction f: the reported variance per axis is (f W)^2 plus the length seen before and not now,
    uniform, (L_max - L_now)^2 / 12. A hull seen whole (60 m), then end-on (20 m) with a 6 m width: 0.2 x 6 = 1.2 m
    and 40 m unseen. A detection over three times the largest length so far counts as three times it. The filter
    and the fusion's term (extent_var_m2, the length rule) are not changed."""
    cfg = replace(CFG, extent_sigma_fraction=0.15, footprint_width_fraction=0.2)
    tracker, plain = PositionTracker("lidar", cfg), PositionTracker("lidar", replace(cfg, footprint_width_fraction=None))
    for k, length in enumerate([60.0, 60.0, 20.0]):
        dets = scan(float(k), [[0.0, 50.0]])
        dets.length_m, dets.width_m = np.array([length]), np.array([6.0])
        tracker.process(dets, np.zeros(2))
        plain.process(dets, np.zeros(2))
    (track,), (other,) = tracker.tracks, plain.tracks
    assert (track.length_max_m, track.length_now_m, track.width_m) == (60.0, 20.0, pytest.approx(6.0))
    assert track.reported_extent_var_m2 == pytest.approx(1.2 ** 2 + 40.0 ** 2 / 12.0)
    np.testing.assert_array_equal(track.p, other.p)
    assert track.extent_var_m2 == other.extent_var_m2 == other.reported_extent_var_m2 > 0.0
    _, p = track.reported(3.0)
    np.testing.assert_allclose(p[:2, :2] - track.predicted(3.0)[1][:2, :2], track.reported_extent_var_m2 * np.eye(2))
    swollen = scan(3.0, [[0.0, 50.0]])
    swollen.length_m, swollen.width_m = np.array([1000.0]), np.array([6.0])
    tracker.process(swollen, np.zeros(2))
    assert tracker.tracks[0].length_max_m == pytest.approx(180.0)


def test_a_tentative_track_inside_a_confirmed_echo_waits_until_it_leaves_it():
    """Pieces of a still echo joined across scans (harbour_approach's pier) do not confirm; a boat that leaves the
    echo confirms once it is out of it."""
    cfg = TrackerConfig(confirm_m=3, confirm_n=4, coast_s=10.0, position_floor_m2=0.0, max_range_m=1e4,
                        init_speed_sigma_mps=4.0)
    held = replace(cfg, echo_hold_beam_deg=5.2)
    own = np.zeros(2)
    pier = np.array([0.0, 500.0])  # 40 m long: its echo spans 5.2 + 2.3 deg either side and 20 + 10 m in range
    off = 500.0 * np.array([np.sin(np.radians(4.0)), np.cos(np.radians(4.0))])  # 35 m from it: no one object

    def run(config, second, scans=8):
        tracker = PositionTracker("radar", config)
        confirmed_at = None
        for k in range(scans):
            t = 2.5 * k
            d = scan(t, [pier, second(t)] if k >= 3 else [pier])
            d.length_m = np.array([40.0, 5.0][:len(d)])
            tracker.process(d, own)
            if confirmed_at is None and len(tracker.confirmed_tracks()) == 2:
                confirmed_at = second(t)
        return tracker, confirmed_at

    assert len(run(held, lambda t: off * 1.1)[0].confirmed_tracks()) == 2  # 50 m beyond: out of the echo
    assert len(run(cfg, lambda t: off)[0].confirmed_tracks()) == 2  # a piece inside it, no hold: confirmed
    assert len(run(held, lambda t: off)[0].confirmed_tracks()) == 1  # held
    # a boat leaving the echo northward at 4 m/s: confirmed once out of it, not before
    _, confirmed_at = run(held, lambda t: off + [0.0, 4.0 * max(t - 7.5, 0.0)], scans=12)
    assert confirmed_at is not None and np.hypot(*confirmed_at) > 500.0 + 20.0 + 10.0


def _plots(t, positions, sigmas):
    d = scan(t, positions)
    d.position_cov_m2 = np.array([np.eye(2) * s**2 for s in sigmas])
    return d


def test_a_one_hit_track_beside_a_hull_does_not_push_its_confirmed_track_off_it():
    # a still hull painted as one wide plot (25 m standard deviation) and confirmed; a one-hit track starts on a
    # small plot 55 m south of it; next scan a small plot shows 35 m east of the hull. The tentative track gates
    # with the hull's plot only, so one assignment over all tracks (which pairs as many as it can) gives it the
    # hull's plot and moves the hull's track onto the small plot (harbour_approach seed 34's anchored tanker); the
    # confirmed track choosing first keeps the hull's plot
    tracker = PositionTracker("radar", CFG)
    for k in range(4):
        tracker.process(_plots(float(k), [[0.0, 0.0]], [25.0]), np.zeros(2))
    (hull,) = tracker.confirmed_tracks()
    tracker.process(_plots(4.0, [[0.0, 0.0], [-12.0, -54.0]], [25.0, 5.0]), np.zeros(2))
    assert len(tracker.tracks) == 2
    tracker.process(_plots(5.0, [[0.0, 0.0], [35.0, 0.0]], [25.0, 5.0]), np.zeros(2))
    assert np.hypot(*hull.x[:2]) < 5.0
    assert hull.updated_s == 5.0


@pytest.mark.parametrize("retry_s", [0.0, 10.0])
def test_a_course_too_uncertain_at_two_plots_is_tried_again_from_the_first(retry_s):
    """A 6 m/s ship going east, plots every 2.5 s on its track with 7 m standard deviation (a radar 450-700 m off).
    Two plots: the velocity's standard deviation is sqrt((49 + 49) / 2) / 2.5 = 3.96 m/s, 6 m/s under two of them,
    so the course stays unknown; the first to the third: 1.98 m/s, 6 m/s over two of them. With ``course_retry_s``
    the track takes the course there and follows the ship; without, its course is never learnt (a track with no
    speed has no position change to learn it from) and the plots leave it behind."""
    tracker = PositionTracker("radar", replace(CFG, course_retry_s=retry_s, init_speed_sigma_mps=4.0))
    track = None
    for k in range(8):
        t = 2.5 * k
        tracker.process(scan(t, [100.0 + 6.0 * t, 450.0], sigma=7.0), np.zeros(2))
        if k == 1:
            (track,) = tracker.tracks
            assert track.course_unknown
        if k == 2:
            assert track.course_unknown == (retry_s == 0.0)
    if retry_s == 0.0:
        assert track not in tracker.tracks or abs(track.x[ekf.U]) < 3.0
        return
    assert tracker.tracks == [track]
    assert track.x[ekf.U] == pytest.approx(6.0, abs=0.6)  # catching up the lag of its first two plots
    assert np.degrees(ekf.wrap_pi(track.x[ekf.PSI] - np.pi / 2)) == pytest.approx(0.0, abs=3.0)
    assert track.x[ekf.E] == pytest.approx(100.0 + 6.0 * 17.5, abs=3.0)


def test_a_still_object_tried_again_keeps_an_unknown_course_and_the_filters_covariance():
    """Plots of a still object, scattered 2 m: no try finds a course, and a later try leaves the filter's
    covariance as the filter made it (its speed correlated with its position by then: bounding the speed's
    variance alone, as the second plot does, could leave a matrix that is no covariance)."""
    rng = np.random.default_rng(4)
    tracker = PositionTracker("radar", replace(CFG, course_retry_s=10.0, init_speed_sigma_mps=4.0))
    for k in range(3):
        tracker.process(scan(2.5 * k, np.array([300.0, 500.0]) + rng.normal(scale=2.0, size=2), sigma=7.0),
                        np.zeros(2))
    (track,) = tracker.tracks
    assert track.course_unknown and abs(track.x[ekf.U]) < 1.5
    assert np.any(track.p[ekf.U, :2] != 0.0) and track.p[ekf.U, ekf.U] > 0.5
    before = track.p.copy()
    tracker._two_point(track, np.array([301.0, 500.0]), 1.0 * np.eye(2), 20.0)  # sd 0.36 m/s: a bound of 0.38 (m/s)^2
    assert track.course_unknown
    np.testing.assert_array_equal(track.p, before)

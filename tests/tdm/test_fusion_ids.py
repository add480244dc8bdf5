"""tdm.fusion: target ids over time: stable while a target's tracks change, an ended target found again where it
was, a target folded into another and its tracks leaving it again."""

import numpy as np
import pytest

from tdm import ekf
from tdm.fusion import Fuser, FusionConfig

from .test_fusion import make_track


def test_tracks_of_one_object_share_a_target_and_ids_stay_stable():
    fuser = Fuser(FusionConfig())
    radar = [make_track(1, "radar", 0.0, 0.0, var=25.0), make_track(2, "radar", 500.0, 0.0, var=25.0)]
    out = fuser.step(1.0, {"radar": radar, "lidar": [], "ais": []})
    ids = {round(e.x[0]): e.target.target_id for e in out}
    # LiDAR and AIS tracks appear near the first object: same target, same id
    lidar = [make_track(7, "lidar", 2.0, 1.0, var=1.0)]
    ais = [make_track(3, "ais", -3.0, 2.0, var=5.0, mmsi=257000001)]
    out = fuser.step(2.0, {"radar": radar, "lidar": lidar, "ais": ais})
    assert len(out) == 2
    first = [e for e in out if abs(e.x[0]) < 50][0]
    assert first.target.target_id == ids[0]
    assert first.sources == ["ais", "lidar", "radar"]
    assert first.target.descriptor == "vessel" and first.target.mmsi == 257000001
    # the radar track of the first object ends: the target lives on with its other tracks
    out = fuser.step(3.0, {"radar": radar[1:], "lidar": lidar, "ais": ais})
    assert sorted(e.target.target_id for e in out) == sorted(ids.values())


def test_a_distant_track_of_a_new_object_starts_a_new_target():
    fuser = Fuser(FusionConfig())
    fuser.step(1.0, {"radar": [make_track(1, "radar", 0.0, 0.0)]})
    out = fuser.step(2.0, {"radar": [make_track(1, "radar", 0.0, 0.0)], "lidar": [make_track(1, "lidar", 300.0, 0.0)]})
    assert len(out) == 2


def test_a_new_track_where_a_target_just_ended_takes_its_id():
    fuser = Fuser(FusionConfig(revive_s=30.0, revive_slow_as_still=False))  # the plain window (a slow one: below)
    (first,) = fuser.step(1.0, {"radar": [make_track(1, "radar", 500.0, 0.0)]})
    fuser.step(2.0, {"radar": []})  # the weak echo was lost: the target ends
    (again,) = fuser.step(10.0, {"radar": [make_track(2, "radar", 503.0, 2.0, t=10.0)]})
    assert again.target.target_id == first.target.target_id
    fuser.step(11.0, {"radar": []})
    (late,) = fuser.step(50.0, {"radar": [make_track(3, "radar", 500.0, 0.0, t=50.0)]})  # 39 s later: new
    assert late.target.target_id != first.target.target_id
    (elsewhere,) = fuser.step(51.0, {"radar": [make_track(4, "radar", 900.0, 0.0, t=51.0)]})
    assert elsewhere.target.target_id not in (first.target.target_id, late.target.target_id)


@pytest.mark.parametrize("spread, gap_s, off_m, same", [
    (True, 45.0, 0.0, True),     # back where it would be, 45 s on
    (True, 45.0, 40.0, True),    # 40 m off the straight line: within the prediction's spread after 45 s
    (False, 45.0, 40.0, False),  # the footprint alone (15 m + 3 sd of the new track's 2 m)
    (True, 45.0, 150.0, True),   # across its track the prediction's spread (193 m after 45 s) is wide
    (True, 45.0, -250.0, False), # along its track it is not (29 m): another ship, 250 m behind
    (True, 65.0, 0.0, False),    # past revive_s (60 s)
])
def test_a_ship_back_from_hiding_takes_its_id_where_its_last_motion_and_its_uncertainty_put_it(spread, gap_s, off_m,
                                                                                              same):
    """A 30 m ship without AIS going east at 6 m/s (its course known to 2 deg, speed to 0.3 m/s, and a turn rate of
    1 deg/s estimated as it went into hiding: not carried on) is lost behind an island; a new radar track appears
    ``gap_s`` later where it went on straight, ``off_m`` to the north of there (across its track; negative: that
    far behind, along its track)."""
    config = FusionConfig(revive_spread=spread, revive_slow_as_still=False)
    fuser = Fuser(config)
    ship = make_track(1, "radar", 0.0, 450.0, var=25.0)
    ship.x[ekf.PSI], ship.x[ekf.U], ship.x[ekf.R] = np.radians(90.0), 6.0, np.radians(1.0)
    ship.p[ekf.PSI, ekf.PSI], ship.p[ekf.U, ekf.U] = np.radians(2.0) ** 2, 0.09
    ship.length_m = 30.0
    (first,) = fuser.step(0.0, {"radar": [ship]})
    fuser.step(1.0, {"radar": []})
    along, across = (off_m, 0.0) if off_m < 0.0 else (0.0, off_m)
    back = make_track(2, "radar", 6.0 * gap_s + along, 450.0 + across, var=4.0, t=gap_s)
    (again,) = fuser.step(gap_s, {"radar": [back]})
    assert (again.target.target_id == first.target.target_id) == same


def test_a_still_target_keeps_its_id_when_its_echo_comes_back_minutes_later_where_it_was():
    fuser = Fuser(FusionConfig(revive_s=30.0, revive_still_s=300.0))
    berg = make_track(1, "radar", 800.0, 0.0, var=25.0)
    for t in range(1, 26):  # still for longer than settle_s (20 s): a fixed obstacle (50 m2: too small for a berg)
        (first,) = fuser.step(float(t), {"radar": [berg]})
    assert first.target.descriptor == "fixed obstacle"
    drifting = make_track(1, "radar", 800.0, 0.0, var=25.0, t=26.0)
    drifting.x[ekf.PSI], drifting.x[ekf.U] = np.radians(90.0), 0.4  # the last update left a small drift eastwards
    fuser.step(26.0, {"radar": [drifting]})
    fuser.step(27.0, {"radar": []})  # the far echo is lost
    # 200 s later (0.4 m/s x 200 s = 80 m of drift, were it carried on) a track where the obstacle was
    (again,) = fuser.step(227.0, {"radar": [make_track(2, "radar", 805.0, 3.0, var=25.0, t=227.0)]})
    assert again.target.target_id == first.target.target_id
    fuser.step(228.0, {"radar": []})
    (late,) = fuser.step(600.0, {"radar": [make_track(3, "radar", 800.0, 0.0, var=25.0, t=600.0)]})  # 373 s: new
    assert late.target.target_id != first.target.target_id


def test_a_radar_target_inside_an_ais_ship_folds_into_the_older_target():
    fuser = Fuser(FusionConfig())
    fuser.lengths_by_mmsi = {257000002: 100.0}
    (radar_only,) = fuser.step(1.0, {"radar": [make_track(1, "radar", 40.0, 0.0, var=100.0)]})
    # the ship's AIS track arrives 40 m away (the radar sees the bow): one object, the older id
    out = fuser.step(2.0, {"radar": [make_track(1, "radar", 40.0, 0.0, var=100.0)],
                           "ais": [make_track(5, "ais", 0.0, 0.0, var=5.0, mmsi=257000002)]})
    assert len(out) == 1 and out[0].target.target_id == radar_only.target.target_id
    assert out[0].target.mmsi == 257000002


def test_a_track_that_leaves_the_target_it_was_folded_into_takes_its_own_id_back():
    fuser = Fuser(FusionConfig())
    lidar = make_track(1, "lidar", 0.0, 0.0, var=1.0)
    fuser.step(1.0, {"lidar": [lidar], "radar": []})
    out = fuser.step(2.0, {"lidar": [lidar], "radar": [make_track(4, "radar", 300.0, 0.0, var=25.0, t=2.0)]})
    ids = {round(e.x[0]): e.target.target_id for e in out}
    assert len(ids) == 2
    # the radar track comes within the LiDAR target's footprint: one object, the older target's id
    (merged,) = fuser.step(3.0, {"lidar": [lidar], "radar": [make_track(4, "radar", 3.0, 0.0, var=25.0, t=3.0)]})
    assert merged.target.target_id == ids[0] and merged.sources == ["lidar", "radar"]
    # the same radar track leaves again: it is the target it was, not a new one
    out = fuser.step(4.0, {"lidar": [lidar], "radar": [make_track(4, "radar", 300.0, 0.0, var=25.0, t=4.0)]})
    assert {round(e.x[0]): e.target.target_id for e in out} == ids
    # a new track there later is a new target (ids are not handed out twice)
    out = fuser.step(5.0, {"lidar": [lidar], "radar": [make_track(4, "radar", 300.0, 0.0, var=25.0, t=5.0),
                                                        make_track(9, "radar", 700.0, 0.0, var=25.0, t=5.0)]})
    assert len({e.target.target_id for e in out}) == 3


def test_a_target_taken_back_by_its_second_track_is_no_longer_among_the_ended():
    fuser = Fuser(FusionConfig(revive_s=30.0, revive_slow_as_still=False))
    lidar = make_track(1, "lidar", 0.0, 0.0, var=1.0)

    def step(t, radar=(), lidar2=None):
        tracks = {"lidar": [lidar] + ([make_track(2, "lidar", *lidar2, var=1.0, t=t)] if lidar2 else []),
                  "radar": [make_track(4, "radar", *xy, var=25.0, t=t) for xy in radar]}
        out = {e.target.target_id: e for e in fuser.step(t, tracks)}
        # a live target is never also one that ended (which a new track could revive: one id on two targets)
        assert not [x for x in fuser.targets if x in fuser._ended]
        return out

    step(1.0)
    two = set(step(2.0, radar=[(300.0, 0.0)], lidar2=(301.0, 0.0))) - {1}
    assert len(two) == 1
    (b,) = two
    assert set(step(3.0, radar=[(3.0, 0.0)], lidar2=(2.0, 1.0))) == {1}  # both of b's tracks folded into 1
    assert set(step(4.0, radar=[(300.0, 0.0)], lidar2=(2.0, 1.0))) == {1, b}  # its radar track takes b back
    assert set(step(5.0, lidar2=(2.0, 1.0))) == {1}  # that track ends, and b with it
    assert set(step(6.0, lidar2=(600.0, 0.0))) == {1, b}  # its LiDAR track leaves 1 and takes b back
    out = step(7.0, radar=[(300.0, 0.0)], lidar2=(600.0, 0.0))  # a new track where b ended: not b a second time
    ids = [e.target.target_id for e in out.values()]
    assert len(out) == 3 and ids.count(b) == 1


@pytest.mark.parametrize("slow, same_id", [(True, True), (False, False)])
def test_a_slow_target_that_ended_before_settling_is_looked_for_where_it_was(slow, same_id):
    """A growler's radar track, still, seen for 5 s (under ``settle_s``: not yet an iceberg) and lost; a minute and a half
    later (over ``revive_s``, under ``revive_still_s``) a new radar track at its place takes its id with
    ``revive_slow_as_still``, a new one without. A moving target's id is not kept so long."""
    config = FusionConfig(revive_slow_as_still=slow)
    assert config.revive_s < 90.0 < config.revive_still_s
    fuser = Fuser(config)
    first = make_track(1, "radar", 0.0, 400.0)
    for t in range(5):
        (out,) = fuser.step(float(t), {"radar": [first]})
    assert out.target.descriptor == "unknown"
    assert fuser.step(5.0, {}) == []
    again = make_track(2, "radar", 2.0, 401.0, t=95.0)
    (back,) = fuser.step(95.0, {"radar": [again]})
    assert (back.target.target_id == out.target.target_id) == same_id
    moving = Fuser(config)
    boat = make_track(1, "radar", 0.0, 400.0)
    boat.x[ekf.PSI], boat.x[ekf.U] = np.pi, -3.0  # north at 3 m/s, as a filter may hold it: course south, speed < 0
    for t in range(5):
        (gone,) = moving.step(float(t), {"radar": [boat]})
    moving.step(5.0, {})
    where = make_track(2, "radar", 0.0, 400.0, t=95.0)  # where it was: a moving target is not looked for there
    assert moving.step(95.0, {"radar": [where]})[0].target.target_id != gone.target.target_id


@pytest.mark.parametrize("on_plot", [True, False])
def test_an_absorbed_track_leaves_its_target_only_on_a_plot_outside_it(on_plot):
    """busy_open_sea seed 3: a track of weak echo pieces beside the moving research ship, absorbed by the ship's
    target, coasted out of its footprint as the ship moved on and was reported as a target of its own. It stays
    absorbed while it has no plot since it last lay inside; a plot outside the footprint releases it."""
    fuser = Fuser(FusionConfig(release_absorbed_on_plot=on_plot))
    host = make_track(1, "radar", 0.0, 600.0, var=4.0, t=1.0)
    host.length_m = 40.0  # absorbing radius 30 m
    piece = make_track(2, "radar", 10.0, 600.0, var=4.0, t=2.0)
    fuser.step(1.0, {"radar": [host]})
    assert len(fuser.step(2.0, {"radar": [host, piece]})) == 1  # inside the footprint: absorbed
    host.x[0], host.t_s, host.updated_s = 200.0, 4.0, 4.0  # the host moves on; the piece coasts, no plot since
    assert len(fuser.step(4.0, {"radar": [host, piece]})) == (1 if on_plot else 2)
    piece.t_s = piece.updated_s = 5.0  # a plot where it is, 190 m from the host: released
    host.t_s = host.updated_s = 5.0
    out = fuser.step(5.0, {"radar": [host, piece]})
    assert len(out) == 2 and sorted(e.sources for e in out) == [["radar"], ["radar"]]

"""tdm.frontend.lidar: clusters of analytic and rendered LiDAR sweeps against known geometry and truth.

Truth (the NPZ ``object_id`` field, truth.jsonl) is used here only to check the front end, never by it.
"""

from __future__ import annotations

import copy
import math
from collections import defaultdict
from pathlib import Path

import numpy as np
import pytest
import yaml

from tdm.detections import Detections
from tdm.frames import Mount, OwnshipTrack
from tdm.frontend.lidar import (HDL32E_FIRING_CYCLE_S, LidarFrontEndConfig, lidar_clusters, lidar_detections,
                                lidar_mount_from_scenario)
from tdm.io import read_ownship, read_truth
from tests.conftest import BASE
from tests.tdm.conftest import render_recording

LAT0, LON0 = BASE["origin"]["lat"], BASE["origin"]["lon"]
ELEVATIONS_DEG = -30.67 + 4.0 / 3.0 * np.arange(32)  # HDL-32E rings, docs/reference.md section 2
MOUNT_Z_M = 3.0
MOUNT = Mount(z_m=MOUNT_Z_M)


# ------------------------------------------------------------------ analytic sweeps


def static_track() -> OwnshipTrack:
    """An own ship at rest at the origin, heading north, level: sensor x = north, y = west."""
    t = np.array([0.0, 100.0])
    zero = np.zeros(2)
    return OwnshipTrack({"t": t, "lat": np.full(2, LAT0), "lon": np.full(2, LON0), "z": zero, "heading_deg": zero,
                         "roll_deg": zero, "pitch_deg": zero, "cog_deg": zero, "sog_mps": zero})


def render_boxes(boxes, t0_s: float = 0.0) -> dict[str, np.ndarray]:
    """Cast one HDL-32E revolution at upright boxes standing in a sea that returns nothing.

    Each box is ``(north_m, west_m, length_m, width_m, yaw_deg, height_m)``: centre in the sensor
    frame (x forward = north, y left = west), footprint length along its yaw (counter-clockwise from
    north), height above the sea. The sensor is ``MOUNT_Z_M`` above the sea; rays below the sea or
    over a box miss. Returns a sweep with the recording's fields (first hit per ray).
    """
    cycles = int(round(0.1 / HDL32E_FIRING_CYCLE_S))
    az = np.linspace(0.0, 2.0 * math.pi, cycles, endpoint=False)          # clockwise from the bow
    elev = np.radians(ELEVATIONS_DEG)
    a, e = np.meshgrid(az, elev, indexing="ij")                            # (cycles, 32)
    dx, dy = np.cos(a), -np.sin(a)                                          # horizontal unit direction
    best = np.full(a.shape, np.inf)
    for north, west, length, width, yaw_deg, height in boxes:
        c, s = math.cos(math.radians(yaw_deg)), math.sin(math.radians(yaw_deg))
        # into the box frame (u along its length, v across)
        ou, ov = -(north * c + west * s), -(-north * s + west * c)
        du, dv = dx * c + dy * s, -dx * s + dy * c
        with np.errstate(divide="ignore", invalid="ignore"):
            tu = np.stack([(-length / 2 - ou) / du, (length / 2 - ou) / du])
            tv = np.stack([(-width / 2 - ov) / dv, (width / 2 - ov) / dv])
        near = np.maximum(tu.min(axis=0), tv.min(axis=0))                 # horizontal distance to the box
        far = np.minimum(tu.max(axis=0), tv.max(axis=0))
        z_up = MOUNT_Z_M + near * np.tan(e)                                 # height of the hit above the sea
        hit = (near > 0) & (near < far) & (z_up >= 0) & (z_up <= height)
        best = np.where(hit & (near < best), near, best)
    ring, cycle = np.nonzero(np.isfinite(best).T)
    d_h = best[cycle, ring]
    return {
        "x": (d_h * np.cos(az[cycle])).astype(np.float32),
        "y": (-d_h * np.sin(az[cycle])).astype(np.float32),
        "z": (d_h * np.tan(elev[ring])).astype(np.float32),
        "intensity": np.full(d_h.shape, 30, dtype=np.uint8),
        "ring": ring.astype(np.uint8),
        "time": t0_s + HDL32E_FIRING_CYCLE_S * cycle,
        "azimuth_deg": np.degrees(az[cycle]).astype(np.float32),
    }


def detect(boxes, **config) -> Detections:
    """Detections of one analytic sweep of ``boxes`` (see :func:`render_boxes`) from an own ship at rest."""
    return lidar_detections(render_boxes(boxes), static_track(), MOUNT, LidarFrontEndConfig(**config))


def test_a_wall_broadside_is_one_box_at_its_place():
    det = detect([(30.0, 0.0, 10.0, 0.3, 90.0, 6.0)], hidden_depth_fraction_elongated=0.0)  # 10 m long, east-west
    assert len(det) == 1
    assert det.position_m[0] == pytest.approx([0.0, 29.85], abs=0.1)   # the near face, 0.15 m short of the centre
    assert det.length_m[0] == pytest.approx(10.0, abs=0.2)
    assert det.width_m[0] < 0.2
    assert det.orientation_deg[0] == pytest.approx(90.0, abs=1.0)
    assert det.cross_section_m2[0] == pytest.approx(det.length_m[0] * det.width_m[0])
    ring_gap_m = 29.85 * math.tan(math.radians(4.0 / 3.0))
    assert 6.0 - ring_gap_m <= det.height_m[0] <= 6.0
    assert det.range_m[0] == pytest.approx(29.85, abs=0.1)
    assert 0.0 <= det.time_s[0] - det.scan_time_s < 0.1 and det.scan_time_s == 0.0
    assert det.sensor == "lidar" and det.n_cells[0] > 100


def test_the_outline_centre_of_a_box_at_an_angle_is_its_centre_and_the_mean_is_short():
    box = [(30.0, -5.0, 12.0, 4.0, 50.0, 6.0)]   # centre 30 m north, 5 m east, seen at an angle
    truth = np.array([5.0, 30.0])
    # the outline itself: without the hidden depth a long footprint is given (it shows two faces here)
    outline, mean = detect(box, hidden_depth_fraction_elongated=0.0), detect(box, centre="mean")
    assert len(outline) == len(mean) == 1
    assert np.linalg.norm(outline.position_m[0] - truth) < 0.4
    # the mean of the visible faces lies toward the sensor
    assert np.linalg.norm(mean.position_m[0]) < np.linalg.norm(truth) - 0.8
    assert np.linalg.norm(mean.position_m[0] - truth) > 1.0


def test_a_compact_cluster_is_put_its_hidden_depth_behind_its_outline_and_a_long_wall_its_elongated_one():
    """An 8 m square block turned 45 deg, 30 m north, shows two faces in a V, 11.3 m across and 5.7 m deep: its
    outline midpoint (the side corners') lies at 30 m; the hidden-depth fraction f puts it f x 5.66 m (half the
    width across the line of sight) further along it. A 10 m wall broadside (length over width far over 3), a hull
    side, is put ``hidden_depth_fraction_elongated`` x 5 m behind it instead."""
    block = [(30.0, 0.0, 8.0, 8.0, 45.0, 5.0)]
    outline, behind = detect(block, hidden_depth_fraction=0.0), detect(block)
    assert outline.position_m[0] == pytest.approx([0.0, 30.0], abs=0.2)
    fraction = LidarFrontEndConfig().hidden_depth_fraction
    assert fraction > 0.0
    assert behind.position_m[0] == pytest.approx([0.0, 30.0 + fraction * 4.0 * math.sqrt(2.0)], abs=0.2)
    wall = [(30.0, 0.0, 10.0, 0.3, 90.0, 6.0)]
    elongated = LidarFrontEndConfig().hidden_depth_fraction_elongated
    assert 0.0 < elongated < fraction
    seen = detect(wall, hidden_depth_fraction=0.0, hidden_depth_fraction_elongated=0.0).position_m[0]
    assert detect(wall, hidden_depth_fraction=0.0).position_m[0] == pytest.approx(seen + [0.0, elongated * 5.0],
                                                                                 abs=0.05)
    assert detect(wall).position_m[0] == pytest.approx(detect(wall, hidden_depth_fraction=0.0).position_m[0])


def test_a_cluster_reaching_the_range_limit_is_flagged_cut_and_the_same_block_nearer_is_not():
    """A 20 m square block turned 45 deg shows its two near faces from its front corner to its side corners,
    14.1 m deeper. Centred 105 m north, they run from 90.9 m to past the 100 m limit: the sensor returns nothing
    beyond it, so the cluster's farthest point lies at the limit and it is flagged (the block goes on, unseen).
    Centred 60 m north, its farthest point is 60 m off: not flagged. Without a margin, nothing is."""
    far, near = [(105.0, 0.0, 20.0, 20.0, 45.0, 6.0)], [(60.0, 0.0, 20.0, 20.0, 45.0, 6.0)]
    det_far, det_near = detect(far), detect(near)
    assert len(det_far) == len(det_near) == 1
    assert det_far.range_cut.tolist() == [True] and det_near.range_cut.tolist() == [False]
    assert detect(far, range_cut_margin_m=None).range_cut.tolist() == [False]
    # the flag changes nothing else
    unflagged = detect(far, range_cut_margin_m=None)
    np.testing.assert_array_equal(det_far.position_m, unflagged.position_m)
    np.testing.assert_array_equal(det_far.position_cov_m2, unflagged.position_cov_m2)
    with pytest.raises(ValueError, match="range_cut_margin_m"):
        LidarFrontEndConfig(range_cut_margin_m=-1.0)


def test_walls_farther_apart_than_the_tolerance_are_two_clusters_closer_are_one():
    def walls(gap_m):
        return [(20.0, 3.0 + gap_m / 2, 6.0, 0.3, 90.0, 5.0), (20.0, -3.0 - gap_m / 2, 6.0, 0.3, 90.0, 5.0)]

    assert len(detect(walls(1.0))) == 2         # 1.0 m > 0.7 m
    assert len(detect(walls(0.3))) == 1         # 0.3 m < 0.7 m
    assert len(detect(walls(1.0), cluster_tolerance_m=1.5)) == 1
    two = detect(walls(1.0))
    assert sorted(two.position_m[:, 0]) == pytest.approx([-3.5, 3.5], abs=0.2)


def test_covariance_grows_with_size_and_range_and_is_never_singular():
    def cov(north_m, length_m, **config):
        det = detect([(north_m, 0.0, length_m, 0.3, 90.0, 6.0)], **config)
        assert len(det) == 1
        p = det.position_cov_m2[0]
        assert np.allclose(p, p.T) and np.linalg.eigvalsh(p).min() > 0.0
        return p

    small, big = cov(15.0, 4.0, nav_position_sigma_m=0.0), cov(15.0, 12.0, nav_position_sigma_m=0.0)
    # the footprint term: a box of length L has variance L^2/12 along it (here east), scaled (the centre from the
    # outline's extreme points is better known than a point anywhere on the footprint)
    scale = LidarFrontEndConfig().footprint_variance_scale
    assert big[0, 0] == pytest.approx(scale * 12.0 ** 2 / 12.0, rel=0.1)
    assert small[0, 0] == pytest.approx(scale * 4.0 / 3.0, rel=0.15)
    whole = cov(15.0, 12.0, nav_position_sigma_m=0.0, footprint_variance_scale=1.0)
    assert whole[0, 0] == pytest.approx(12.0 ** 2 / 12.0, rel=0.1)
    assert np.linalg.eigvalsh(big - small).min() >= -1e-9
    # the sensor term: a 0.3 m pole (a few points; footprint ~0) at 15 m and 80 m, no navigation error
    pole = {"min_points": 1, "min_surface_fraction": 0.0, "nav_position_sigma_m": 0.0}
    near, far = cov(15.0, 0.3, **pole), cov(80.0, 0.3, **pole)
    config = LidarFrontEndConfig()
    per_m2 = (config.azimuth_step_rad ** 2 / 12 + (1e-3 * config.beam_divergence_mrad) ** 2 / 16
              + math.radians(config.nav_heading_sigma_deg) ** 2)
    assert far[0, 0] - near[0, 0] == pytest.approx((80.0 ** 2 - 15.0 ** 2) * per_m2, rel=0.25)   # across the sight line
    assert far[1, 1] == pytest.approx(config.range_sigma_m ** 2, rel=0.05)                         # along it
    assert np.linalg.eigvalsh(near).min() >= config.range_sigma_m ** 2 * 0.99


def test_config_checks_and_scenario_values():
    with pytest.raises(ValueError, match="voxel_m"):
        LidarFrontEndConfig(voxel_m=0.0)
    with pytest.raises(ValueError, match="centre"):
        LidarFrontEndConfig(centre="median")
    scenario = {"own_ship": {"length_m": 30.0, "beam_m": 8.0},
                "sensors": {"lidar": {"range_max_m": 80.0, "rotation_hz": 20.0, "mount": {"x_m": 2.0, "z_m": 5.0}},
                            "nav": {"position_noise_m": 0.3, "position_bias_m": 0.4}}}
    config = LidarFrontEndConfig.from_scenario(scenario, min_points=5)
    assert (config.ownship_length_m, config.ownship_beam_m, config.range_max_m) == (30.0, 8.0, 80.0)
    assert config.nav_position_sigma_m == pytest.approx(0.5) and config.min_points == 5
    assert config.azimuth_step_rad == pytest.approx(math.radians(360 * 20 * 46.08e-6))
    assert lidar_mount_from_scenario(scenario) == Mount(x_m=2.0, z_m=5.0)
    assert LidarFrontEndConfig.from_scenario({}) == LidarFrontEndConfig()


# ------------------------------------------------------------------ rendered recordings


def scenario(**changes) -> dict:
    s = copy.deepcopy(BASE)
    s["sensors"] = {"lidar": {"enabled": True, "rotation_hz": 10, "mount": {"x_m": 1.0, "z_m": 3.0}},
                    "radar": {"enabled": False}}
    s["own_ship"] = {"length_m": 10.9, "beam_m": 3.5, "position": [LAT0, LON0], "heading_deg": 0.0}
    s["obstacles"], s["ships"] = [], []
    s.update(changes)
    return s


def render(tmp_path_factory, name: str, data: dict, duration_s: float, extra_files=()) -> Path:
    folder = tmp_path_factory.mktemp(name)
    for file_name, text in extra_files:
        (folder / file_name).write_text(text, encoding="utf-8")
    path = folder / "scenario.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    return render_recording(path, folder / "rec", duration_s, sensors=("lidar",))


class Recording:
    """A rendered recording read as the TDM reads it, plus truth for the checks."""

    def __init__(self, path: Path, **config):
        self.path = path
        self.scenario = yaml.safe_load((path / "scenario.yaml").read_text(encoding="utf-8"))
        self.track = OwnshipTrack(read_ownship(path))
        self.mount = lidar_mount_from_scenario(self.scenario)
        self.config = LidarFrontEndConfig.from_scenario(self.scenario, **config)
        self.sweep_files = sorted((path / "lidar" / "sweeps").glob("*.npz"))
        rows = defaultdict(list)
        for row in read_truth(path):
            rows[row["id"]].append(row)
        self.truth = {}
        for object_id, r in rows.items():
            east, north = self.track.frame.to_enu([x["lat"] for x in r], [x["lon"] for x in r])
            self.truth[object_id] = (np.array([x["t"] for x in r]), east, north, r[0])

    def sweeps(self):
        for file in self.sweep_files:
            with np.load(file) as data:
                yield {k: data[k] for k in data.files}

    def truth_at(self, object_id: int, t_s: float) -> np.ndarray:
        t, east, north, _ = self.truth[object_id]
        return np.array([np.interp(t_s, t, east), np.interp(t_s, t, north)])

    def sensor_at(self, t_s: float) -> np.ndarray:
        return self.track.sensor_to_enu(np.zeros((1, 3)), np.array([t_s]), self.mount)[0, :2]


@pytest.fixture(scope="module")
def ship_ahead(tmp_path_factory) -> Recording:
    """A 20 m ship broadside, 40 m north of the own ship at rest in sea state 3 (roll, pitch, heave, foam)."""
    lat, lon = static_track().frame.to_geodetic(0.0, 40.0)
    data = scenario(ships=[{"name": "target", "length_m": 20, "waypoints": [[float(lat), float(lon)]],
                            "heading_deg": 90}])
    return Recording(render(tmp_path_factory, "ship_ahead", data, 1.0))


def test_a_ship_ahead_is_one_cluster_near_its_truth_and_toward_the_sensor(ship_ahead):
    target_id = next(i for i, (_, _, _, row) in ship_ahead.truth.items() if row["name"] == "target")
    row = ship_ahead.truth[target_id][3]
    n = 0
    for sweep in ship_ahead.sweeps():
        det = lidar_detections(sweep, ship_ahead.track, ship_ahead.mount, ship_ahead.config)
        assert len(det) == 1
        truth = ship_ahead.truth_at(target_id, det.time_s[0])
        sensor = ship_ahead.sensor_at(det.time_s[0])
        assert np.linalg.norm(det.position_m[0] - truth) < 3.0
        assert np.linalg.norm(det.position_m[0] - sensor) < np.linalg.norm(truth - sensor)
        assert det.length_m[0] == pytest.approx(row["length_m"], abs=3.0)
        assert det.width_m[0] < row["beam_m"] + 1.0              # the near side and some deck
        assert det.orientation_deg[0] == pytest.approx(90.0, abs=8.0)
        assert det.height_m[0] == pytest.approx(row["height_m"], abs=1.5)
        assert det.range_m[0] == pytest.approx(np.linalg.norm(det.position_m[0] - sensor))
        n += 1
    assert n == len(ship_ahead.sweep_files) >= 9


def test_own_ship_and_sea_returns_are_gone_and_truth_fields_are_not_used(ship_ahead):
    target_id = next(i for i, (_, _, _, row) in ship_ahead.truth.items() if row["name"] == "target")
    own_id = next(i for i, (_, _, _, row) in ship_ahead.truth.items() if row["kind"] == "ownship")
    for sweep in ship_ahead.sweeps():
        assert np.mean(sweep["object_id"] == own_id) > 0.5        # most of a sweep hits the own ship
        assert np.sum(sweep["object_id"] == -1) > 0               # and some of it the sea
        det, index, label = lidar_clusters(sweep, ship_ahead.track, ship_ahead.mount, ship_ahead.config)
        assert np.all(sweep["object_id"][index] == target_id)
        assert np.array_equal(np.bincount(label), det.n_cells)
        blind = {k: v for k, v in sweep.items() if k in ("x", "y", "z", "intensity", "ring", "time", "azimuth_deg")}
        again = lidar_detections(blind, ship_ahead.track, ship_ahead.mount, ship_ahead.config)
        assert np.array_equal(again.position_m, det.position_m)


@pytest.fixture(scope="module")
def empty_rough_sea(tmp_path_factory) -> Recording:
    """No targets: sea state 5 (foam) and 16 mm/h rain (false echoes of drops near the sensor)."""
    data = scenario(environment={"sea_state": 5, "wind_speed_mps": 15, "wind_from_deg": 90, "rain_mm_per_h": 16})
    return Recording(render(tmp_path_factory, "empty_sea", data, 0.5))


def test_an_empty_sea_in_rain_gives_no_clusters(empty_rough_sea):
    rec = empty_rough_sea
    unfiltered = LidarFrontEndConfig.from_scenario(rec.scenario, min_height_m=-1.0, min_surface_fraction=0.0)
    clutter = 0
    for sweep in rec.sweeps():
        assert np.sum(sweep["object_id"] == -1) > 100             # foam and rain echoes are there
        assert len(lidar_detections(sweep, rec.track, rec.mount, rec.config)) == 0
        clutter += len(lidar_detections(sweep, rec.track, rec.mount, unfiltered))
    assert clutter > 0                                            # the sea and weather filters do the work


@pytest.fixture(scope="module")
def turning(tmp_path_factory) -> Recording:
    """The own ship turns to starboard at 20 deg/s on the spot; a 20 m ship lies across the bow's path.

    The sweep's seam (its start and end, 0.1 s apart) runs through the target all along, so
    the target is seen in two parts 2 deg of own-ship yaw apart: 1.3 m at 38 m.
    """
    bearing_deg, distance_m = 14.0, 40.0
    frame = static_track().frame
    lat, lon = frame.to_geodetic(distance_m * math.sin(math.radians(bearing_deg)),
                                 distance_m * math.cos(math.radians(bearing_deg)))
    t = np.arange(0.0, 1.55, 0.05)
    csv = "t_s,lat,lon,heading_deg\n" + "".join(f"{ti:.2f},{LAT0!r},{LON0!r},{20.0 * ti:.3f}\n" for ti in t)
    data = scenario(duration_s=1.4, own_ship={"length_m": 10.9, "beam_m": 3.5, "trajectory_csv": "turn.csv"},
                    environment={"sea_state": 0, "wind_speed_mps": 0, "wind_from_deg": 0},
                    ships=[{"name": "target", "length_m": 20, "waypoints": [[float(lat), float(lon)]],
                            "heading_deg": bearing_deg + 90.0}])
    return Recording(render(tmp_path_factory, "turning", data, 1.4, extra_files=[("turn.csv", csv)]))


def test_deskew_keeps_a_static_target_compact_while_the_own_ship_turns(turning):
    skewed = LidarFrontEndConfig.from_scenario(turning.scenario, deskew=False)
    positions, distorted = [], 0
    for sweep in turning.sweeps():
        det = lidar_detections(sweep, turning.track, turning.mount, turning.config)
        assert len(det) == 1
        assert det.length_m[0] == pytest.approx(20.0, abs=1.0)      # the ship broadside, in one piece
        positions.append(det.position_m[0])
        # without deskew the part seen at the sweep's end is placed 2 deg off: 1.3 m longer (or split)
        other = lidar_detections(sweep, turning.track, turning.mount, skewed)
        distorted += len(other) != 1 or abs(other.length_m[0] - det.length_m[0]) > 0.8
    positions = np.array(positions)
    assert np.linalg.norm(positions - positions.mean(axis=0), axis=1).max() < 1.0   # static, and seen so
    assert distorted >= len(positions) // 2


def test_busy_open_sea_every_well_seen_object_gives_a_cluster_near_it(bos_recording):
    rec = Recording(bos_recording)
    checked = 0
    for sweep in rec.sweeps():
        det = lidar_detections(sweep, rec.track, rec.mount, rec.config)
        ids, counts = np.unique(sweep["object_id"], return_counts=True)
        for object_id, count in zip(ids, counts):
            if object_id <= 0 or count < 30:      # -1: nothing; 0: the own ship
                continue
            t = float(sweep["time"][sweep["object_id"] == object_id].mean())
            truth = rec.truth_at(int(object_id), t)
            if np.linalg.norm(truth - rec.sensor_at(t)) > rec.config.range_max_m:
                continue                          # cut by the range limit: its centre is not seen
            assert len(det) and np.hypot(*(det.position_m - truth).T).min() < 10.0, (t, object_id)
            checked += 1
    assert checked > 200


@pytest.mark.parametrize("n, e", [(1, 0), (60, 0), (60, 80), (300, 250), (500, 3000), (2000, 1999)])
def test_connected_components_are_scipys_with_its_numbering(n, e):
    from scipy.sparse import csr_array
    from scipy.sparse.csgraph import connected_components

    from tdm.frontend.lidar_graph import components as _components

    rng = np.random.default_rng(n + e)
    rows, cols = rng.integers(0, n, e), rng.integers(0, n, e)
    if e == n - 1:  # one long chain in shuffled order: the deepest trees
        order = rng.permutation(n)
        rows, cols = order[:-1], order[1:]
    rows[:3], cols[:3] = rows[:3], rows[:3]  # self loops
    graph = csr_array((np.ones(e), (rows, cols)), shape=(n, n))
    assert np.array_equal(_components(rows, cols, n), connected_components(graph, directed=False)[1])


def test_a_mount_pose_is_formed_once_and_is_the_mounts():
    from tdm.frontend.lidar import _mount_pose

    mount = Mount(x_m=1.0, z_m=3.0, roll_deg=2.0, yaw_deg=-4.0)
    rotation, translation, identity = _mount_pose(mount)
    assert _mount_pose(Mount(x_m=1.0, z_m=3.0, roll_deg=2.0, yaw_deg=-4.0))[0] is rotation
    assert np.array_equal(rotation, mount.rotation()) and np.array_equal(translation, mount.translation_m())
    assert not identity and _mount_pose(Mount(x_m=1.0))[2]
    assert not rotation.flags.writeable


def _pickled(results) -> list[bytes]:
    import pickle
    return [pickle.dumps(r) for r in results]


@pytest.mark.parametrize("config", [{}, {"deskew": False}, {"deskew_step_s": 0.0}, {"centre": "mean"}])
def test_sweeps_taken_together_give_each_sweeps_result_alone(bos_recording, config):
    """lidar_clusters_batch: each sweep's detections, point indices and labels, bit for bit, are those of the
    sweep alone, whatever its neighbours in the batch (no point, all on the own ship, another dtype)."""
    from tdm.frontend.lidar import lidar_clusters_batch
    rec = Recording(bos_recording, **config)
    sweeps = [s for k, s in enumerate(rec.sweeps()) if k % 7 == 0][:40]
    own_ship = {k: v[sweeps[3]["object_id"] == 0] for k, v in sweeps[3].items()}
    empty = {k: v[:0] for k, v in sweeps[5].items()}
    wide = {**sweeps[8], **{k: sweeps[8][k].astype(np.float64) for k in ("x", "y", "z")}}
    sweeps = sweeps[:4] + [own_ship, empty] + sweeps[4:9] + [wide] + sweeps[9:]
    alone = [lidar_clusters(s, rec.track, rec.mount, rec.config) for s in sweeps]
    assert sum(len(a[0]) for a in alone) > 50 and len(alone[4][0]) == len(alone[5][0]) == 0
    for size in (5, 16, len(sweeps)):
        together = [r for k in range(0, len(sweeps), size)
                    for r in lidar_clusters_batch(sweeps[k:k + size], rec.track, rec.mount, rec.config)]
        assert _pickled(together) == _pickled(alone)


def test_voxel_pairs_are_the_kd_trees_pairs_within_each_sweep():
    from scipy.spatial import cKDTree
    from tdm.frontend.lidar_graph import voxel_grid, voxel_pairs
    rng = np.random.default_rng(11)
    for voxel_m, tolerance_m in ((0.25, 0.7), (0.3, 0.6), (0.5, 0.5), (0.2, 1.1)):
        sweep = np.repeat(np.arange(4), 3000)
        centres = rng.uniform(-20.0, 20.0, (40, 2))  # clumps of points, some sweeps sharing places
        points = centres[rng.integers(0, 40, sweep.shape[0])] + rng.normal(0.0, 1.5, (sweep.shape[0], 2))
        enu = np.column_stack([points, np.zeros(sweep.shape[0])])
        grid = voxel_grid(enu, sweep, voxel_m, tolerance_m)
        i, j = voxel_pairs(grid, tolerance_m)
        voxel_sweep = np.zeros(grid.keys.shape[0], dtype=np.int64)
        voxel_sweep[grid.inverse] = sweep
        expected = set()
        for s in range(4):
            members = np.flatnonzero(voxel_sweep == s)
            pairs = cKDTree(grid.centres_m[members]).query_pairs(tolerance_m, output_type="ndarray")
            expected |= {tuple(p) for p in members[pairs]}
        assert len(expected) > 1000 and {tuple(p) for p in np.column_stack([i, j])} == expected
        assert np.all(i < j)


def test_deskew_of_several_sweeps_with_a_pose_per_point_is_the_tracks():
    """_deskewed with no grid is OwnshipTrack.sensor_to_enu bit for bit; with the grid, each point's pose is
    at most half a step off its time."""
    from tdm.frontend.lidar import _deskewed
    t = np.linspace(0.0, 50.0, 6)
    track = OwnshipTrack({"t": t, "lat": np.full(6, LAT0), "lon": LON0 + 1e-4 * t, "z": 0.1 * np.sin(t),
                          "heading_deg": 7.0 * t, "roll_deg": 3.0 * np.sin(t), "pitch_deg": np.cos(t),
                          "cog_deg": np.full(6, 90.0), "sog_mps": np.full(6, 0.2)})
    mount = Mount(x_m=1.0, z_m=3.0, roll_deg=1.0)
    rng = np.random.default_rng(2)
    sweep = np.repeat(np.arange(3), [500, 7, 900])
    times = np.sort(rng.uniform(0.0, 0.1, sweep.shape[0])) + 0.1 * sweep
    points = rng.normal(0.0, 30.0, (sweep.shape[0], 3))
    exact = track.sensor_to_enu(points, times, mount)
    assert np.array_equal(_deskewed(track, points, times, sweep, mount, 0.0), exact)
    gridded = _deskewed(track, points, times, sweep, mount, 2.5e-4)
    assert np.abs(gridded - exact).max() < 0.01 and not np.array_equal(gridded, exact)

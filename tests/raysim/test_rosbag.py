"""The recording's ROS 2 bag, read back with mcap-ros2-support (a reader other than the writer)."""

from __future__ import annotations

import json

import numpy as np
import pytest
import yaml

from raysim.cli import main
from tests.conftest import REPO



@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    out = tmp_path_factory.mktemp("bag") / "rec"
    assert main(["render", str(REPO / "scenarios" / "busy_open_sea.yaml"), "-o", str(out), "--duration", "3"]) == 0
    return out


def messages(recording):
    """{topic: [decoded message]} read with mcap's reader and the mcap-ros2 decoder."""
    from mcap.reader import make_reader
    from mcap_ros2.decoder import DecoderFactory

    bags = list((recording / "rosbag").glob("*.mcap"))
    assert len(bags) == 1
    by_topic = {}
    with open(bags[0], "rb") as handle:
        for _, channel, _, msg in make_reader(handle, decoder_factories=[DecoderFactory()]).iter_decoded_messages():
            by_topic.setdefault(channel.topic, []).append(msg)
    return by_topic


def stamp_s(msg) -> float:
    return msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9


def test_bag_topics_and_counts_match_the_recording(recording):
    bag = messages(recording)
    manifest = json.loads((recording / "manifest.json").read_text())
    start = 1496318400.0  # 2017-06-01T12:00:00Z, busy_open_sea's start
    assert set(bag) == {"/tf_static", "/tf", "/lidar/points", "/radar/sector", "/ais/nmea", "/ownship/fix",
                        "/ownship/pose", "/truth/objects"}
    for topic, msgs in bag.items():
        assert manifest["counts"][f"rosbag{topic}"] == len(msgs)
    meta = yaml.safe_load((recording / "rosbag" / "metadata.yaml").read_text())
    assert meta["rosbag2_bagfile_information"]["version"] == 8
    assert meta["rosbag2_bagfile_information"]["storage_identifier"] == "mcap"

    sweeps = sorted((recording / "lidar" / "sweeps").glob("*.npz"))
    assert len(bag["/lidar/points"]) == len(sweeps) > 0
    cloud = bag["/lidar/points"][3]
    layout = [(f.name, f.offset, f.datatype, f.count) for f in cloud.fields]
    assert layout == [("x", 0, 7, 1), ("y", 4, 7, 1), ("z", 8, 7, 1), ("intensity", 12, 7, 1), ("ring", 16, 4, 1),
                      ("time", 18, 7, 1)]
    assert cloud.point_step == 22 and cloud.header.frame_id == "lidar" and not cloud.is_bigendian
    points = np.frombuffer(bytes(cloud.data), dtype=np.dtype([("x", "<f4"), ("y", "<f4"), ("z", "<f4"),
                                                              ("intensity", "<f4"), ("ring", "<u2"), ("time", "<f4")]))
    with np.load(sweeps[3]) as sweep:
        assert points.size == cloud.width == sweep["x"].size
        np.testing.assert_array_equal(points["x"], sweep["x"])
        np.testing.assert_array_equal(points["ring"], sweep["ring"])
        assert stamp_s(cloud) == pytest.approx(start + float(sweep["time"].min()), abs=1e-6)
        assert points["time"].min() == 0.0 and points["time"].max() <= 0.11

    radar = sorted((recording / "radar" / "sweeps").glob("*.npz"))
    assert len(bag["/radar/sector"]) == len(radar) > 0
    sector = bag["/radar/sector"][0]
    with np.load(radar[0]) as sweep:
        assert len(sector.intensities) == sweep["echo"].shape[0]
        assert {len(e.echoes) for e in sector.intensities} == {sweep["echo"].shape[1]}
        np.testing.assert_allclose(np.array(sector.intensities[100].echoes) * 15.0, sweep["echo"][100], atol=1e-4)
        assert stamp_s(sector) == pytest.approx(start + float(sweep["time"][0]), abs=1e-6)
        assert sector.range_max == pytest.approx(float(sweep["range_m"][-1]))
        assert sector.angle_increment == pytest.approx(-2 * np.pi / sweep["echo"].shape[0])

    lines = (recording / "ais" / "ais.nmea").read_text().splitlines()
    assert [m.sentence for m in bag["/ais/nmea"]] == [line.split("\\")[2] for line in lines]
    own = [json.loads(line) for line in (recording / "ownship.jsonl").read_text().splitlines()]
    fix = bag["/ownship/fix"][0]
    assert (fix.latitude, fix.longitude) == (own[0]["lat"], own[0]["lon"])
    frames = {t.child_frame_id for t in bag["/tf_static"][0].transforms}
    assert frames == {"lidar", "radar"}


def test_bag_carries_the_own_ship_transform_and_truth_boxes(recording):
    bag = messages(recording)
    own = [json.loads(line) for line in (recording / "ownship.jsonl").read_text().splitlines()]
    tf = bag["/tf"][5].transforms[0]
    row = next(r for r in own if abs(r["t"] - (stamp_s(tf) - 1496318400.0)) < 1e-6)
    assert (tf.header.frame_id, tf.child_frame_id) == ("map", "base_link")
    assert (tf.transform.translation.x, tf.transform.translation.y) == (row["x"], row["y"])
    q = tf.transform.rotation
    yaw = np.arctan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y**2 + q.z**2))
    assert (90.0 - np.degrees(yaw)) % 360.0 == pytest.approx(row["heading_deg"], abs=1e-6)
    truth = [json.loads(line) for line in (recording / "truth.jsonl").read_text().splitlines()]
    boxes = bag["/truth/objects"]
    assert len(boxes) == 4  # t = 0, 1, 2, 3 s
    at_two = {r["id"]: r for r in truth if r["t"] == 2.0}
    markers = boxes[2].markers
    assert {m.id for m in markers} == set(at_two)
    ship = next(m for m in markers if at_two[m.id]["kind"] == "ship")
    assert (ship.pose.position.x, ship.scale.x, ship.text) == (at_two[ship.id]["x"], at_two[ship.id]["length_m"],
                                                               at_two[ship.id]["name"])


def test_the_bag_is_deterministic(recording, tmp_path):
    again = tmp_path / "again"
    assert main(["render", str(REPO / "scenarios" / "busy_open_sea.yaml"), "-o", str(again), "--duration", "3"]) == 0
    for name in ("rosbag.mcap", "metadata.yaml"):
        assert (again / "rosbag" / name).read_bytes() == (recording / "rosbag" / name).read_bytes()

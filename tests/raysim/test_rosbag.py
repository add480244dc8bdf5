"""The recording's ROS 2 bag, read back with mcap-ros2-support (a reader other than the writer)."""

from __future__ import annotations

import json
import math

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
    assert set(bag) == {"/tf_static", "/tf", "/lidar/points", "/radar/sector", "/radar/image/compressed", "/ais/nmea",
                        "/ownship/fix", "/ownship/pose", "/ownship/imu", "/ownship/odom", "/truth/objects",
                        "/truth/geojson"}
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
    received = [json.loads(line) for line in (recording / "ais" / "ais_received.jsonl").read_text().splitlines()]
    # stamped at the reception time, not at the TAG block's whole second
    assert [stamp_s(m) for m in bag["/ais/nmea"]] == pytest.approx([start + r["t"] for r in received], abs=1e-6)
    assert any(r["t"] % 1.0 > 0.01 for r in received)
    own = [json.loads(line) for line in (recording / "ownship.jsonl").read_text().splitlines()]
    fix = bag["/ownship/fix"][0]
    assert (fix.latitude, fix.longitude) == (own[0]["lat"], own[0]["lon"])
    frames = {t.child_frame_id for t in bag["/tf_static"][0].transforms}
    assert frames == {"lidar", "radar", "ais"}


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


def test_bag_is_compressed_checksummed_in_time_order_and_offers_qos(recording):
    """zstd chunks with CRCs (checked by both readers), log times in order, QoS of the real publishers."""
    from mcap.reader import make_reader
    from rosbags.interfaces import QosDurability, QosHistory, QosReliability
    from rosbags.rosbag2 import Reader

    (path,) = (recording / "rosbag").glob("*.mcap")
    with open(path, "rb") as handle:
        reader = make_reader(handle, validate_crcs=True)
        summary = reader.get_summary()
        chunks = list(summary.chunk_indexes)
        assert chunks and {c.compression for c in chunks} == {"zstd"}
        assert all(c.compressed_size < c.uncompressed_size for c in chunks)
        times = [m.log_time for _, _, m in reader.iter_messages(log_time_order=False)]
        assert times == sorted(times) and len(times) == summary.statistics.message_count
        qos = {ch.topic: yaml.safe_load(ch.metadata["offered_qos_profiles"]) for ch in summary.channels.values()}
    assert qos["/tf_static"] == [dict(qos["/tf_static"][0], reliability=1, durability=1, history=1, depth=1)]
    assert all(q[0]["durability"] == 2 and q[0]["reliability"] == 1 for t, q in qos.items() if t != "/tf_static")
    with open(path, "rb") as handle:  # every chunk's CRC is set (mcap's reader checks them only when non-zero)
        from mcap.records import Chunk
        from mcap.stream_reader import StreamReader

        chunks = [r for r in StreamReader(handle, emit_chunks=True).records if isinstance(r, Chunk)]
    assert chunks and all(c.uncompressed_crc for c in chunks)
    # compressed at zstd level 1, as the MCAP C++ library (rosbag2's plugin) writes by default
    import zstandard

    from raysim.recording.rosbag.storage import ZSTD_LEVEL

    assert ZSTD_LEVEL == 1
    for chunk in chunks[:3]:
        raw = zstandard.ZstdDecompressor().decompress(chunk.data, max_output_size=chunk.uncompressed_size)
        assert chunk.data == zstandard.ZstdCompressor(level=ZSTD_LEVEL).compress(raw)

    with Reader(recording / "rosbag") as bag:  # rosbags checks chunk CRCs too
        conns = {c.topic: c for c in bag.connections}
        static = conns["/tf_static"].ext.offered_qos_profiles[0]
        assert (static.reliability, static.durability, static.history, static.depth) == (
            QosReliability.RELIABLE, QosDurability.TRANSIENT_LOCAL, QosHistory.KEEP_LAST, 1)
        assert sum(1 for _ in bag.messages()) == len(times)


def test_bag_own_ship_imu_odometry_and_fix_carry_the_navigation_model(recording):
    bag = messages(recording)
    scenario = yaml.safe_load((recording / "scenario.yaml").read_text())
    nav = scenario["sensors"]["nav"]
    own = {round(r["t"], 6): r for r in map(json.loads, (recording / "ownship.jsonl").read_text().splitlines())}
    start = 1496318400.0
    position_var = nav["position_noise_m"] ** 2 + nav["position_bias_m"] ** 2
    fix = bag["/ownship/fix"][7]
    row = own[round(stamp_s(fix) - start, 6)]
    assert fix.position_covariance_type == 2  # DIAGONAL_KNOWN
    np.testing.assert_allclose(np.diag(np.reshape(fix.position_covariance, (3, 3))), [position_var] * 3)
    assert fix.altitude == pytest.approx(row["z"] + nav["geoid_separation_m"])

    imu, odom, pose = bag["/ownship/imu"][7], bag["/ownship/odom"][7], bag["/ownship/pose"][7]
    assert stamp_s(imu) == stamp_s(odom) == stamp_s(fix)
    q = imu.orientation
    assert (q.x, q.y, q.z, q.w) == pytest.approx((pose.pose.orientation.x, pose.pose.orientation.y,
                                                  pose.pose.orientation.z, pose.pose.orientation.w))
    yaw = np.arctan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y**2 + q.z**2))
    assert (90.0 - np.degrees(yaw)) % 360.0 == pytest.approx(row["heading_deg"], abs=1e-6)
    heading_var = np.radians(nav["heading_noise_deg"]) ** 2 + np.radians(nav["heading_bias_deg"]) ** 2
    assert np.reshape(imu.orientation_covariance, (3, 3))[2, 2] == pytest.approx(heading_var)
    # the yaw rate is the heading's change over +-0.1 s (clockwise heading = negative yaw about up)
    before, after = own[round(row["t"] - 0.1, 6)], own[round(row["t"] + 0.1, 6)]
    heading_rate = ((after["heading_deg"] - before["heading_deg"] + 180.0) % 360.0 - 180.0) / 0.2
    assert imu.angular_velocity.z == pytest.approx(-np.radians(heading_rate), abs=2e-3)
    # an accelerometer on a floating ship reads about g, mostly along its up axis
    f = np.array([imu.linear_acceleration.x, imu.linear_acceleration.y, imu.linear_acceleration.z])
    assert 8.0 < np.linalg.norm(f) < 11.6 and f[2] > 8.0
    assert (odom.header.frame_id, odom.child_frame_id) == ("map", "base_link")
    assert (odom.pose.pose.position.x, odom.pose.pose.position.y) == (row["x"], row["y"])
    assert odom.twist.twist.linear.x == pytest.approx(row["sog_mps"], abs=0.5)  # forward, within drift and attitude
    cov = np.reshape(odom.pose.covariance, (6, 6))
    np.testing.assert_allclose(np.diag(cov)[:2], [position_var] * 2)
    assert np.reshape(odom.twist.covariance, (6, 6))[0, 0] == pytest.approx(nav["velocity_noise_mps"] ** 2)


def test_bag_radar_picture_and_truth_labels_and_geojson(recording):
    bag = messages(recording)
    (image,) = bag["/radar/image/compressed"][:1]
    assert image.format == "png"
    assert bytes(image.data) == (recording / "radar" / "ppi" / "000000.png").read_bytes()
    assert stamp_s(image) == stamp_s(bag["/radar/sector"][0])
    markers = bag["/truth/objects"][1].markers
    assert markers[0].action == 3  # DELETEALL first: objects that left vanish at once
    labels = {m.id: m.text for m in markers if m.type == 9}  # TEXT_VIEW_FACING
    boxes = {m.id for m in markers if m.type == 1}
    assert set(labels) == boxes and labels[0] == "odin"
    geo = json.loads(bag["/truth/geojson"][1].geojson)
    truth = [json.loads(line) for line in (recording / "truth.jsonl").read_text().splitlines()]
    at_one = {r["name"]: r for r in truth if r["t"] == 1.0}
    assert geo["type"] == "FeatureCollection" and len(geo["features"]) == len(at_one)
    for feature in geo["features"]:
        lon, lat = feature["geometry"]["coordinates"]
        row = at_one[feature["properties"]["name"]]
        assert (lon, lat) == pytest.approx((row["centre_lon"], row["centre_lat"]), abs=1e-8)  # the centre
    by_id = {r["id"]: r for r in at_one.values()}
    for box in (m for m in markers if m.type == 1):  # each truth box stands about its object's centre
        row = by_id[box.id]
        assert (box.pose.position.x, box.pose.position.y) == pytest.approx((row["centre_x"], row["centre_y"]), abs=1e-3)
    berg = at_one["Iceberg_1"]  # a generated berg's centre is not its body origin
    assert math.hypot(berg["centre_x"] - berg["x"], berg["centre_y"] - berg["y"]) > 0.5


def test_the_foxglove_layout_names_topics_the_bag_has(recording):
    """docs/foxglove_layout.json opens a recording: every topic it names is in the bag (TDM topics after raysim run)."""
    layout = json.loads((REPO / "docs" / "foxglove_layout.json").read_text())
    panels = layout["configById"]
    assert {key.split("!")[0] for key in panels} == {"3D", "Map", "Image", "Plot"}
    named = set(panels["3D!raysim3d"]["topics"]) | set(panels["Map!raysimmap"]["topicColors"])
    named |= {panels["Map!raysimmap"]["followTopic"], panels["Image!raysimppi"]["imageMode"]["imageTopic"]}
    named |= {p["value"].split(".")[0] for p in panels["Plot!raysimplot"]["paths"]}
    bag = set(messages(recording))
    tdm_topics = {"/tdm/detected_targets", "/tdm/markers", "/tdm/detections", "/tdm/geojson"}
    assert {t for t in named if not t.startswith("/tdm/")} <= bag
    assert {t for t in named if t.startswith("/tdm/")} <= tdm_topics
    assert panels["3D!raysim3d"]["followTf"] == "base_link"

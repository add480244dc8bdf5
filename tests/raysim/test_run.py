"""``raysim run``: render, run the TDM, evaluate; the detected targets join the bag."""

from __future__ import annotations

import copy
import json

from raysim.cli import main as raysim_main

from ..conftest import BASE

METRIC_KEYS = {"ospa_m", "gospa_m", "position_rmse_m", "cog_rmse_deg", "sog_rmse_mps", "detection_rate",
               "false_targets_per_min", "id_switches", "nees", "per_sensor"}


def test_run_renders_detects_evaluates_and_bags_the_targets(write_scenario, tmp_path, capsys):
    data = copy.deepcopy(BASE)
    data["duration_s"] = 12
    data["sensors"]["lidar"]["enabled"] = True
    data["sensors"]["radar"]["enabled"] = True
    out = tmp_path / "run"
    assert raysim_main(["run", str(write_scenario(data)), "-o", str(out), "--no-progress"]) == 0
    printed = capsys.readouterr().out
    assert "OSPA" in printed and "GOSPA" in printed  # the evaluation table
    rows = [json.loads(line) for line in (out / "tdm" / "detected_targets.jsonl").read_text().splitlines()]
    assert rows and {r["mmsi"] for r in rows} >= {257000002}
    metrics = json.loads((out / "tdm" / "metrics.json").read_text())
    assert METRIC_KEYS <= set(metrics)
    for name in ("tracks.png", "errors.png"):
        assert (out / "tdm" / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["counts"]["tdm/detected_targets.jsonl"] == len(rows)
    assert "tdm" in manifest["wall_time_s"]

    from mcap.reader import make_reader
    from mcap_ros2.decoder import DecoderFactory

    (bag,) = (out / "rosbag").glob("*.mcap")
    with open(bag, "rb") as handle:
        msgs = [(ch.topic, m) for _, ch, _, m in make_reader(handle, decoder_factories=[DecoderFactory()])
                .iter_decoded_messages(topics=["/tdm/detected_targets"])]
    epochs = sorted({r["t"] for r in rows})
    assert len(msgs) == len(epochs) == manifest["counts"]["rosbag/tdm/detected_targets"]
    first = [r for r in rows if r["t"] == epochs[0]]
    got = msgs[0][1].targets
    assert [t.target_id for t in got] == [r["target_id"] for r in first]
    assert abs(got[0].latitude - first[0]["latitude"]) < 1e-9
    assert list(got[0].sources) == first[0]["sources"]


def test_run_bags_the_targets_as_standard_markers_detections_and_geojson(write_scenario, tmp_path):
    from mcap.reader import make_reader
    from mcap_ros2.decoder import DecoderFactory

    from raysim.geodesy import LocalFrame
    from raysim.recording.rosbag.objects import target_box_m

    data = copy.deepcopy(BASE)
    data["duration_s"] = 12
    out = tmp_path / "run"
    assert raysim_main(["run", str(write_scenario(data)), "-o", str(out), "--no-progress"]) == 0
    rows = [json.loads(line) for line in (out / "tdm" / "detected_targets.jsonl").read_text().splitlines()]
    last_t = max(r["t"] for r in rows)
    last = {r["target_id"]: r for r in rows if r["t"] == last_t}
    (bag,) = (out / "rosbag").glob("*.mcap")
    topics = ["/tdm/markers", "/tdm/detections", "/tdm/geojson"]
    with open(bag, "rb") as handle:
        got = {}
        for _, ch, _, m in make_reader(handle, decoder_factories=[DecoderFactory()]).iter_decoded_messages(topics=topics):
            got.setdefault(ch.topic, []).append(m)
    epochs = sorted({r["t"] for r in rows})
    assert all(len(got[t]) == len(epochs) for t in topics)
    frame = LocalFrame(data["origin"]["lat"], data["origin"]["lon"])

    markers = got["/tdm/markers"][-1].markers
    assert markers[0].action == 3  # DELETEALL, then a box and a label per target
    boxes = {m.id: m for m in markers if m.type == 1}
    labels = {m.id: m.text for m in markers if m.type == 9}
    assert set(boxes) == set(labels) == set(last)
    for target_id, r in last.items():
        x, y = frame.to_local(r["latitude"], r["longitude"])
        box = boxes[target_id]
        assert (box.pose.position.x, box.pose.position.y) == (float(x), float(y))
        assert (box.scale.x, box.scale.y, box.scale.z) == target_box_m(r["object_descriptor"], r["cross_section_m2"])
        assert labels[target_id] == f"T{target_id} {r['object_descriptor']} {r['sog_mps'] * 3600 / 1852:.1f} kn"

    detections = {int(d.id): d for d in got["/tdm/detections"][-1].detections}
    assert set(detections) == set(last)
    for target_id, d in detections.items():
        assert d.results[0].hypothesis.class_id == last[target_id]["object_descriptor"]
        cov = [[d.results[0].pose.covariance[0], d.results[0].pose.covariance[1]],
               [d.results[0].pose.covariance[6], d.results[0].pose.covariance[7]]]
        assert cov == last[target_id]["position_cov_m2"]
        assert d.bbox.center.position.x == boxes[target_id].pose.position.x

    geo = json.loads(got["/tdm/geojson"][-1].geojson)
    features = {f["properties"]["target_id"]: f for f in geo["features"]}
    assert set(features) == set(last)
    for target_id, f in features.items():
        assert f["geometry"]["coordinates"] == [round(last[target_id]["longitude"], 9),
                                                round(last[target_id]["latitude"], 9)]
        assert f["properties"]["class"] == last[target_id]["object_descriptor"]

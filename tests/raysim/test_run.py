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

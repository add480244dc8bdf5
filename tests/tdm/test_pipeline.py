"""``tdm run`` / ``tdm evaluate`` end to end on rendered recordings, and on broken ones.

The thresholds are the TDM issue's "done when" criteria: every object reported within 10 s
of becoming visible, median position error <= 5 m within LiDAR range and <= 15 m with radar
alone, at most one false target per minute, at most one id switch per object.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from tdm.cli import main as tdm_main

from .conftest import REPO, render_recording

CONTRACT_FIELDS = {"t", "target_id", "object_descriptor", "longitude", "latitude", "cog_deg", "sog_mps",
                   "cross_section_m2", "sources", "position_cov_m2"}


def run_and_evaluate(recording: Path, *extra: str) -> dict:
    assert tdm_main(["run", str(recording), *extra]) == 0
    assert tdm_main(["evaluate", str(recording), "--no-plots"]) == 0
    return json.loads((recording / "tdm" / "metrics.json").read_text())


@pytest.fixture(scope="module")
def crossing(tmp_path_factory) -> tuple[Path, dict]:
    """crossing_silent_ship for 120 s (the silent ship and the ferry both in view), run and evaluated."""
    rec = render_recording(REPO / "scenarios" / "crossing_silent_ship.yaml", tmp_path_factory.mktemp("x") / "rec", 120.0)
    return rec, run_and_evaluate(rec)


@pytest.fixture(scope="module")
def busy(bos_recording, tmp_path_factory) -> tuple[Path, dict]:
    """The session's 40 s of busy_open_sea (linked, not copied), run and evaluated into a directory of its own."""
    rec = tmp_path_factory.mktemp("bos") / "rec"
    rec.mkdir()
    for entry in bos_recording.iterdir():
        if entry.name != "tdm":
            (rec / entry.name).symlink_to(entry)
    return rec, run_and_evaluate(rec)


def check_done_when(metrics: dict, latency_limit_s: float = 10.0, false_per_min: float = 1.0,
                    false_targets: bool = True) -> None:
    assert metrics["missed_objects"] == []
    assert metrics["detection_latency_max_s"] <= latency_limit_s, metrics["detection_latency_s"]
    assert metrics["median_position_error_within_lidar_range_m"] <= 5.0
    assert metrics["per_sensor"]["radar"]["median_position_error_m"] <= 15.0
    if false_targets:
        assert metrics["false_targets_per_min"] <= false_per_min, metrics["false_target_ids"]
    assert metrics["id_switches_max_per_object"] <= 1


def test_detected_targets_follow_the_contract(busy):
    rec, _ = busy
    rows = [json.loads(line) for line in (rec / "tdm" / "detected_targets.jsonl").read_text().splitlines()]
    assert rows
    for row in rows:
        assert CONTRACT_FIELDS <= set(row)
        assert set(row["sources"]) <= {"ais", "lidar", "radar"} and row["sources"]
        assert row["object_descriptor"] in {"vessel", "iceberg", "fixed obstacle", "unknown"}
        cov = np.array(row["position_cov_m2"])
        assert np.allclose(cov, cov.T) and np.all(np.linalg.eigvalsh(cov) > 0)
        assert 0 <= row["cog_deg"] < 360 and row["sog_mps"] >= 0
    times = sorted({r["t"] for r in rows})
    assert np.allclose(np.diff(times), 1.0)  # tdm.update_rate_hz = 1
    # the AIS ships are vessels with their MMSI
    mmsis = {r["mmsi"] for r in rows if r["mmsi"] is not None}
    assert mmsis == {257000001, 257000002}
    assert all(r["object_descriptor"] == "vessel" for r in rows if r["mmsi"] is not None)


def test_crossing_with_a_silent_ship_meets_the_done_criteria(crossing):
    rec, metrics = crossing
    check_done_when(metrics)
    silent = next(o for o in metrics["per_object"] if o["name"] == "silent_crosser")
    assert silent["matched_fraction"] > 0.8  # found without AIS, by radar and LiDAR


def test_crossing_classifies_ships_as_vessels_and_bergs_as_icebergs(crossing):
    # ships are vessels, bergs icebergs (after the 20 s it takes to call something still): 0.66 since the radar's
    # tracks try their course again (TrackerConfig.course_retry_s; a strict expected failure from issue 19's coherent
    # radar, whose shorter plots of mirror-like hulls took it to 0.44, until then)
    _, metrics = crossing
    assert metrics["classification_accuracy"] >= 0.5


def test_busy_open_sea_meets_the_done_criteria(busy):
    _, metrics = busy
    check_done_when(metrics, false_targets=False)
    # the clock starts when an object comes into view: radar occlusion behind a nearer berg is ray truth
    assert metrics["parameters"]["radar_visibility"] == "rays"


def test_busy_open_sea_has_at_most_one_false_target_a_minute(busy):
    """Failed (strict xfail) until the radar front end dropped sidelobe-arc plots (docs/tdm.md, "Sidelobe arcs")."""
    _, metrics = busy
    assert metrics["false_targets_per_min"] <= 1.0, metrics["false_target_ids"]


def test_fusion_beats_the_single_sensors_where_they_overlap(busy):
    _, metrics = busy
    assert metrics["ospa_m"] <= metrics["per_sensor"]["radar"]["ospa_m"] + 0.5
    assert metrics["detection_rate"] >= max(metrics["per_sensor"]["radar"]["detection_rate"] - 0.02, 0.8)


def test_identical_runs_give_identical_bytes_with_or_without_workers(bos_recording, tmp_path):
    outs = []
    for workers in ("2", "0"):
        out = tmp_path / f"w{workers}"
        assert tdm_main(["run", str(bos_recording), "-o", str(out), "--workers", workers]) == 0
        outs.append((out / "detected_targets.jsonl").read_bytes() + (out / "sensor_tracks.jsonl").read_bytes())
    assert outs[0] == outs[1]


def test_pcap_and_npz_lidar_give_the_same_targets(bos_recording, tmp_path):
    a, b = tmp_path / "npz", tmp_path / "pcap"
    assert tdm_main(["run", str(bos_recording), "-o", str(a), "--lidar-source", "npz"]) == 0
    assert tdm_main(["run", str(bos_recording), "-o", str(b), "--lidar-source", "pcap"]) == 0
    ra = [json.loads(x) for x in (a / "detected_targets.jsonl").read_text().splitlines()]
    rb = [json.loads(x) for x in (b / "detected_targets.jsonl").read_text().splitlines()]
    assert abs(len(ra) - len(rb)) <= 0.05 * len(ra)
    assert {r["target_id"] for r in ra if "lidar" in r["sources"]}  # the LiDAR contributes in both
    assert {r["target_id"] for r in rb if "lidar" in r["sources"]}


# ---- broken recordings ------------------------------------------------------------------------

def broken_copy(src: Path, dst: Path) -> Path:
    shutil.copytree(src, dst, ignore=shutil.ignore_patterns("rosbag", "bev", "ppi", "tdm"))
    return dst


def test_missing_and_cut_sweeps_and_bad_nmea_are_counted_warnings(bos_recording, tmp_path, capsys):
    rec = broken_copy(bos_recording, tmp_path / "rec")
    sweeps = sorted((rec / "lidar" / "sweeps").glob("*.npz"))
    sweeps[10].unlink()  # a missing sweep
    sweeps[20].write_bytes(sweeps[20].read_bytes()[:500])  # a cut sweep
    radar = sorted((rec / "radar" / "sweeps").glob("*.npz"))
    radar[3].write_bytes(b"not a zip file")
    with open(rec / "ais" / "ais.nmea", "a", encoding="ascii") as handle:
        handle.write("\\c:1496318430*5E\\!AIVDM,1,1,,A,13m62@P41gPgwLdR0eraOWV00000,0*00\n")  # bad checksum
        handle.write("garbage line\n")
    pcap = rec / "lidar" / "hdl32e.pcap"
    pcap.write_bytes(pcap.read_bytes()[: pcap.stat().st_size // 2 + 77])  # a cut PCAP
    capsys.readouterr()
    assert tdm_main(["run", str(rec)]) == 0
    err = capsys.readouterr().err
    assert "lidar: sweep files missing from the numbering: 1" in err
    assert "lidar/sweeps: unreadable sweep files" in err and "radar/sweeps: unreadable sweep files" in err
    assert err.count("ais/nmea") >= 2
    assert tdm_main(["run", str(rec), "-o", str(tmp_path / "p"), "--lidar-source", "pcap"]) == 0
    assert "lidar/pcap" in capsys.readouterr().err
    assert (rec / "tdm" / "detected_targets.jsonl").stat().st_size > 0


@pytest.mark.parametrize("breakage, expect", [
    ("no_directory", "not a directory"),
    ("no_manifest", "manifest.json: (file): missing"),
    ("bad_ownship", "ownship.jsonl: line 3: not valid JSON"),
    ("bad_scenario", "scenario.yaml"),
    ("misspelt_key", "scenario.yaml: sensors.lidar.range_max_mm: unknown key (did you mean 'range_max_m'?)"),
    ("no_sensor_data", "holds no LiDAR, radar or AIS data"),
    ("pcap_garbage", "hdl32e.pcap"),
])
def test_unreadable_recordings_give_one_line_and_exit_2(bos_recording, tmp_path, capsys, breakage, expect):
    rec = tmp_path / "rec"
    extra: list[str] = []
    if breakage != "no_directory":
        shutil.copytree(bos_recording, rec, ignore=shutil.ignore_patterns("rosbag", "bev", "ppi", "sweeps", "tdm"))
        if breakage == "no_manifest":
            (rec / "manifest.json").unlink()
        elif breakage == "bad_ownship":
            lines = (rec / "ownship.jsonl").read_text().splitlines()
            lines[2] = lines[2][:30]
            (rec / "ownship.jsonl").write_text("\n".join(lines) + "\n")
        elif breakage == "bad_scenario":
            (rec / "scenario.yaml").write_text("sensors: [unclosed\n")
        elif breakage == "misspelt_key":  # hand-edited: the TDM would run on the LiDAR's default range
            text = (rec / "scenario.yaml").read_text()
            assert text.count("range_max_m:") == 1
            (rec / "scenario.yaml").write_text(text.replace("range_max_m:", "range_max_mm:"))
        elif breakage == "no_sensor_data":
            shutil.rmtree(rec / "lidar")
            shutil.rmtree(rec / "radar")
            shutil.rmtree(rec / "ais")
        elif breakage == "pcap_garbage":
            (rec / "lidar" / "hdl32e.pcap").write_bytes(b"\x00" * 100)
            extra = ["--lidar-source", "pcap"]
    capsys.readouterr()
    assert tdm_main(["run", str(rec), *extra]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("error: ") and expect in err
    assert not (rec / "tdm").exists()  # nothing left behind


def test_a_run_shorter_than_a_radar_revolution_has_no_radar_sweep_and_runs(bos_recording, tmp_path, capsys):
    """An empty radar/sweeps is a partial copy only where manifest.json counts sweeps: a 1 s run has none."""
    rec = tmp_path / "rec"
    shutil.copytree(bos_recording, rec, ignore=shutil.ignore_patterns("rosbag", "bev", "ppi", "sweeps", "tdm"))
    (rec / "radar" / "sweeps").mkdir()
    manifest = json.loads((rec / "manifest.json").read_text())
    assert manifest["counts"]["radar/sweeps"] > 0
    manifest["counts"]["radar/sweeps"] = 0
    (rec / "manifest.json").write_text(json.dumps(manifest))
    assert tdm_main(["run", str(rec)]) == 0
    assert (rec / "tdm" / "detected_targets.jsonl").stat().st_size > 0


def test_evaluate_without_a_run_is_an_error(bos_recording, tmp_path, capsys):
    rec = broken_copy(bos_recording, tmp_path / "rec")
    assert tdm_main(["evaluate", str(rec)]) == 2
    assert "run `tdm run` first" in capsys.readouterr().err


@pytest.mark.parametrize("workers", [0, 2])
def test_the_detection_stream_is_in_time_order_and_complete(bos_recording, workers):
    from tdm.detections import ReadStats
    from tdm.pipeline import DetectionStream, TdmConfig

    events = list(DetectionStream(bos_recording, TdmConfig(workers=workers), ReadStats()).events())
    times = np.array([e[0] for e in events])
    assert np.all(np.diff(times) >= 0)
    sensors = [e[1] for e in events]
    assert sensors.count("lidar") == len(list((bos_recording / "lidar" / "sweeps").glob("*.npz")))
    assert sensors.count("radar") == len(list((bos_recording / "radar" / "sweeps").glob("*.npz")))
    # the sensors are interleaved, not one after the other
    first_radar = sensors.index("radar")
    assert sensors[first_radar + 1:].count("lidar") > 0.8 * sensors.count("lidar")


def test_radar_tracks_report_their_face_offset_along_the_line_of_sight_from_the_own_ship(busy, tmp_path):
    """sensor_tracks.jsonl with ``radar_track_face_covariance`` (the default) against without it: the same positions;
    each radar track's covariance differs by a u^T (the face offset along the line of sight u from the own ship at
    that epoch) minus b I (the 0.5 x length per axis it replaces), so the difference's larger eigenvector points
    along u and its other eigenvalue is not positive."""
    from dataclasses import replace

    from groundfloor.frames import LocalFrame
    from tdm.pipeline import run_tdm
    from tdm.run_config import TdmConfig

    rec, _ = busy
    on = TdmConfig.for_recording(rec)
    off = replace(on, fusion_config=replace(on.fusion_config, radar_track_face_covariance=False))
    run_tdm(rec, tmp_path / "off", off)

    def radar_rows(path: Path) -> dict:
        rows = (json.loads(line) for line in path.read_text().splitlines())
        return {(r["t"], r["target_id"]): r for r in rows if r["sensor"] == "radar"}

    on_rows = radar_rows(rec / "tdm" / "sensor_tracks.jsonl")
    off_rows = radar_rows(tmp_path / "off" / "sensor_tracks.jsonl")
    assert on_rows.keys() == off_rows.keys() and len(on_rows) > 20
    own = [json.loads(line) for line in (rec / "ownship.jsonl").read_text().splitlines()]
    own_t = np.array([o["t"] for o in own])
    frame = LocalFrame(own[0]["lat"], own[0]["lon"])
    aligned = 0
    for key, on in on_rows.items():
        off_row = off_rows[key]
        assert (on["latitude"], on["longitude"]) == (off_row["latitude"], off_row["longitude"])
        d = np.array(on["position_cov_m2"]) - np.array(off_row["position_cov_m2"])
        values, vectors = np.linalg.eigh(d)
        i = int(np.argmin(np.abs(own_t - key[0])))
        e, n = frame.to_local(np.array([on["latitude"], own[i]["lat"]]), np.array([on["longitude"], own[i]["lon"]]))
        u = np.array([e[0] - e[1], n[0] - n[1]])
        u /= np.hypot(*u)
        assert values[0] <= 1e-3
        if values[1] - values[0] > 1.0:  # the offset is not lost in the rounding
            assert abs(vectors[:, 1] @ u) > np.cos(np.radians(1.0)), key
            aligned += 1
    assert aligned > 0.5 * len(on_rows)

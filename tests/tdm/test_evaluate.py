"""tdm.evaluate and tdm.plots on synthetic recordings with known offsets, and on a rendered one."""

from __future__ import annotations

import json
import math
import os
import shutil

import numpy as np
import pytest

from tdm.errors import RecordingError
from tdm.eval_truth import NO_MMSI, TruthAtEpochs
from tdm.eval_visibility import ais_in_view
from tdm.evaluate import _sustained_start, evaluate, format_table, write_metrics
from tdm.plots import plot_errors, plot_tracks

from tdm.frames import EnuFrame

from .eval_helpers import DURATION_S, LAT0, LON0, _line, _objects, make_recording, save_sweep

C = 50.0
CONTRACT_KEYS = {"ospa_m", "gospa_m", "position_rmse_m", "cog_rmse_deg", "sog_rmse_mps", "detection_rate",
                 "false_targets_per_min", "id_switches", "nees", "per_sensor"}


@pytest.fixture(scope="module")
def synthetic(tmp_path_factory):
    rec = make_recording(tmp_path_factory.mktemp("synthetic") / "rec")
    return rec, evaluate(rec)


def test_known_offsets_give_known_errors(synthetic):
    _, m = synthetic
    assert CONTRACT_KEYS <= set(m)
    assert m["epochs"] == 21
    assert m["position_rmse_m"] == pytest.approx(3.0, abs=1e-4)
    assert m["median_position_error_m"] == pytest.approx(3.0, abs=1e-4)
    assert m["median_position_error_within_lidar_range_m"] == pytest.approx(3.0, abs=1e-4)
    assert m["median_position_error_beyond_lidar_range_m"] == pytest.approx(3.0, abs=1e-4)
    assert m["position_bias_east_m"] == pytest.approx(3.0, abs=1e-4)
    assert m["cog_rmse_deg"] == pytest.approx(2.0, abs=1e-6)  # 358 vs 0, wrapped; alpha only: the others do not move
    assert m["sog_rmse_mps"] == pytest.approx(math.sqrt(21 * 0.25 / 79), rel=1e-5)
    # NEES: 63 pairs at 9/4, charlie's 16 at 9 (outside the 95 % interval [0.05, 7.38])
    assert m["nees"] == pytest.approx((63 * 2.25 + 16 * 9) / 79, rel=1e-4)
    assert m["nees_fraction_in_95"] == pytest.approx(63 / 79, rel=1e-5)
    assert m["classification_accuracy"] == pytest.approx(63 / 79, rel=1e-5)


def test_detection_latency_switches_and_false_targets(synthetic):
    _, m = synthetic
    # in range: alpha, bravo, charlie (radar) and echo (AIS) at 21 epochs; delta never
    assert m["in_range_pairs"] == 84 and m["matched_pairs"] == 79
    assert m["detection_rate"] == pytest.approx(79 / 84, rel=1e-5)
    assert m["detection_latency_s"] == {"alpha": 0.0, "bravo": 0.0, "charlie": 5.0, "echo": 0.0}
    assert m["detection_latency_max_s"] == 5.0
    assert m["detection_latency_from_first_in_range_max_s"] == 5.0  # charlie: in range from 0 s, found at 5 s
    assert m["missed_objects"] == []
    assert m["id_switches"] == 1 and m["id_switches_max_per_object"] == 1
    assert m["false_target_ids"] == [99]
    assert m["false_targets_per_min"] == pytest.approx(1 / (DURATION_S / 60))
    assert m["false_reports"] == 21
    assert m["false_reports_per_min"] == pytest.approx(21 / (DURATION_S / 60))
    rows = {o["name"]: o for o in m["per_object"]}
    assert set(rows) == {"alpha", "bravo", "charlie", "echo"}
    assert rows["bravo"]["target_ids"] == [2, 7] and rows["bravo"]["id_switches"] == 1
    assert rows["charlie"]["matched_fraction"] == pytest.approx(16 / 21, rel=1e-5)
    assert rows["charlie"]["first_in_range_s"] == 0.0 and rows["charlie"]["latency_s"] == 5.0


def test_false_target_is_one_matched_at_fewer_than_half_its_epochs(tmp_path):
    def lines(frame):
        out = []
        for t in range(21):
            truth = {o[1]: o for o in _objects(float(t))}
            a, b, ch = truth["alpha"], truth["bravo"], truth["charlie"]
            out.append(_line(frame, float(t), a[3], a[4], target_id=1))
            # 40: on bravo at 7 of its 21 epochs (false); 41: on charlie at 14 of 21 (not false)
            out.append(_line(frame, float(t), *((b[3], b[4]) if t < 7 else (0.0, -700.0)), target_id=40))
            out.append(_line(frame, float(t), *((ch[3], ch[4]) if t < 14 else (0.0, -800.0)), target_id=41))
        return out

    m = evaluate(make_recording(tmp_path / "rec", targets=lines, tracks=False))
    assert m["false_target_ids"] == [40]
    assert m["false_reports"] == 14 + 7
    assert m["missed_objects"] == ["echo"] and m["detection_latency_s"]["echo"] is None
    assert m["detection_rate"] == pytest.approx((21 + 7 + 14) / 84, rel=1e-5)
    assert m["nees"] is None and m["cog_rmse_deg"] is None  # no covariance, no COG reported
    assert m["position_rmse_m"] == pytest.approx(0.0, abs=1e-4)


def test_id_switches_follow_the_clear_mot_correspondence(tmp_path):
    def lines(frame):
        out = []
        for t in range(21):
            truth = {o[1]: o for o in _objects(float(t))}
            a, b = truth["alpha"], truth["bravo"]
            out.append(_line(frame, float(t), a[3], a[4], target_id=1))
            # two targets on bravo, 2 and 4 m off, the nearer one changing every second; 40 leaves at 15 s
            near, far = (40, 41) if t % 2 == 0 and t < 15 else (41, 40)
            out.append(_line(frame, float(t), b[3] + 2.0, b[4], target_id=near))
            out.append(_line(frame, float(t), b[3] - 4.0, b[4] + (200.0 if t >= 15 else 0.0), target_id=far))
        return out

    m = evaluate(make_recording(tmp_path / "rec", targets=lines, tracks=False))
    bravo = {o["name"]: o for o in m["per_object"]}["bravo"]
    # per-epoch optimal: 40, 41, 40, ... to 14 s (14 changes), then 41 (one more); CLEAR MOT: 40 kept to 14 s
    assert bravo["id_switches_per_epoch_assignment"] == 15
    assert bravo["id_switches"] == 1 and m["id_switches"] == 1 and m["id_switches_max_per_object"] == 1
    assert m["id_switches_per_epoch_assignment"] == 15
    # the errors keep the optimal assignment: bravo's nearer target, 2 m off, at every epoch but the last six
    assert bravo["median_error_m"] == pytest.approx(2.0, abs=1e-3)


def test_ospa_and_gospa_means(synthetic):
    _, m = synthetic
    # t < 5: 4 truths, 4 targets, 3 pairs at 3 m, charlie vs the false target beyond c
    # t >= 5: 4 truths, 5 targets, 4 pairs at 3 m, one false target
    ospa_early, ospa_late = math.sqrt((3 * 9 + C ** 2) / 4), math.sqrt((4 * 9 + C ** 2) / 5)
    gospa_early, gospa_late = math.sqrt(3 * 9 + C ** 2 / 2 * 2), math.sqrt(4 * 9 + C ** 2 / 2)
    assert m["ospa_m"] == pytest.approx((5 * ospa_early + 16 * ospa_late) / 21, rel=1e-5)
    assert m["gospa_m"] == pytest.approx((5 * gospa_early + 16 * gospa_late) / 21, rel=1e-5)
    # within the LiDAR's 200 m of the own ship, c = 10 m: alpha alone (100-116 m off) and its report 3 m east
    assert m["gospa_within_lidar_range_c10_m"] == pytest.approx(3.0, rel=1e-5)
    s = m["series"]
    assert len(s["t_s"]) == 21 and s["ospa_m"][0] == pytest.approx(ospa_early, rel=1e-5)
    assert s["n_in_range"] == [4] * 21 and s["n_reports"] == [4] * 5 + [5] * 16
    assert len(s["pairs"]["error_m"]) == 79


def test_per_sensor_metrics_use_each_sensors_range(synthetic):
    _, m = synthetic
    ais, radar = m["per_sensor"]["ais"], m["per_sensor"]["radar"]
    assert "per_sensor" not in ais and "series" not in ais
    assert ais["position_rmse_m"] == pytest.approx(0.0, abs=1e-4)
    assert ais["detection_rate"] == 1.0  # AIS sees alpha and echo only
    assert ais["cog_rmse_deg"] == pytest.approx(0.0, abs=1e-6)
    assert radar["position_rmse_m"] == pytest.approx(1.0, abs=1e-4)
    assert radar["detection_rate"] == pytest.approx(21 / 63, rel=1e-5)  # radar range holds alpha, bravo, charlie
    assert radar["nees"] == pytest.approx(1.0, rel=1e-4)
    assert "_pairs" not in ais and "_pairs" not in m
    # each object is tracked by one sensor only (AIS: alpha and echo, radar: bravo): none to set the fusion against
    assert m["fusion_against_sensors"]["summary"]["objects_compared"] == 0


def test_metrics_json_is_atomic_sorted_and_null_for_nan(synthetic, tmp_path):
    rec, m = synthetic
    out = write_metrics(rec, m)
    assert out == rec / "tdm" / "metrics.json"
    assert [p.name for p in out.parent.iterdir() if p.name.endswith(".tmp")] == []
    text = out.read_text(encoding="utf-8")
    loaded = json.loads(text)
    assert loaded == m
    assert list(loaded) == sorted(loaded)
    assert "NaN" not in text and "Infinity" not in text
    # nothing reported: NaN metrics become null
    empty = make_recording(tmp_path / "empty", tracks=False)
    (empty / "tdm" / "detected_targets.jsonl").write_text("", encoding="utf-8")
    e = evaluate(empty)
    assert e["position_rmse_m"] is None and e["nees"] is None and e["detection_rate"] == 0.0
    assert e["ospa_m"] == pytest.approx(C) and e["gospa_m"] == pytest.approx(math.sqrt(4 * C ** 2 / 2))
    assert e["missed_objects"] == ["alpha", "bravo", "charlie", "echo"]
    assert e["detection_latency_s"]["charlie"] is None and e["per_sensor"] == {}
    assert "null" in write_metrics(empty, e).read_text(encoding="utf-8")


def test_format_table_names_metrics_sensors_and_objects(synthetic):
    _, m = synthetic
    table = format_table(m)
    for word in ("OSPA", "GOSPA", "NEES", "fused", "ais", "radar", "alpha", "charlie", "5.0"):
        assert word in table
    assert "delta" not in table


def test_missing_targets_and_bad_lines_are_recording_errors(tmp_path):
    rec = make_recording(tmp_path / "rec", targets=False, tracks=False)
    with pytest.raises(RecordingError) as err:
        evaluate(rec)
    assert err.value.file.endswith("detected_targets.jsonl") and "tdm run" in err.value.what
    path = rec / "tdm" / "detected_targets.jsonl"
    path.write_text('{"t": 0.0, "target_id": 1, "longitude": 10.47, "latitude": 59.43}\n\n'
                    '{"t": 1.0, "target_id": 1, "longitude": 10.47}\n', encoding="utf-8")
    with pytest.raises(RecordingError) as err:
        evaluate(rec)
    assert err.value.where == "line 3" and "latitude" in err.value.what
    path.write_text("", encoding="utf-8")
    (rec / "scenario.yaml").write_text("sensors: {radar: {range_m: far}}\n", encoding="utf-8")
    with pytest.raises(RecordingError) as err:
        evaluate(rec)
    assert err.value.file.endswith("scenario.yaml") and err.value.where == "sensors.radar.range_m"


def test_lidar_visibility_comes_from_the_sweeps_object_ids(tmp_path):
    """LiDAR alone: an object is in range only within +-0.5 s of a point that hit it."""
    rec = make_recording(tmp_path / "rec", sensors=("lidar",), tracks=False)
    sweeps = rec / "lidar" / "sweeps"
    sweeps.mkdir(parents=True)
    for i, t0 in enumerate([3.0, 7.6, 12.0]):
        t = t0 + np.linspace(0.0, 0.099, 100)
        oid = np.full(100, -1, dtype=np.int32)
        if t0 != 7.6:
            oid[40:50] = 2  # bravo, at t0 + 0.04 .. t0 + 0.05 s
        np.savez(sweeps / f"{i:06d}.npz", x=np.zeros(100, np.float32), time=t, object_id=oid)
    m = evaluate(rec)
    assert m["parameters"]["lidar_visibility"] == "hits"
    assert m["in_range_pairs"] == 2 and m["matched_pairs"] == 2
    rows = {o["name"]: o for o in m["per_object"]}
    assert list(rows) == ["bravo"] and rows["bravo"]["first_in_range_s"] == 3.0
    assert rows["bravo"]["latency_s"] == 0.0
    assert m["id_switches"] == 1  # target 2 at t = 3, target 7 at t = 12
    # sweeps without object_id: the LiDAR's range (200 m) stands in
    for f in sweeps.iterdir():
        np.savez(f, x=np.zeros(3, np.float32), time=np.zeros(3))
    m = evaluate(rec)
    assert m["parameters"]["lidar_visibility"] == "range"
    assert {o["name"] for o in m["per_object"]} == {"alpha"}  # 100..117 m from the own ship


def test_plots_are_deterministic_pngs(synthetic):
    rec, m = synthetic
    a = plot_tracks(rec)
    b = plot_errors(rec, m)
    assert a == rec / "tdm" / "tracks.png" and b == rec / "tdm" / "errors.png"
    first = a.read_bytes(), b.read_bytes()
    for data in first:
        assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 10_000
    plot_tracks(rec)
    plot_errors(rec, m["series"])
    assert (a.read_bytes(), b.read_bytes()) == first
    write_metrics(rec, m)
    other = plot_errors(rec, None, rec / "tdm" / "errors_again.png")
    assert other.read_bytes() == first[1]


def test_perfect_targets_on_a_rendered_recording(bos_recording, tmp_path):
    """Targets placed on the truth of a real recording (each object's centre) score zero error and full detection."""
    rec = tmp_path / "rec"
    (rec / "lidar").mkdir(parents=True)
    for name in ("truth.jsonl", "scenario.yaml", "manifest.json"):
        shutil.copy(bos_recording / name, rec / name)
    os.symlink(bos_recording / "lidar" / "sweeps", rec / "lidar" / "sweeps")
    (rec / "tdm").mkdir()
    truth = [json.loads(line) for line in open(rec / "truth.jsonl", encoding="utf-8")]
    with open(rec / "tdm" / "detected_targets.jsonl", "w", encoding="utf-8") as f:
        for r in truth:
            if r["kind"] != "ownship" and abs(r["t"] - round(r["t"])) < 1e-6:
                f.write(json.dumps({"t": float(round(r["t"])), "target_id": 100 + r["id"],
                                    "object_descriptor": {"ship": "vessel"}.get(r["kind"], r["kind"]),
                                    "longitude": r["centre_lon"], "latitude": r["centre_lat"], "cog_deg": r["cog_deg"],
                                    "sog_mps": r["sog_mps"], "cross_section_m2": 1.0, "sources": ["radar"],
                                    "position_cov_m2": [[1.0, 0.0], [0.0, 1.0]]}) + "\n")
    m = evaluate(rec)
    assert m["parameters"]["lidar_visibility"] == "hits"
    assert m["position_rmse_m"] == pytest.approx(0.0, abs=1e-3)
    assert m["ospa_m"] == pytest.approx(0.0, abs=1e-3)
    assert m["detection_rate"] == 1.0 and m["false_reports"] == 0 and m["id_switches"] == 0
    assert m["detection_latency_max_s"] == 0.0
    n_objects = len({r["id"] for r in truth if r["kind"] != "ownship"})
    assert m["objects_in_range"] == n_objects  # the radar's 1852 m holds the whole scene


def test_a_glimpse_does_not_start_the_latency_clock():
    t_s = np.arange(30.0)
    # in range at 2-3 s (a glimpse between occlusions), then 6-8 s (3 s: still too short), then from 12 s on
    vis_e = np.r_[2, 3, 6, 7, 8, np.arange(12, 30)]
    assert _sustained_start(vis_e, t_s) == 12
    assert _sustained_start(np.arange(0, 6), t_s) == 0  # 0..5 s: a 5 s run counts from its start
    assert _sustained_start(np.r_[4, 5, 9], t_s) == 4  # never in view 5 s: the first in-range epoch


def test_an_object_comes_into_the_radars_view_when_the_beam_passes_it(tmp_path):
    rec = make_recording(tmp_path / "rec")
    sweeps = rec / "radar" / "sweeps"
    sweeps.mkdir(parents=True)
    for rev in range(8):  # charlie (id 3, due west: 6 of 8 spokes into a revolution) first reached in revolution 2
        save_sweep(sweeps, rev, [1, 2, 3] if rev >= 2 else [1, 2])
    m = evaluate(rec)
    charlie = next(o for o in m["per_object"] if o["name"] == "charlie")
    # revolution 2 starts at 5 s; the beam points west at 5 + 6/8 x 2.5 = 6.875 s: in view from epoch 7 (+- 0.5 s)
    assert charlie["first_in_range_s"] == 7.0 and charlie["in_view_from_s"] == 7.0
    bravo = next(o for o in m["per_object"] if o["name"] == "bravo")  # due north: the first spoke
    assert bravo["first_in_range_s"] == 0.0


def test_reports_of_an_object_hidden_from_the_radar_are_neither_matched_nor_false(tmp_path):
    rec = make_recording(tmp_path / "rec")
    sweeps = rec / "radar" / "sweeps"
    sweeps.mkdir(parents=True)
    for rev in range(8):  # 2.5 s revolutions; bravo (id 2) hidden behind something in revolutions 2-4 (5-12.5 s)
        ids = [1, 3] if 2 <= rev <= 4 else [1, 2, 3]
        save_sweep(sweeps, rev, ids)
    m = evaluate(rec)
    assert m["parameters"]["radar_visibility"] == "rays"
    # bravo's epochs 6-11 s are out of view (no revolution reaching it within +-0.5 s): its 6 reports are ignored
    assert m["ignored_reports"] == 6
    # and charlie (silent, due west) is seen from the beam's first pass over it, 1.875 s in: epochs 0 and 1 less
    assert m["in_range_pairs"] == 84 - 6 - 2 and m["matched_pairs"] == 79 - 6
    assert m["false_reports"] == 21 and m["false_target_ids"] == [99]  # only target 99, as without ray truth
    bravo = next(o for o in m["per_object"] if o["name"] == "bravo")
    assert bravo["epochs_in_range"] == 21 - 6


def test_an_unreadable_radar_sweep_counts_as_not_seen_as_in_tdm_run(tmp_path):
    """Not an archive at all (what a broken copy leaves): a counted warning under tdm run's key, not an error."""
    rec = make_recording(tmp_path / "rec")
    sweeps = rec / "radar" / "sweeps"
    sweeps.mkdir(parents=True)
    for rev in range(3):
        save_sweep(sweeps, rev, [1, 2, 3])
    (sweeps / "000001.npz").write_bytes(b"not an npz file")
    metrics = evaluate(rec)
    assert metrics["warnings"] == {"radar/sweeps: unreadable sweep files (not a zip archive), counted as not seen": 1}


def _with_centres(recording, east_m, own_east_m):
    """Give every truth line ``centre_lat``/``centre_lon``: the body origin moved ``east_m`` east (the own ship's
    ``own_east_m``)."""
    path = recording / "truth.jsonl"
    rows = [json.loads(line) for line in path.read_text(encoding="utf-8").splitlines()]
    from tdm.frames import EnuFrame
    from .eval_helpers import LAT0, LON0
    frame = EnuFrame(LAT0, LON0)
    for row in rows:
        shift = own_east_m if row["kind"] == "ownship" else east_m
        lat, lon = frame.to_geodetic(row["x"] + shift, row["y"])
        row["centre_lat"], row["centre_lon"] = float(lat), float(lon)
    path.write_text("".join(json.dumps(r) + "\n" for r in rows), encoding="utf-8")


def test_objects_are_scored_at_their_centre_when_truth_has_it(tmp_path):
    """The targets lie 3 m east of each body origin: 3 m off by the origin, on the centre when truth puts it there.
    The own ship stays at its body origin (the frame of the mounts), whatever its centre."""
    from tdm.eval_truth import read_truth_enu

    rec = make_recording(tmp_path / "rec")
    _with_centres(rec, 3.0, 50.0)
    m = evaluate(rec)
    assert m["position_rmse_m"] == pytest.approx(0.0, abs=1e-4)
    assert m["position_bias_east_m"] == pytest.approx(0.0, abs=1e-4)
    _, truth = read_truth_enu(rec)
    own = truth["kind"] == "ownship"
    assert np.allclose(truth["east_m"][own], 0.0, atol=1e-6)
    bravo = truth["name"] == "bravo"
    assert np.allclose(truth["east_m"][bravo], 3.0, atol=1e-6)


def test_an_ais_ship_comes_into_the_ais_view_with_its_first_report_received(tmp_path):
    """AIS sees a ship from its first position report in ais/ais.nmea; its targets before that are ignored."""
    from pyais import encode_dict

    from .test_frontend_ais import START, tagged, type1

    rec = make_recording(tmp_path / "rec")
    before = evaluate(rec)
    echo_before = next(o for o in before["per_object"] if o["name"] == "echo")  # 3 km off: the AIS's alone
    assert before["parameters"]["ais_visibility"] == "range" and echo_before["in_view_from_s"] == 0.0
    frame = EnuFrame(LAT0, LON0)
    lat, lon = frame.to_geodetic(0.0, -3000.0)
    sentence = encode_dict(type1(mmsi=257000005, speed=0.0, lon=float(lon), lat=float(lat)), talker_id="AI",
                           sentence_type="VDM")[0]
    (rec / "ais").mkdir()
    (rec / "ais" / "ais.nmea").write_text(tagged(int(START) + 8, sentence) + "\n", encoding="ascii")
    m = evaluate(rec)
    assert m["parameters"]["ais_visibility"] == "reports"
    echo = next(o for o in m["per_object"] if o["name"] == "echo")
    # a report in whole second 8 was received at 8.5 s (tdm.frontend.ais): in view from epoch 9
    assert echo["first_in_range_s"] == 9.0 and echo["latency_s"] == 0.0 and echo["epochs_in_range"] == 12
    # echo's 9 reports before its first AIS report are neither matched nor false; alpha (no report received)
    # stays in view through the radar
    assert m["ignored_reports"] == before["ignored_reports"] + 9
    assert m["matched_pairs"] == before["matched_pairs"] - 9
    assert m["false_reports"] == before["false_reports"]
    assert "alpha" in {o["name"] for o in m["per_object"]}
    assert "alpha" not in {o["name"] for o in m["per_sensor"]["ais"]["per_object"]}


def test_a_ship_leaves_the_ais_view_180_s_after_its_last_report():
    t_s = np.arange(0.0, 400.0, 10.0)
    truth = TruthAtEpochs(t_s=t_s, ids=np.array([1, 2]), names=["a", "b"], kinds=["ship", "ship"],
                          east_m=np.zeros((t_s.size, 2)), north_m=np.zeros((t_s.size, 2)),
                          cog_deg=np.zeros((t_s.size, 2)), sog_mps=np.zeros((t_s.size, 2)),
                          ais=np.ones((t_s.size, 2), bool), range_m=np.zeros((t_s.size, 2)),
                          own_east_m=np.zeros(t_s.size), own_north_m=np.zeros(t_s.size),
                          mmsi=np.array([257000001, NO_MMSI]))
    seen = ais_in_view(truth, {257000001: np.array([95.0, 30.0])})  # out of order on purpose
    assert list(t_s[seen[:, 0]]) == list(np.arange(30.0, 280.0, 10.0))  # 30 s .. 95 + 180 s
    assert not seen[:, 1].any()  # no MMSI: never heard

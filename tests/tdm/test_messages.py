"""tdm.messages: the detected-target record's fields, and the atomic JSON-lines writer."""

from __future__ import annotations

import numpy as np
import pytest

from tdm import ekf
from tdm.frames import EnuFrame
from tdm.messages import jsonl_writer, target_record, target_records

FRAME = EnuFrame(59.43, 10.47)


def state(e=100.0, n=-50.0, psi=np.pi / 2, u=3.0, alpha=12.3456):
    x = np.zeros(ekf.N_STATES)
    x[ekf.E], x[ekf.N], x[ekf.PSI], x[ekf.U], x[ekf.ALPHA] = e, n, psi, u, alpha
    p = np.diag([4.0, 9.0, 0.1, 0.2, 0.01, 1.0])
    p[0, 1] = p[1, 0] = 1.23456
    return x, p


def test_record_fields_and_rounding():
    x, p = state()
    rec = target_record(12.3456789, 7, "vessel", x, p, ["ais", "radar"], FRAME, mmsi=257000002)
    assert list(rec) == ["t", "target_id", "object_descriptor", "longitude", "latitude", "cog_deg", "sog_mps",
                         "cross_section_m2", "sources", "position_cov_m2", "mmsi"]
    lat, lon = FRAME.to_geodetic(100.0, -50.0)
    assert rec["t"] == 12.345679 and rec["target_id"] == 7 and rec["object_descriptor"] == "vessel"
    assert rec["latitude"] == round(float(lat), 8) and rec["longitude"] == round(float(lon), 8)
    assert rec["cog_deg"] == 90.0 and rec["sog_mps"] == 3.0  # psi is the compass course, radians
    assert rec["cross_section_m2"] == 12.346
    assert rec["position_cov_m2"] == [[4.0, 1.2346], [1.2346, 9.0]]
    assert rec["sources"] == ["ais", "radar"] and rec["mmsi"] == 257000002
    assert "sensor" not in rec


def test_negative_speed_is_reported_as_motion_the_other_way():
    x, p = state(psi=np.radians(30.0), u=-2.0)
    rec = target_record(0.0, 1, "unknown", x, p, [], FRAME)
    assert rec["sog_mps"] == 2.0 and rec["cog_deg"] == pytest.approx(210.0)
    assert rec["mmsi"] is None


def test_sensor_tracks_carry_their_sensor():
    x, p = state()
    assert target_record(0.0, 1, "iceberg", x, p, ["lidar"], FRAME, sensor="lidar")["sensor"] == "lidar"


def test_jsonl_writer_writes_lines_and_renames_at_the_end(tmp_path):
    path = tmp_path / "tdm" / "detected_targets.jsonl"
    with jsonl_writer(path) as write:
        write({"t": 0.0, "a": [1, 2]})
        write({"t": 1.0})
        assert not path.exists()
    assert path.read_text(encoding="utf-8") == '{"t": 0.0, "a": [1, 2]}\n{"t": 1.0}\n'
    assert [p.name for p in path.parent.iterdir()] == [path.name]


def test_jsonl_writer_leaves_nothing_when_interrupted(tmp_path):
    path = tmp_path / "out.jsonl"
    with pytest.raises(RuntimeError):
        with jsonl_writer(path) as write:
            write({"t": 0.0})
            raise RuntimeError("stop")
    assert list(tmp_path.iterdir()) == []


def test_records_of_an_epoch_are_those_of_one_state_at_a_time():
    """target_records (one lat/lon conversion for all states) gives the very records of target_record, one by one,
    and the writer the lines of json.dumps."""
    import json

    rng = np.random.default_rng(4)
    rows = []
    for k in range(300):
        x, p = state(e=float(rng.normal(0, 3000)), n=float(rng.normal(0, 3000)), psi=float(rng.uniform(-4, 4)),
                     u=float(rng.normal(0, 5)), alpha=float(rng.uniform(0, 900)))
        rows.append((k, "vessel", x, p, ["ais", "radar"], None if k % 2 else 257000000 + k, None if k % 3 else "radar"))
    records = target_records(123.4, rows, FRAME)
    singles = [target_record(123.4, *row[:5], FRAME, row[5], row[6]) for row in rows]
    dumps = [json.dumps(r, separators=(", ", ": ")) for r in singles]
    assert [json.dumps(r, separators=(", ", ": ")) for r in records] == dumps
    from tdm.messages import _ENCODER
    assert [_ENCODER.encode(r) for r in records] == dumps
    assert target_records(0.0, [], FRAME) == []

"""The recording writers on their own: JSON lines, .npz, point clouds, NMEA sentences (no render)."""

from __future__ import annotations

import io
import json
import zipfile
from functools import reduce

import numpy as np
import pytest

from raysim.recording import jsonl, nmea, npz, pointclouds


# ---------------------------------------------------------------- jsonl

def truth_object(**over):
    o = {"id": 3, "name": 'ship "A"', "kind": "ship", "length_m": 40.0, "beam_m": 8.125, "height_m": 12.0,
         "ais": True, "mmsi": 257000009, "lat": np.array([59.1234567891, 59.2]), "lon": np.array([10.5, 10.6]),
         "x": np.array([1.0004, -2.5]), "y": np.array([3.0, 4.0]), "centre_lat": np.array([59.1234571, 59.2]),
         "centre_lon": np.array([10.5, 10.6000001]), "centre_x": np.array([1.0004, -2.5]),
         "centre_y": np.array([3.0456, 4.0]), "heading_deg": np.array([359.9996, 90.0]),
         "cog_deg": np.array([10.0, 20.0]), "sog_mps": np.array([5.1234, 0.0])}
    o.update(over)
    return o


def test_truth_lines_have_fixed_decimals_and_key_order():
    handle = io.StringIO()
    assert jsonl.write_truth_chunk(handle, np.array([0.0, 0.1]), [truth_object()]) == 2
    first = handle.getvalue().splitlines()[0]
    assert first == ('{"t": 0.0000, "id": 3, "name": "ship \\"A\\"", "kind": "ship", "lat": 59.123456789, '
                     '"lon": 10.500000000, "x": 1.000, "y": 3.000, "centre_lat": 59.123457100, '
                     '"centre_lon": 10.500000000, "centre_x": 1.000, "centre_y": 3.046, "heading_deg": 0.000, "cog_deg": 10.000, '
                     '"sog_mps": 5.123, "length_m": 40.00, "beam_m": 8.12, "height_m": 12.00, "ais": true, '
                     '"mmsi": 257000009}')
    rows = [json.loads(line) for line in handle.getvalue().splitlines()]
    assert tuple(rows[1]) == jsonl.TRUTH_KEYS


def test_truth_lines_are_time_major_and_null_mmsi():
    handle = io.StringIO()
    objects = [truth_object(id=1), truth_object(id=2, ais=False, mmsi=None)]
    jsonl.write_truth_chunk(handle, np.array([0.0, 0.1]), objects)
    rows = [json.loads(line) for line in handle.getvalue().splitlines()]
    assert [(r["t"], r["id"]) for r in rows] == [(0.0, 1), (0.0, 2), (0.1, 1), (0.1, 2)]
    assert rows[1]["mmsi"] is None and rows[1]["ais"] is False


@pytest.mark.parametrize("yaw_deg, east_m, north_m", [(0.0, 30.0, 2.0), (90.0, -2.0, 30.0), (-90.0, 2.0, -30.0),
                                                      (180.0, -30.0, -2.0)])
def test_a_body_point_lands_where_the_yaw_turns_it(yaw_deg, east_m, north_m):
    """Body (30 m forward, 2 m to port) at yaw 0 (facing east), 90 (north), -90 (south), 180 (west)."""
    position = np.array([[100.0, 200.0, 0.5]])
    x, y = jsonl.centre_positions_m(position, np.radians([yaw_deg]), (30.0, 2.0))
    assert (x[0] - 100.0, y[0] - 200.0) == pytest.approx((east_m, north_m), abs=1e-9)


def test_ownship_lines():
    handle = io.StringIO()
    c = {k: np.array([1.0, 2.0]) for k in jsonl.OWNSHIP_KEYS if k != "t"}
    c["heading_deg"] = np.array([-0.0001, 360.0])
    assert jsonl.write_ownship_chunk(handle, np.array([0.5, 0.6]), c) == 2
    rows = [json.loads(line) for line in handle.getvalue().splitlines()]
    assert tuple(rows[0]) == jsonl.OWNSHIP_KEYS
    assert [r["heading_deg"] for r in rows] == [0.0, 0.0]  # rounded, 360 folded to 0, no negative zero
    assert "-0.000" not in handle.getvalue()


def test_course_and_speed_from_velocity_and_heading_when_still():
    v = np.array([[1.0, 0.0, 0.0], [0.0, -2.0, 0.0], [0.0, 0.0, 0.0]])
    cog, sog = jsonl.course_and_speed(v, np.array([0.0, 0.0, np.pi / 2]))
    assert cog == pytest.approx([90.0, 180.0, 0.0])
    assert sog == pytest.approx([1.0, 2.0, 0.0])


def test_truth_epochs_reads_back_the_kept_times(tmp_path):
    path = tmp_path / "truth.jsonl"
    with open(path, "w", encoding="utf-8") as handle:
        jsonl.write_truth_chunk(handle, np.array([0.0, 0.5, 1.0]), [truth_object(id=1, **{
            k: np.zeros(3) for k in ("lat", "lon", "x", "y", "centre_lat", "centre_lon", "centre_x", "centre_y",
                                     "heading_deg", "cog_deg", "sog_mps")})])
    epochs = list(jsonl.truth_epochs(path, jsonl.every(1.0)))
    assert [t for t, _ in epochs] == [0.0, 1.0]
    assert all(len(rows) == 1 and rows[0]["id"] == 1 for _, rows in epochs)


# ---------------------------------------------------------------- npz

def test_npz_round_trips_in_order_and_is_the_same_bytes_every_time(tmp_path):
    arrays = {"b": np.arange(5, dtype=np.int16), "a": np.ones((2, 3), dtype=np.float32)}
    npz.write_npz(tmp_path / "one.npz", arrays)
    npz.write_npz(tmp_path / "two.npz", arrays)
    assert (tmp_path / "one.npz").read_bytes() == (tmp_path / "two.npz").read_bytes()
    with np.load(tmp_path / "one.npz") as loaded:
        assert list(loaded.keys()) == ["b", "a"]
        assert np.array_equal(loaded["b"], arrays["b"]) and loaded["a"].dtype == np.float32
    with zipfile.ZipFile(tmp_path / "one.npz") as archive:
        infos = archive.infolist()
        assert [i.date_time for i in infos] == [(1980, 1, 1, 0, 0, 0)] * 2
        assert all(i.compress_type == zipfile.ZIP_STORED for i in infos)
    assert not [p for p in tmp_path.iterdir() if p.name not in ("one.npz", "two.npz")]  # no temporary left


# ---------------------------------------------------------------- point clouds

def sweep():
    return {"x": np.array([1.0, 2.0], np.float32), "y": np.array([0.5, -0.5], np.float32),
            "z": np.array([0.0, 1.0], np.float32), "intensity": np.array([0, 255], np.uint8),
            "ring": np.array([3, 31], np.uint8), "time": np.array([10.25, 10.5])}


def test_velodyne_points_layout_and_relative_time():
    points = pointclouds.velodyne_points(sweep())
    assert points.dtype.itemsize == 22
    assert points["time"].tolist() == [0.0, 0.25]
    assert points["ring"].tolist() == [3, 31] and points["intensity"].tolist() == [0.0, 255.0]


def test_pcd_header_and_body():
    data = pointclouds.pcd_bytes(sweep())
    header, body = data.split(b"DATA binary\n")
    assert b"FIELDS x y z intensity ring time\n" in header and b"POINTS 2\n" in header and b"WIDTH 2\n" in header
    assert len(body) == 2 * 22
    assert np.frombuffer(body, pointclouds.PCD_DTYPE)["x"].tolist() == [1.0, 2.0]


def test_kitti_is_xyz_and_reflectance_in_unit_range():
    values = np.frombuffer(pointclouds.kitti_bytes(sweep()), "<f4").reshape(-1, 4)
    assert values[:, 3].tolist() == [0.0, 1.0]
    assert values[1, :3].tolist() == [2.0, -0.5, 1.0]


# ---------------------------------------------------------------- nmea

def xor(body: str) -> str:
    return f"{reduce(lambda a, c: a ^ ord(c), body, 0):02X}"


@pytest.mark.parametrize("body", ["GPGLL,4916.45,N,12311.12,W,225444,A", "HEHDT,274.07,T", ""])
def test_checksum_is_the_xor_of_the_body(body):
    assert nmea.checksum(body) == xor(body)
    assert nmea.sentence(body) == f"${body}*{xor(body)}"
    assert nmea.sentence(body, "!") == f"!{body}*{xor(body)}"


def test_tag_block_carries_whole_unix_seconds():
    assert nmea.tag_block(1496318400.9) == f"\\c:1496318400*{xor('c:1496318400')}\\"


def test_hehdt_is_a_checked_sentence():
    text = nmea.hehdt(274.07)
    body, check = text[1:].split("*")
    assert text.startswith("$HEHDT,274.07") and check == xor(body)

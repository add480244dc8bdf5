"""The cases of the corpus of broken recordings: one corruption each and the outcome of every command.

Outcomes follow docs/formats.md, "Reading a recording: warnings and errors". ``tdm evaluate`` runs
on the run's outputs (or, when the run refused the recording, on those of the valid recording).
"""

from __future__ import annotations

import os
import shutil
import struct
from pathlib import Path

import numpy as np

from tests.tdm.corpus.corrupt import (
    AIS, CUT_LINE, LGAP, OK, PCAP_BACK, PCAP_BAD, PCAP_CLOCK, PCAP_CUT, PCAP_OUT, RGAP, TARGETS, UNREADABLE, A, Case,
    M, O, P, S, T, as_dir, at, cut, each, err, huge_header, json_edit, lidar, line_edit, link_loop, no_permission,
    nmea_sentence, npz_drop, npz_edit, npz_set, pcap_patch, pcap_record_length, pcap_times, radar, remove, rename,
    replace,
    swap_lines, tag_line, text_edit, warn, with_at, yaml_set,
)

PCAP = ("--lidar-source", "pcap")
AIS_LINE = 2  # a single-sentence message (lines 0-1 and 4-5 are two-sentence type 5 messages)


def refused(rel: str):
    """``tdm evaluate`` refuses the file: its own reader's message (tdm/eval_visibility.py), the file named."""
    return err(rel, "")


def _bytes(rel: str, data: bytes):
    return lambda rec: replace(rec / rel, data)


def _json_key(key: str, value):
    return at(M, json_edit, lambda d: d.__setitem__(key, value))


def _json_drop(key: str):
    return at(M, json_edit, lambda d: d.pop(key))


def _scenario(key_path: str, text: str):
    return at(S, yaml_set, key_path, text)


def _ownship_line(edit):
    return at(O, line_edit, 4, edit)


def _ownship_field(key: str, text: str):
    """Line 5's field ``key`` set to the JSON ``text``."""
    def edit(line: str) -> str:
        import json

        row = json.loads(line)
        row[key] = "__VALUE__"
        return json.dumps(row).replace('"__VALUE__"', text)
    return _ownship_line(edit)


def _no_field(key: str):
    import json

    return _ownship_line(lambda line: json.dumps({k: v for k, v in json.loads(line).items() if k != key}))


def _lidar10(edit):
    return at(lidar(10), npz_edit, edit)


def _radar0(edit):
    return at(radar(0), npz_edit, edit)


def _unreadable(sensor: str, reason: str) -> tuple[str, int]:
    return UNREADABLE.format(sensor, reason), 1


def _recording_is_a_file(rec: Path) -> None:
    shutil.rmtree(rec)
    rec.write_text("not a recording\n")


def _no_sensor_data(rec: Path) -> None:
    for folder in ("lidar", "radar", "ais"):
        shutil.rmtree(rec / folder)


def _emptied(sensor: str):
    """``<sensor>/sweeps`` copied without its files (a partial copy)."""
    def corrupt(rec: Path) -> None:
        shutil.rmtree(rec / sensor / "sweeps")
        (rec / sensor / "sweeps").mkdir()
    return corrupt


def _pickled_x(rec: Path) -> None:
    path = rec / lidar(10)
    with np.load(path) as z:
        arrays = {k: z[k] for k in z.files}
    arrays["x"] = np.array([{"x": 1.0}] * arrays["x"].size, dtype=object)
    path.unlink()
    np.savez(path, **arrays)


def _extra_array(arrays: dict) -> None:
    arrays["velocity_mps"] = np.zeros(arrays["x"].size, dtype=np.float32)


def _empty(arrays: dict) -> None:
    for name in list(arrays):
        arrays[name] = arrays[name][:0]


def _ais_insert(line: bytes):
    def edit(rec: Path) -> None:
        lines = (rec / A).read_bytes().splitlines(keepends=True)
        replace(rec / A, b"".join(lines[:3] + [line + b"\n"] + lines[3:]))
    return edit


def _ais_line(edit):
    return at(A, line_edit, AIS_LINE, edit)


def _bad_sentence_checksum(line: str) -> str:
    body, checksum = line.rsplit("*", 1)
    return f"{body}*{int(checksum, 16) ^ 0x55:02X}"


def _bad_tag_checksum(line: str) -> str:
    return line.replace("*5D\\", "*00\\", 1)


def _ais_time(unix_s: str):
    return _ais_line(lambda line: tag_line(unix_s, line.rsplit("\\", 1)[-1]))


def _copy(src: str, dst: str):
    def copy(rec: Path) -> None:
        if os.path.lexists(rec / dst):
            remove(rec / dst)
        shutil.copyfile(rec / src, rec / dst)
    return copy


def _targets(edit):
    return at(TARGETS, line_edit, 0, edit)


CASES: list[Case] = [
    # ---- the directory and manifest.json
    Case("recording_is_a_file", "the recording's path is a file", _recording_is_a_file,
         *[err("", "(directory)", "not a directory")] * 3),
    Case("no_sensor_data", "lidar/, radar/ and ais/ removed", _no_sensor_data,
         OK, err("", "(directory)", "holds no LiDAR, radar or AIS data"), OK),
    Case("radar_not_copied", "radar/ removed (manifest.json lists the radar as rendered)",
         lambda rec: shutil.rmtree(rec / "radar"),
         OK, err("radar/sweeps", "(directory)", "missing, though manifest.json lists radar as rendered"), OK),
    Case("radar_sweeps_emptied", "radar/sweeps copied without its files", _emptied("radar"),
         OK, err("radar/sweeps", "(directory)", "holds none of the 2 sweep files manifest.json counts"), OK),
    Case("lidar_sweeps_emptied", "lidar/sweeps copied without its files", _emptied("lidar"),
         OK, err("lidar/sweeps", "(directory)", "holds none of the 59 sweep files manifest.json counts"), OK),
    Case("manifest_missing", "manifest.json removed", at(M, remove), *[err(M, "(file)", "missing")] * 3),
    Case("manifest_zero_bytes", "manifest.json of zero bytes", _bytes(M, b""), *[err(M, "(file)", "empty")] * 3),
    Case("manifest_cut", "manifest.json cut after 40 bytes", at(M, cut, 40),
         *[err(M, "line 3", "not valid JSON")] * 3),
    Case("manifest_list", "manifest.json is a list", _bytes(M, b"[1, 2]"),
         *[err(M, "(top level)", "must be a JSON object, not a list")] * 3),
    Case("manifest_number", "manifest.json is a number", _bytes(M, b"42"),
         *[err(M, "(top level)", "must be a JSON object")] * 3),
    Case("manifest_string", "manifest.json is a string", _bytes(M, b'"busy_open_sea"'),
         *[err(M, "(top level)", "must be a JSON object")] * 3),
    Case("manifest_not_utf8", "a Latin-1 byte in manifest.json's scenario name",
         at(M, text_edit, lambda t: t.replace("busy_open_sea", "busy_\udce9pen_sea")),
         *[err(M, "line 4", "not UTF-8")] * 3),
    Case("manifest_directory", "manifest.json is a directory", at(M, as_dir),
         *[err(M, "(file)", "is a directory")] * 3),
    Case("manifest_link_loop", "manifest.json is a symbolic link to itself", at(M, link_loop),
         *[err(M, "(file)", "symbolic link loop")] * 3),
    Case("manifest_no_permission", "manifest.json with permissions 000", at(M, no_permission),
         *[err(M, "(file)", "permission denied")] * 3, as_user=True),
    Case("manifest_no_start_time", "manifest.json without start_time", _json_drop("start_time"),
         *[err(M, "start_time", "missing")] * 3),
    Case("manifest_no_duration", "manifest.json without duration_s", _json_drop("duration_s"),
         *[err(M, "duration_s", "missing")] * 3),
    Case("manifest_duration_string", 'duration_s "6"', _json_key("duration_s", "6"),
         *[err(M, "duration_s", "must be a number")] * 3),
    Case("manifest_duration_nan", "duration_s NaN", _json_key("duration_s", float("nan")),
         *[err(M, "duration_s", "must be a finite number")] * 3),
    Case("manifest_duration_negative", "duration_s -6", _json_key("duration_s", -6.0),
         *[err(M, "duration_s", "must be > 0")] * 3),
    Case("manifest_duration_huge", "duration_s 1e12 (7 TiB of epochs)", _json_key("duration_s", 1e12),
         *[err(M, "duration_s", "more than the largest accepted")] * 3),
    Case("manifest_start_time_garbage", 'start_time "yesterday"', _json_key("start_time", "yesterday"),
         *[err(M, "start_time", "not an ISO 8601 time")] * 3),
    Case("manifest_start_time_number", "start_time a number", _json_key("start_time", 1496318400),
         *[err(M, "start_time", "must be an ISO 8601 time string")] * 3),
    Case("manifest_sensors_number", "sensors_rendered 5", _json_key("sensors_rendered", 5),
         *[err(M, "sensors_rendered", "must be a list of strings")] * 3),
    Case("manifest_other_format", 'format "rosbag"', _json_key("format", "rosbag"),
         *[err(M, "format", "not a raysim-recording manifest")] * 3),
    # ---- scenario.yaml
    Case("scenario_missing", "scenario.yaml removed", at(S, remove), *[err(S, "(file)", "missing")] * 3),
    Case("scenario_zero_bytes", "scenario.yaml of zero bytes", _bytes(S, b""), *[err(S, "(file)", "empty")] * 3),
    Case("scenario_not_yaml", "scenario.yaml is not YAML", _bytes(S, b"sensors: [unclosed\n"),
         *[err(S, "line 2", "not valid YAML")] * 3),
    Case("scenario_list", "scenario.yaml is a list", _bytes(S, b"- a\n- b\n"),
         *[err(S, "(top level)", "must be a mapping")] * 3),
    Case("scenario_not_utf8", "a byte 0xff in scenario.yaml",
         at(S, text_edit, lambda t: t.replace("busy", "b\udcffsy", 1)),
         *[err(S, "line 1", "not UTF-8")] * 3),
    Case("scenario_directory", "scenario.yaml is a directory", at(S, as_dir),
         *[err(S, "(file)", "is a directory")] * 3),
    Case("rate_nan", "tdm.update_rate_hz .nan", _scenario("tdm.update_rate_hz", ".nan"),
         *[err(S, "tdm.update_rate_hz", "must be a finite number")] * 3),
    Case("rate_zero", "tdm.update_rate_hz 0", _scenario("tdm.update_rate_hz", "0"),
         *[err(S, "tdm.update_rate_hz", "must be > 0")] * 3),
    Case("rate_huge", "tdm.update_rate_hz 1e9 (74 GiB of epochs)", _scenario("tdm.update_rate_hz", "1.0e+9"),
         *[err(S, "tdm.update_rate_hz", "more than the largest accepted, 100")] * 3),
    Case("rate_string", 'tdm.update_rate_hz "fast"', _scenario("tdm.update_rate_hz", "fast"),
         *[err(S, "tdm.update_rate_hz", "must be a number")] * 3),
    Case("radar_rpm_zero", "sensors.radar.rpm 0", _scenario("sensors.radar.rpm", "0"),
         *[err(S, "sensors.radar.rpm", "must be > 0")] * 3),
    Case("lidar_rotation_nan", "sensors.lidar.rotation_hz .nan", _scenario("sensors.lidar.rotation_hz", ".nan"),
         *[err(S, "sensors.lidar.rotation_hz", "must be a finite number")] * 3),
    Case("radar_spokes_fraction", "sensors.radar.spokes 2048.5", _scenario("sensors.radar.spokes", "2048.5"),
         *[err(S, "sensors.radar.spokes", "must be a whole number")] * 3),
    Case("radar_spokes_other", "sensors.radar.spokes 1024 (the sweeps have 2048)",
         _scenario("sensors.radar.spokes", "1024"),
         err(radar(0), "echo", "scenario.yaml sensors.radar.spokes says 1024"),
         err(radar(0), "echo", "scenario.yaml sensors.radar.spokes says 1024"), OK),
    Case("mount_string", 'sensors.lidar.mount.z_m "high"', _scenario("sensors.lidar.mount.z_m", "high"),
         *[err(S, "sensors.lidar.mount.z_m", "must be a number")] * 3),
    Case("sensors_list", "sensors is a list", _scenario("sensors", "[lidar, radar]"),
         *[err(S, "sensors", "must be a mapping")] * 3),
    Case("lidar_range_negative", "sensors.lidar.range_max_m -5", _scenario("sensors.lidar.range_max_m", "-5"),
         *[err(S, "sensors.lidar.range_max_m", "must be > 0")] * 3),
    Case("own_length_inf", "own_ship.length_m .inf", _scenario("own_ship.length_m", ".inf"),
         *[err(S, "own_ship.length_m", "must be a finite number")] * 3),
    # ---- ownship.jsonl (tdm evaluate does not read it)
    Case("ownship_missing", "ownship.jsonl removed", at(O, remove), *[err(O, "(file)", "missing")] * 2, OK),
    Case("ownship_zero_bytes", "ownship.jsonl of zero bytes", _bytes(O, b""),
         *[err(O, "(file)", "holds no navigation samples")] * 2, OK),
    Case("ownship_cut_last_line", "ownship.jsonl cut inside its last line", at(O, cut, -30),
         warn(CUT_LINE), warn(CUT_LINE), OK),
    Case("ownship_first_half", "ownship.jsonl holds only the first half of its lines (a copy cut at a line's end)",
         at(O, text_edit, lambda text: "".join(text.splitlines(keepends=True)[:len(text.splitlines()) // 2])),
         *[err(O, "time", "the navigation covers")] * 2, OK),
    Case("ownship_cut_line", "line 5 of ownship.jsonl cut", _ownship_line(lambda line: line[:20]),
         *[err(O, "line 5", "not valid JSON")] * 2, OK),
    Case("ownship_line_number", "line 5 of ownship.jsonl is 42", _ownship_line(lambda line: "42"),
         *[err(O, "line 5", "not a JSON object but int 42")] * 2, OK),
    Case("ownship_line_string", "line 5 is a string", _ownship_line(lambda line: '"fix"'),
         *[err(O, "line 5", "not a JSON object but a string")] * 2, OK),
    Case("ownship_line_null", "line 5 is null", _ownship_line(lambda line: "null"),
         *[err(O, "line 5", "not a JSON object but null")] * 2, OK),
    Case("ownship_line_list", "line 5 is a list", _ownship_line(lambda line: "[1, 2]"),
         *[err(O, "line 5", "not a JSON object but a list")] * 2, OK),
    Case("ownship_field_string", 'lat "north" on line 5', _ownship_field("lat", '"north"'),
         *[err(O, "line 5", "field 'lat' must be a number, not a string")] * 2, OK),
    Case("ownship_field_nan", "heading_deg NaN on line 5", _ownship_field("heading_deg", "NaN"),
         *[err(O, "line 5", "field 'heading_deg' must be a finite number")] * 2, OK),
    Case("ownship_field_null", "sog_mps null on line 5", _ownship_field("sog_mps", "null"),
         *[err(O, "line 5", "field 'sog_mps' must be a number, not null")] * 2, OK),
    Case("ownship_field_missing", "roll_deg missing on line 5", _no_field("roll_deg"),
         *[err(O, "line 5", "field 'roll_deg' missing")] * 2, OK),
    Case("ownship_lat_123", "lat 123 on line 5", _ownship_field("lat", "123.0"),
         *[err(O, "line 5", "outside [-90, 90]")] * 2, OK),
    Case("ownship_time_back", "lines 5 and 6 swapped", at(O, swap_lines, 4, 5),
         *[err(O, "line 6", "not after the previous sample's")] * 2, OK),
    Case("ownship_not_utf8", "a Latin-1 byte on line 5", _ownship_line(lambda line: line.replace("lat", "l\udce9t")),
         *[err(O, "line 5", "not UTF-8")] * 2, OK),
    Case("ownship_directory", "ownship.jsonl is a directory", at(O, as_dir),
         *[err(O, "(file)", "is a directory")] * 2, OK),
    # ---- truth.jsonl (only tdm evaluate reads it)
    Case("truth_garbage_line", "line 3 of truth.jsonl is not JSON", at(T, line_edit, 2, lambda line: "garbage"),
         OK, OK, err(T, "line 3", "not valid JSON")),
    Case("truth_time_huge", "t = 1e12 on line 10 of truth.jsonl",
         at(T, line_edit, 9, lambda line: line.replace('"t": 0.', '"t": 1000000000000.', 1)),
         OK, OK, err(T, "line 10", "")),
    Case("truth_missing", "truth.jsonl removed", at(T, remove), OK, OK, err(T, "(file)", "missing")),
    # ---- LiDAR sweeps: files that copying or a crash leave (warnings)
    Case("lidar_zero_bytes", "sweep 10 of zero bytes", _bytes(lidar(10), b""),
         *[warn(_unreadable("lidar", "zero bytes"))] * 2, OK),
    Case("lidar_cut_last", "the last sweep cut in half", at(lidar(58), cut, 0.5),
         *[warn(_unreadable("lidar", "zip archive cut short"))] * 2, OK),
    Case("lidar_cut_head", "sweep 20 cut after 500 bytes", at(lidar(20), cut, 500),
         *[warn(_unreadable("lidar", "zip archive cut short"))] * 2, OK),
    Case("lidar_cut_tail", "the last 10 bytes of sweep 21 cut", at(lidar(21), cut, -10),
         *[warn(_unreadable("lidar", "zip archive cut short"))] * 2, OK),
    Case("lidar_not_a_zip", "sweep 10 is text", _bytes(lidar(10), b"not a zip file\n"),
         *[warn(_unreadable("lidar", "not a zip archive"))] * 2, OK),
    Case("lidar_huge_header", "x's header in sweep 10 claims 10^12 points (4 TB)",
         at(lidar(10), huge_header), *[warn(_unreadable("lidar", "damaged array data"))] * 2, OK),
    Case("lidar_gap", "sweep 20 removed", at(lidar(20), remove), *[warn((LGAP, 1))] * 2, OK),
    Case("lidar_renumbered", "the last sweep renamed 000070.npz", lambda rec: rename(rec, [(lidar(58), lidar(70))]),
         *[warn((LGAP, 12))] * 2, OK),
    Case("lidar_empty_sweep", "sweep 10 holds no points", _lidar10(_empty), OK, warn(("lidar: empty sweeps", 1)), OK),
    Case("lidar_extra_array", "sweep 10 has an extra array", _lidar10(_extra_array), OK, OK, OK),
    Case("lidar_compressed", "sweep 10 saved compressed (allowed)", at(lidar(10), npz_edit, lambda a: None, True),
         OK, OK, OK),
    # ---- LiDAR sweeps that break the format (errors)
    Case("lidar_x_int16", "x of sweep 10 int16", _lidar10(npz_set("x", lambda v: v.astype(np.int16))),
         *[err(lidar(10), "x", "dtype int16, the format says float32")] * 2, OK),
    Case("lidar_time_float32", "time of sweep 10 float32", _lidar10(npz_set("time", lambda v: v.astype(np.float32))),
         *[err(lidar(10), "time", "dtype float32, the format says float64")] * 2, OK),
    Case("lidar_ring_strings", "ring of sweep 10 strings", _lidar10(npz_set("ring", lambda v: v.astype(str))),
         *[err(lidar(10), "ring", "dtype <U")] * 2, OK),
    Case("lidar_x_2d", "x of sweep 10 of shape (N, 1)", _lidar10(npz_set("x", lambda v: v[:, None])),
         *[err(lidar(10), "x", "the format says 1 dimension(s)")] * 2, OK),
    Case("lidar_y_short", "y of sweep 10 one point short", _lidar10(npz_set("y", lambda v: v[:-1])),
         *[err(lidar(10), "y", "points, but x has")] * 2, OK),
    Case("lidar_ring_missing", "sweep 10 without ring", _lidar10(npz_drop("ring")),
         *[err(lidar(10), "ring", "array missing")] * 2, OK),
    Case("lidar_object_id_float", "object_id of sweep 10 float32",
         _lidar10(npz_set("object_id", lambda v: v.astype(np.float32))),
         *[err(lidar(10), "object_id", "dtype float32, the format says int32")] * 2, refused(lidar(10))),
    Case("lidar_pickled", "x of sweep 10 Python objects (pickled)", _pickled_x,
         *[err(lidar(10), "x", "pickled data")] * 3),
    Case("lidar_x_nan", "a NaN in x of sweep 10", _lidar10(npz_set("x", lambda v: with_at(v, 100, np.nan))),
         OK, err(lidar(10), "x", "not a finite number at index 100"), OK),
    Case("lidar_time_inf", "an inf in time of sweep 10", _lidar10(npz_set("time", lambda v: with_at(v, 5, np.inf))),
         OK, err(lidar(10), "time", "not a finite number at index 5"), refused(lidar(10))),
    Case("lidar_ring_40", "ring 40 in sweep 10", _lidar10(npz_set("ring", lambda v: with_at(v, 7, 40))),
         OK, err(lidar(10), "ring", "above 31 at index 7"), OK),
    Case("lidar_time_outside", "sweep 10's times 10^6 s late", _lidar10(npz_set("time", lambda v: v + 1e6)),
         OK, err(lidar(10), "time", "outside the run"), OK),
    Case("lidar_swapped", "sweeps 10 and 30 swapped",
         lambda rec: rename(rec, [(lidar(10), lidar(30)), (lidar(30), lidar(10))]),
         OK, err(lidar(11), "time", "before 000010.npz ends"), OK),
    Case("lidar_duplicated", "sweep 10 copied over sweep 11", _copy(lidar(10), lidar(11)),
         OK, err(lidar(11), "time", "sweeps out of order or duplicated"), OK),
    Case("lidar_sweep_directory", "sweep 10 is a directory", at(lidar(10), as_dir),
         *[err(lidar(10), "(file)", "is a directory")] * 2, refused(lidar(10))),
    Case("lidar_sweep_link_loop", "sweep 10 is a symbolic link to itself", at(lidar(10), link_loop),
         *[err(lidar(10), "(file)", "symbolic link loop")] * 2, refused(lidar(10))),
    Case("lidar_sweep_no_permission", "sweep 10 with permissions 000", at(lidar(10), no_permission),
         *[err(lidar(10), "(file)", "permission denied")] * 2, refused(lidar(10)), as_user=True),
    Case("lidar_sweeps_is_a_file", "lidar/sweeps is a file",
         each(at("lidar/sweeps", remove), _bytes("lidar/sweeps", b"sweeps\n")),
         *[err("lidar/sweeps", "(directory)", "not a directory")] * 2, OK),
    Case("lidar_two_numbers", "sweep 5 also as 5.npz", _copy(lidar(5), "lidar/sweeps/5.npz"),
         *[err("lidar/sweeps/5.npz", "(file)", "numbered 5 like 000005.npz")] * 2, OK),
    # ---- radar sweeps
    Case("radar_cut", "radar sweep 1 cut in half", at(radar(1), cut, 0.5),
         *[warn(_unreadable("radar", "zip archive cut short"))] * 2, OK),
    Case("radar_not_a_zip", "radar sweep 1 is text", _bytes(radar(1), b"not a zip file"),
         *[warn(_unreadable("radar", "not a zip archive"))] * 2, OK),
    Case("radar_gap", "radar sweep 1 renamed 000003.npz", lambda rec: rename(rec, [(radar(1), radar(3))]),
         *[warn((RGAP, 2))] * 2, OK),
    Case("radar_echo_float", "echo float32", _radar0(npz_set("echo", lambda v: v.astype(np.float32))),
         *[err(radar(0), "echo", "dtype float32, the format says uint8")] * 2, OK),
    Case("radar_echo_1d", "echo flattened", _radar0(npz_set("echo", lambda v: v.ravel())),
         *[err(radar(0), "echo", "the format says 2 dimension(s)")] * 2, OK),
    Case("radar_time_short", "time one spoke short", _radar0(npz_set("time", lambda v: v[:-1])),
         *[err(radar(0), "time", "2047 spokes, but echo has 2048")] * 2, refused(radar(0))),
    Case("radar_range_short", "range_m one sample short", _radar0(npz_set("range_m", lambda v: v[:-1])),
         *[err(radar(0), "range_m", "1023 samples, but echo has 1024")] * 2, OK),
    Case("radar_heading_missing", "no heading_deg", _radar0(npz_drop("heading_deg")),
         *[err(radar(0), "heading_deg", "array missing")] * 2, OK),
    Case("radar_object_spokes_short", "object_spokes one short of object_id",
         _radar0(npz_set("object_spokes", lambda v: v[:-1])),
         *[err(radar(0), "object_spokes", "objects, but object_id has")] * 2, refused(radar(0))),
    Case("radar_echo_16", "a video level of 16", _radar0(npz_set("echo", lambda v: with_at(v, 3, 16))),
         OK, err(radar(0), "echo", "above 15 at index (0, 3)"), OK),
    Case("radar_azimuth_nan", "a NaN azimuth", _radar0(npz_set("azimuth_deg", lambda v: with_at(v, 9, np.nan))),
         OK, err(radar(0), "azimuth_deg", "not a finite number at index 9"), refused(radar(0))),
    Case("radar_range_descending", "range_m reversed", _radar0(npz_set("range_m", lambda v: v[::-1].copy())),
         OK, err(radar(0), "range_m", "not ascending"), OK),
    Case("radar_swapped", "radar sweeps 0 and 1 swapped",
         lambda rec: rename(rec, [(radar(0), radar(1)), (radar(1), radar(0))]),
         OK, err(radar(1), "time", "sweeps out of order or duplicated"), OK),
    # ---- the Velodyne PCAP (tdm run --lidar-source pcap)
    Case("pcap_bad_magic", "PCAP magic zeroed", pcap_patch(0, b"\0\0\0\0"),
         *[err(P, "byte 0", "not a pcap file")] * 2, OK, run_args=PCAP),
    Case("pcap_zero_bytes", "PCAP of zero bytes", _bytes(P, b""), *[err(P, "byte 0", "not a pcap file")] * 2, OK,
         run_args=PCAP),
    Case("pcap_pcapng", "PCAP with a pcapng magic", pcap_patch(0, b"\x0a\x0d\x0d\x0a"),
         *[err(P, "byte 0", "pcapng is not supported")] * 2, OK, run_args=PCAP),
    Case("pcap_link_type", "PCAP link type 147", pcap_patch(20, struct.pack("<I", 147)),
         *[err(P, "byte 20", "link type 147 not supported")] * 2, OK, run_args=PCAP),
    Case("pcap_directory", "the PCAP is a directory", at(P, as_dir), *[err(P, "(file)", "is a directory")] * 2, OK,
         run_args=PCAP),
    Case("pcap_missing", "the PCAP removed", at(P, remove), OK, err(P, "(file)", "missing: --lidar-source pcap"), OK,
         run_args=PCAP),
    Case("pcap_cut_record", "PCAP cut inside a record", at(P, cut, 5_000_037), OK, warn((PCAP_CUT, 1)), OK,
         run_args=PCAP),
    Case("pcap_cut_header", "PCAP cut inside its first record header", at(P, cut, 30), OK, warn((PCAP_CUT, 1)), OK,
         run_args=PCAP),
    Case("pcap_record_length", "a record length of 0xFFFF0000", pcap_record_length, OK, warn((PCAP_BAD, 1)), OK,
         run_args=PCAP),
    Case("pcap_first_times_zero", "record times 0 for the first two records",
         each(at(P, pcap_times, 0, 1, lambda s: 0), pcap_patch(24, b"\0\0\0\0")),
         OK, warn((PCAP_OUT, 1)), OK, run_args=PCAP),
    Case("pcap_times_zero", "record times 0 for 50 data packets", at(P, pcap_times, 3000, 50, lambda s: 0),
         OK, warn((PCAP_OUT, 50)), OK, run_args=PCAP),
    Case("pcap_time_back", "record times of 50 data packets 30 s back", at(P, pcap_times, 3000, 50, lambda s: s - 30),
         OK, warn((PCAP_BACK, 50), (PCAP_CLOCK, 50)), OK, run_args=PCAP),
    # ---- ais/ais.nmea
    Case("ais_bad_checksum", "a sentence checksum wrong", _ais_line(_bad_sentence_checksum),
         OK, warn((AIS + "bad checksum skipped", 1)), OK),
    Case("ais_garbage_line", "a line of text", _ais_insert(b"garbage line"),
         OK, warn((AIS + "unparsable line skipped", 1)), OK),
    Case("ais_binary_line", "a line of binary bytes", _ais_insert(bytes(range(0, 256, 7))),
         OK, warn((AIS + "unparsable line skipped", 1)), OK),
    Case("ais_tag_broken", "a TAG block checksum wrong", _ais_line(_bad_tag_checksum),
         OK, warn((AIS + "line without a (valid) TAG block time skipped", 1)), OK),
    Case("ais_no_tag", "a line without its TAG block", _ais_line(lambda line: line.rsplit("\\", 1)[-1]),
         OK, warn((AIS + "line without a (valid) TAG block time skipped", 1)), OK),
    Case("ais_missing_fields", "!AIVDM,1,1,,A (fields missing, checksum right)",
         _ais_insert(tag_line("1496318401", nmea_sentence("AIVDM,1,1,,A")).encode()),
         OK, warn((AIS + "unparsable line skipped", 1)), OK),
    Case("ais_time_far", "a TAG time of 2286", _ais_time("9999999999"),
         OK, warn((AIS + "message with a time outside the run skipped", 1)), OK),
    Case("ais_cut_last_line", "ais.nmea cut inside its last line", at(A, cut, -12),
         OK, warn((AIS + "unparsable line skipped", 1), (AIS + "orphan fragment skipped", 1)), OK),
    Case("ais_zero_bytes", "ais.nmea of zero bytes", _bytes(A, b""), OK, OK, OK),
    Case("ais_directory", "ais.nmea is a directory", at(A, as_dir), *[err(A, "(file)", "is a directory")] * 3),
    # ---- the run's outputs, broken before tdm evaluate
    Case("targets_garbage_line", "line 1 of tdm/detected_targets.jsonl is not JSON", lambda rec: None, OK, OK,
         err(TARGETS, "line 1", "not valid JSON"), outputs=_targets(lambda line: "garbage")),
    Case("targets_time_nan", "t NaN on line 1 of tdm/detected_targets.jsonl", lambda rec: None, OK, OK,
         err(TARGETS, "line 1", "t"), outputs=_targets(lambda line: line.replace('"t": ', '"t": NaN, "x": ', 1))),
]

NAMES = [case.name for case in CASES]
assert len(set(NAMES)) == len(NAMES), "case names must be unique"

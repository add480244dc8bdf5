"""``tdm evaluate`` on broken recordings: one line ``error: <file>: <place>: <what>``, exit 2, nothing written.

Also: sweep files cut short are counted warnings (docs/formats.md, "What tdm evaluate refuses"),
and the truth kept around the epochs gives exactly the truth at the epochs of every sample.
"""

from __future__ import annotations

import io
import json
import math
import zipfile
from pathlib import Path

import numpy as np
import pytest
import yaml

import tdm.eval_truth
from tdm.cli import main
from tdm.errors import RecordingError
from tdm.eval_params import read_params
from tdm.eval_truth import epoch_grid, read_truth_enu, truth_at
from tests.tdm.eval_helpers import make_recording, save_sweep


@pytest.fixture(scope="module")
def pristine(tmp_path_factory):
    """A valid synthetic recording (radar, AIS; targets and tracks), copied by :func:`broken`."""
    return make_recording(tmp_path_factory.mktemp("inputs") / "rec")


@pytest.fixture
def broken(pristine, tmp_path):
    """A fresh copy of the valid recording to break."""
    import shutil

    rec = tmp_path / "rec"
    shutil.copytree(pristine, rec)
    return rec


def evaluate_fails(rec, capsys, file: str, where: str, what: str) -> str:
    """``tdm evaluate rec`` exits 2 with one line naming ``file`` / ``where`` / ``what``, and writes nothing."""
    before = sorted(p.name for p in (rec / "tdm").iterdir())
    capsys.readouterr()
    assert main(["evaluate", str(rec)]) == 2
    out, err = capsys.readouterr()
    lines = err.splitlines()
    assert len(lines) == 1 and out == "", err
    assert lines[0].startswith(f"error: {rec / file}: {where}: "), lines[0]
    assert what in lines[0] and "Traceback" not in err
    assert sorted(p.name for p in (rec / "tdm").iterdir()) == before  # no metrics.json, no plots
    assert not [p for p in rec.iterdir() if ".partial-" in p.name]
    return lines[0]


def edit_lines(path, edit) -> None:
    """Rewrite a JSON-lines file: ``edit(lines)`` returns the new list of lines (without newlines)."""
    lines = path.read_text(encoding="utf-8").splitlines()
    path.write_text("".join(line + "\n" for line in edit(lines)), encoding="utf-8")


def set_field(number: int, key: str, raw: str):
    """An edit setting field ``key`` of line ``number`` (1-based) to the raw JSON text ``raw``."""
    def edit(lines):
        row = json.loads(lines[number - 1])
        row[key] = "@@"
        lines[number - 1] = json.dumps(row).replace('"@@"', raw)
        return lines
    return edit


TRUTH_CASES = [  # (edit, place, what)
    (lambda ls: ls[:4] + ['{"t": 0.0, "id": 4,'] + ls[5:], "line 5", "not valid JSON"),
    (lambda ls: ls[:4] + ["[0.0, 4]"] + ls[5:], "line 5", "not a JSON object"),
    (set_field(3, "t", "NaN"), "line 3", "field 't': NaN is not a finite number"),
    (set_field(3, "t", '"0.0"'), "line 3", "field 't': \"0.0\" is not a number"),
    (set_field(3, "id", "2.5"), "line 3", "field 'id': 2.5 is not an integer"),
    (set_field(3, "lat", "95.0"), "line 3", "field 'lat': 95.0 is not a finite number in [-90, 90]"),
    (set_field(3, "lon", "1e400"), "line 3", "field 'lon': Infinity is not a finite number"),
    (set_field(3, "ais", '"yes"'), "line 3", "field 'ais'"),
    (set_field(3, "mmsi", "1234567890"), "line 3", "field 'mmsi': 1234567890 is not an MMSI"),
    (set_field(3, "mmsi", '"257000001"'), "line 3", "field 'mmsi': '257000001' is not an MMSI"),
    (set_field(3, "centre_lat", "59.43"), "line 3", "field 'centre_lat' without 'centre_lon'"),
    (set_field(3, "centre_lon", "10.47"), "line 3", "field 'centre_lon' without 'centre_lat'"),
    (lambda ls: set_field(3, "centre_lon", "1e400")(set_field(3, "centre_lat", "59.43")(ls)), "line 3",
     "field 'centre_lon': Infinity is not a finite number"),
    (set_field(3, "name", "null"), "line 3", "field 'name' is null"),
    (lambda ls: ls[:6] + ls[7:13] + ls[6:7] + ls[13:], "line 13", "before the previous line's"),
    (lambda ls: ls[:3] + ls[2:3] + ls[3:], "line 4", "id 2 a second time at t = 0.0"),
    (set_field(9, "name", '"zulu"'), "line 9", "id 2 is 'zulu' (iceberg) here but 'bravo'"),
    (lambda ls: [x.replace('"echo", "kind": "ship"', '"echo", "kind": "ownship"') for x in ls], "line 6",
     "a second own ship (id 5; the first is id 0)"),
    (lambda ls: [x for x in ls if '"ownship"' not in x], "(file)", "no own ship"),
    (lambda ls: [], "(file)", "holds no truth samples"),
    (lambda ls: ls[:-1] + [ls[-1][:30]], "line 1206", "not valid JSON"),
    (set_field(1206, "t", "1e12"), "line 1206", "is not a finite number in [0, 1e+08]"),
]


@pytest.mark.parametrize("edit, where, what", TRUTH_CASES)
def test_a_broken_truth_line_is_one_error_line_and_nothing_written(broken, capsys, edit, where, what):
    edit_lines(broken / "truth.jsonl", edit)
    evaluate_fails(broken, capsys, "truth.jsonl", where, what)


def test_truth_cut_inside_its_last_line_and_bytes_not_utf8_are_errors(broken, capsys):
    path = broken / "truth.jsonl"
    data = path.read_bytes()
    path.write_bytes(data[:-40])  # a crash while writing: no final newline, half a line
    evaluate_fails(broken, capsys, "truth.jsonl", "line 1206", "not valid JSON")
    path.write_bytes(data.replace(b'"bravo"', b'"br\xffvo"', 1))
    evaluate_fails(broken, capsys, "truth.jsonl", "line 3", "not UTF-8")


REPORT_CASES = [  # (file, edit, place, what)
    ("detected_targets.jsonl", set_field(2, "target_id", '"7"'), "line 2", "field 'target_id': \"7\" is not an integer"),
    ("detected_targets.jsonl", set_field(2, "latitude", "null"), "line 2", "field 'latitude': null is not a number"),
    ("detected_targets.jsonl", set_field(2, "position_cov_m2", "[[1, 2], [3]]"), "line 2", "not a 2x2 matrix"),
    ("detected_targets.jsonl", set_field(2, "sog_mps", "Infinity"), "line 2", "field 'sog_mps': Infinity"),
    ("detected_targets.jsonl", set_field(2, "object_descriptor", "7"), "line 2", "is not a string"),
    ("detected_targets.jsonl", lambda ls: ls[5:6] + ls[:5] + ls[6:], "line 2", "before the previous line's"),
    ("detected_targets.jsonl", set_field(2, "t", "-1.0"), "line 2", "is not a finite number in [0, 1e+08]"),
    ("sensor_tracks.jsonl", lambda ls: [ls[0].replace('"sensor": "ais", ', "")] + ls[1:], "line 1",
     "field 'sensor' missing"),
    ("sensor_tracks.jsonl", lambda ls: ls[:2] + ["true"] + ls[2:], "line 3", "not a JSON object"),
]


@pytest.mark.parametrize("file, edit, where, what", REPORT_CASES)
def test_a_broken_report_line_is_one_error_line_and_nothing_written(broken, capsys, file, edit, where, what):
    edit_lines(broken / "tdm" / file, edit)
    evaluate_fails(broken, capsys, f"tdm/{file}", where, what)


def edit_yaml(path, key_path: str, value) -> None:
    data = yaml.safe_load(path.read_text(encoding="utf-8"))
    *parents, last = key_path.split(".")
    node = data
    for key in parents:
        node = node[key]
    node[last] = value
    path.write_text(yaml.safe_dump(data), encoding="utf-8")


SETTING_CASES = [  # (file, key path, value): the readers of tdm.io may refuse these first, in their words
    ("scenario.yaml", "tdm.update_rate_hz", 0),
    ("scenario.yaml", "tdm.update_rate_hz", 1e9),
    ("scenario.yaml", "tdm.update_rate_hz", float("inf")),
    ("scenario.yaml", "tdm.update_rate_hz", True),
    ("scenario.yaml", "sensors.radar.range_m", float("nan")),
    ("scenario.yaml", "sensors.ais.range_m", -5),
    ("scenario.yaml", "sensors", ["radar"]),
    ("manifest.json", "duration_s", "long"),
    ("manifest.json", "sensors_rendered", "radar"),
]


@pytest.mark.parametrize("file, key_path, value", SETTING_CASES)
def test_a_bad_setting_is_one_error_line_naming_its_key(broken, capsys, file, key_path, value):
    path = broken / file
    if file == "manifest.json":
        data = json.loads(path.read_text(encoding="utf-8"))
        data[key_path] = value
        path.write_text(json.dumps(data), encoding="utf-8")
    else:
        edit_yaml(path, key_path, value)
    evaluate_fails(broken, capsys, file, key_path, "")


PARAM_CASES = [  # (manifest, scenario, file, place, what): tdm.eval_params itself, whatever tdm.io lets through
    ({}, {"tdm": {"update_rate_hz": 0}}, "scenario.yaml", "tdm.update_rate_hz", "0 is not a finite positive number"),
    ({}, {"tdm": {"update_rate_hz": 1e9}}, "scenario.yaml", "tdm.update_rate_hz", "up to 1000"),
    ({}, {"tdm": {"update_rate_hz": float("inf")}}, "scenario.yaml", "tdm.update_rate_hz", "inf is not a finite"),
    ({}, {"tdm": {"update_rate_hz": True}}, "scenario.yaml", "tdm.update_rate_hz", "True is not a finite"),
    ({}, {"sensors": {"radar": {"range_m": float("nan")}}}, "scenario.yaml", "sensors.radar.range_m", "nan is not"),
    ({}, {"sensors": {"ais": {"range_m": -5}}}, "scenario.yaml", "sensors.ais.range_m", "-5 is not a finite"),
    ({}, {"sensors": ["radar"]}, "scenario.yaml", "sensors", "must be a mapping"),
    ({"duration_s": "long"}, {}, "manifest.json", "duration_s", "'long' is not a finite positive number"),
    ({"sensors_rendered": "radar"}, {}, "manifest.json", "sensors_rendered", "is not a list of sensor names"),
    ([], {}, "manifest.json", "(top level)", "must be a mapping"),
]


@pytest.mark.parametrize("manifest, scenario, file, where, what", PARAM_CASES)
def test_each_setting_the_evaluation_uses_is_checked(tmp_path, manifest, scenario, file, where, what):
    with pytest.raises(RecordingError) as err:
        read_params(tmp_path, manifest, scenario)
    assert (err.value.file, err.value.where) == (str(tmp_path / file), where) and what in err.value.what


def test_absent_settings_take_their_defaults():
    params = read_params(Path("rec"), {"duration_s": 0}, {"sensors": None})
    assert (params.rate_hz, params.radar_range_m, params.ais_range_m, params.lidar_range_m) == (1.0, math.inf,
                                                                                                 math.inf, 100.0)
    assert params.duration_s is None and params.rendered == []


def test_the_epoch_grid_is_bounded_before_it_is_made(broken, capsys, monkeypatch):
    monkeypatch.setattr(tdm.eval_truth, "MAX_EPOCHS", 100)
    edit_yaml(broken / "scenario.yaml", "tdm.update_rate_hz", 10.0)  # 20 s at 10 Hz: 200 epochs
    evaluate_fails(broken, capsys, "truth.jsonl", "(file)", "that is 200 epochs, more than the evaluation's 100")
    monkeypatch.setattr(tdm.eval_truth, "MAX_EPOCHS", 1000)
    monkeypatch.setattr(tdm.eval_truth, "MAX_EPOCH_OBJECT_CELLS", 500)  # 201 epochs x 5 objects
    evaluate_fails(broken, capsys, "truth.jsonl", "(file)", "5 objects at 201 epochs")


# ----------------------------------------------------------------------------------------------- sweeps


def radar_sweeps(rec, revolutions=8):
    sweeps = rec / "radar" / "sweeps"
    sweeps.mkdir(parents=True)
    for rev in range(revolutions):
        save_sweep(sweeps, rev, [1, 2, 3])
    return sweeps


def test_sweeps_cut_short_are_counted_warnings_and_count_as_not_seen(broken, capsys):
    sweeps = radar_sweeps(broken)
    assert main(["evaluate", str(broken), "--no-plots"]) == 0
    every = json.loads((broken / "tdm" / "metrics.json").read_text())
    whole = (sweeps / "000003.npz").read_bytes()
    for name in ("000003.npz", "000004.npz"):
        (sweeps / name).unlink()
    assert main(["evaluate", str(broken), "--no-plots"]) == 0
    without = json.loads((broken / "tdm" / "metrics.json").read_text())
    assert without["in_range_pairs"] < every["in_range_pairs"]  # those sweeps matter
    (sweeps / "000003.npz").write_bytes(whole[:len(whole) // 2])  # the renderer stopped while writing it
    (sweeps / "000004.npz").write_bytes(b"")  # created, nothing written
    capsys.readouterr()
    assert main(["evaluate", str(broken), "--no-plots"]) == 0
    cut_short = "radar/sweeps: unreadable sweep files (zip archive cut short), counted as not seen"
    empty = "radar/sweeps: unreadable sweep files (zero bytes), counted as not seen"
    assert sorted(capsys.readouterr().err.splitlines()) == sorted([f"warning: {cut_short}: 1", f"warning: {empty}: 1"])
    cut = json.loads((broken / "tdm" / "metrics.json").read_text())
    assert cut.pop("warnings") == {cut_short: 1, empty: 1}
    assert cut == without  # a sweep cut short saw nothing
    assert "warnings" not in every


def npz_bytes(arrays: dict, raw: dict | None = None) -> bytes:
    """An NPZ archive of ``arrays``, plus members given as raw .npy bytes."""
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w") as archive:
        for name, array in arrays.items():
            member = io.BytesIO()
            np.lib.format.write_array(member, np.asarray(array), allow_pickle=True)
            archive.writestr(f"{name}.npy", member.getvalue())
        for name, data in (raw or {}).items():
            archive.writestr(f"{name}.npy", data)
    return buffer.getvalue()


def radar_arrays(**change):
    arrays = {"time": np.arange(8) * 2.5 / 8, "azimuth_deg": np.arange(8) * 45.0, "heading_deg": np.zeros(8),
              "object_id": np.array([1, 2, 3], np.int32), "object_spokes": np.full(3, 10, np.int32)}
    arrays.update(change)
    return arrays


def huge_header() -> bytes:
    member = io.BytesIO()
    np.lib.format.write_array_header_1_0(member, {"descr": "<f8", "fortran_order": False, "shape": (10 ** 12,)})
    return member.getvalue() + b"\0" * 64


SWEEP_CASES = [  # (arrays, raw members, place, what)
    (radar_arrays(object_id=np.array([1.0, 2.0, 3.0])), None, "object_id", "expected 1-D of kind 'i' or 'u'"),
    (radar_arrays(time=np.zeros((2, 4))), None, "time", "shape (2, 4)"),
    (radar_arrays(object_spokes=np.full(2, 10, np.int32)), None, "object_id, object_spokes", "lengths differ"),
    (radar_arrays(heading_deg=np.full(8, np.nan)), None, "heading_deg", "NaN or infinite"),
    (radar_arrays(object_id=np.array([1, "x", None], dtype=object)), None, "object_id", "pickled"),
]


def test_a_sweep_header_claiming_more_than_its_file_is_damaged_data_counted_not_allocated(broken, capsys):
    """As in tdm run (tdm.recording.npz): a warning, the sweep not seen, nothing allocated from the header."""
    sweeps = radar_sweeps(broken)
    arrays = {k: v for k, v in radar_arrays().items() if k != "time"}
    (sweeps / "000002.npz").write_bytes(npz_bytes(arrays, {"time": huge_header()}))
    capsys.readouterr()
    assert main(["evaluate", str(broken), "--no-plots"]) == 0
    assert "warning: radar/sweeps: unreadable sweep files (damaged array data)" in capsys.readouterr().err


@pytest.mark.parametrize("arrays, raw, where, what", SWEEP_CASES)
def test_a_hand_edited_sweep_array_is_an_error(broken, capsys, arrays, raw, where, what):
    sweeps = radar_sweeps(broken)
    (sweeps / "000002.npz").write_bytes(npz_bytes(arrays, raw))
    evaluate_fails(broken, capsys, "radar/sweeps/000002.npz", where, what)


def test_a_lidar_sweep_of_the_wrong_dtype_is_an_error_and_a_cut_one_a_warning(tmp_path, capsys):
    rec = make_recording(tmp_path / "rec", sensors=("lidar",), tracks=False)
    sweeps = rec / "lidar" / "sweeps"
    sweeps.mkdir(parents=True)
    for i in range(3):
        np.savez(sweeps / f"{i:06d}.npz", time=3.0 * i + np.linspace(0, 0.099, 10),
                 object_id=np.r_[np.full(5, 2), np.full(5, -1)].astype(np.int32))
    (sweeps / "000001.npz").write_bytes((sweeps / "000001.npz").read_bytes()[:100])
    capsys.readouterr()
    assert main(["evaluate", str(rec), "--no-plots"]) == 0
    assert "warning: lidar/sweeps: unreadable sweep files (zip archive cut short)" in capsys.readouterr().err
    np.savez(sweeps / "000001.npz", time=np.arange(10), object_id=np.zeros(10, np.int32))  # integer times
    evaluate_fails(rec, capsys, "lidar/sweeps/000001.npz", "time", "expected 1-D of kind 'f'")


# ----------------------------------------------------------------------------------------------- truth kept


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_truth_kept_around_the_epochs_interpolates_exactly_as_all_of_it(tmp_path, seed):
    """Irregular steps, gaps, objects coming and going, null SOG, epochs off the samples: bit for bit."""
    rng = np.random.default_rng(seed)
    times = np.round(np.cumsum(rng.choice([0.1, 0.05, 0.3], 300)), 3)
    spans = {i: sorted(rng.choice(times.size, 2, replace=False)) for i in range(1, 6)}
    lines = []
    for j, t in enumerate(times):  # loop over time steps, then objects
        for oid in range(6):
            if oid and (not spans[oid][0] <= j <= spans[oid][1] or rng.random() < 0.1):
                continue
            lines.append(json.dumps({"t": float(t), "id": oid, "name": f"o{oid}", "kind": "ship" if oid else "ownship",
                                     "lat": 59.4 + 1e-3 * rng.normal(), "lon": 10.4 + 1e-3 * rng.normal(),
                                     "cog_deg": float(rng.uniform(0, 360)),
                                     "sog_mps": float(rng.uniform(0, 5)) if rng.random() < 0.9 else None,
                                     "ais": bool(rng.random() < 0.5)}))
    (tmp_path / "truth.jsonl").write_text("\n".join(lines) + "\n", encoding="utf-8")
    reports_s = np.sort(np.r_[np.round(rng.uniform(times[0], times[-1], 20), 6), times[rng.choice(times.size, 10)]])
    epochs = epoch_grid(reports_s, float(rng.choice([0.7, 1.0, 3.0, 10.0])), times[0], times[-1])
    _, every = read_truth_enu(tmp_path)
    _, kept = read_truth_enu(tmp_path, epochs)
    assert kept["t"].size < every["t"].size
    a, b = truth_at(every, epochs), truth_at(kept, epochs)
    for name in ("ids", "east_m", "north_m", "cog_deg", "sog_mps", "ais", "range_m", "own_east_m", "own_north_m"):
        assert np.array_equal(getattr(a, name), getattr(b, name), equal_nan=getattr(a, name).dtype.kind == "f"), name
    assert (a.names, a.kinds) == (b.names, b.kinds)

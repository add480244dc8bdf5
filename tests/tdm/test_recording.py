"""tdm.recording: the reader layer's parts that the corpus (test_corpus.py) does not reach one by one."""

from __future__ import annotations

import io
import pickle
import zipfile
from pathlib import Path

import numpy as np
import pytest

from tdm.detections import ReadStats
from tdm.errors import RecordingError
from tdm.pipeline import _EpochTimes
from tdm.recording import npz as npz_module
from tdm.recording.npz import NpzFile, Unreadable, load_arrays, read_layout
from tdm.recording.pcap_times import BACK, OUTSIDE, PacketClock
from tdm.recording.values import integer, number


def _npz(path, members: dict[str, bytes]) -> None:
    with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_DEFLATED) as zf:
        for name, data in members.items():
            zf.writestr(name, data)


def _npy(array: np.ndarray, version=(1, 0)) -> bytes:
    buf = io.BytesIO()
    np.lib.format.write_array(buf, array, version=version)
    return buf.getvalue()


def test_arrays_read_as_np_load_reads_them(tmp_path):
    arrays = {"a": np.arange(12, dtype=">f8").reshape(3, 4), "b": np.asfortranarray(np.ones((2, 5), np.uint8)),
              "c": np.zeros(0, np.int32)}
    np.savez(tmp_path / "plain.npz", **arrays)
    np.savez_compressed(tmp_path / "packed.npz", **arrays)
    _npz(tmp_path / "v2.npz", {f"{k}.npy": _npy(v, (2, 0)) for k, v in arrays.items()})
    for name in ("plain.npz", "packed.npz", "v2.npz"):
        got = load_arrays(tmp_path / name, ("a", "b", "c"))
        with np.load(tmp_path / name) as want:
            for key in arrays:
                assert got[key].dtype == want[key].dtype and got[key].shape == want[key].shape
                assert np.array_equal(got[key], want[key]) and got[key].flags.writeable
                assert got[key].flags.f_contiguous == want[key].flags.f_contiguous
        assert read_layout(tmp_path / name)["a"].shape == (3, 4)


def _load(path, names, preload: bool) -> dict:
    """The arrays ``names``, read with the headers (``preload``, as read_sweep reads) or after them."""
    with NpzFile(path, preload=names if preload else ()) as npz:
        return npz.load(names)


@pytest.mark.parametrize("preload", [True, False])
@pytest.mark.parametrize("in_memory", [True, False])
def test_both_reading_routes_give_np_load_arrays(tmp_path, monkeypatch, in_memory, preload):
    """Small files are read whole and their stored members sliced out; larger ones go through zipfile."""
    if not in_memory:
        monkeypatch.setattr(npz_module, "IN_MEMORY_MAX_BYTES", 0)
    arrays = {"f": np.linspace(0, 1, 7, dtype="<f4"), "d": np.arange(6, dtype=">f8").reshape(2, 3),
              "u": np.arange(5, dtype=np.uint8), "b": np.array([True, False]), "z": np.array([1 + 2j]),
              "s": np.float64(3.5), "t": np.array(["2026-11-27"], dtype="datetime64[ns]"),
              "r": np.zeros(3, dtype=[("a", "<i4"), ("b", "<f8")])}
    np.savez(tmp_path / "a.npz", **arrays)
    got = _load(tmp_path / "a.npz", tuple(arrays), preload)
    with np.load(tmp_path / "a.npz") as want:
        for key in arrays:
            assert got[key].dtype == want[key].dtype and got[key].shape == want[key].shape, key
            assert np.array_equal(got[key], want[key]) and got[key].flags.writeable and got[key].flags.aligned


def test_the_fast_header_parser_agrees_with_numpys():
    for array in (np.zeros((), "<f8"), np.zeros(3, ">i2"), np.zeros((3, 4), "|u1"), np.zeros((2, 0, 5), "<c16"),
                  np.asfortranarray(np.zeros((2, 3), "<f4")), np.zeros(1, "|b1"), np.zeros(2, "<M8[ns]")):
        member = _npy(array)
        raw = member[:10 + int.from_bytes(member[8:10], "little")]  # magic to the end of the header text
        fp = io.BytesIO(raw)
        np.lib.format.read_magic(fp)
        assert npz_module._decode_header.__wrapped__(raw) == np.lib.format.read_array_header_1_0(fp), array.dtype


def _central_directory_entry(content: bytes, name: bytes) -> int:
    """Where the zip central directory's entry for member ``name`` starts."""
    at = content.find(b"PK\x01\x02")
    while content[at + 46:at + 46 + len(name)] != name:
        at = content.find(b"PK\x01\x02", at + 4)
    return at


@pytest.mark.parametrize("preload", [True, False])
@pytest.mark.parametrize("in_memory", [True, False])
@pytest.mark.parametrize("fault", ["data", "crc", "local header", "header cut"])
def test_a_damaged_stored_member_is_unreadable_on_both_routes(tmp_path, monkeypatch, in_memory, fault, preload):
    if not in_memory:
        monkeypatch.setattr(npz_module, "IN_MEMORY_MAX_BYTES", 0)
    np.savez(tmp_path / "a.npz", y=np.arange(3), x=np.arange(1000, dtype=np.float64))  # x not at the start
    content = bytearray((tmp_path / "a.npz").read_bytes())
    with zipfile.ZipFile(tmp_path / "a.npz") as zf:
        x_at = zf.getinfo("x.npy").header_offset
    if fault == "data":  # a flipped byte inside x's data: its CRC-32 no longer matches
        content[x_at + 2000] ^= 0xFF
    elif fault == "crc":  # the central directory's CRC-32 of x changed
        content[_central_directory_entry(bytes(content), b"x.npy") + 16] ^= 0xFF
    elif fault == "local header":  # x's local header overwritten
        content[x_at:x_at + 4] = b"\0\0\0\0"
    else:  # x's .npy header says its text is longer than the member
        x_data = x_at + 30 + len("x.npy") + int.from_bytes(content[x_at + 28:x_at + 30], "little")  # + extra field
        content[x_data + 8:x_data + 10] = (60000).to_bytes(2, "little")
    (tmp_path / "b.npz").write_bytes(bytes(content))
    with pytest.raises(Unreadable) as caught:
        _load(tmp_path / "b.npz", ("x", "y"), preload)
    assert caught.value.reason == "damaged array data" and "'x'" in caught.value.detail


def _npy_claiming(data: np.ndarray, shape_text: str) -> bytes:
    """A version 1.0 ``.npy`` member holding ``data`` (float32) whose header says shape ``shape_text``."""
    header = ("{'descr': '<f4', 'fortran_order': False, 'shape': %s, }" % shape_text).ljust(117) + "\n"
    return b"\x93NUMPY\x01\x00" + len(header).to_bytes(2, "little") + header.encode("latin1") + data.tobytes()


def test_a_header_claiming_more_than_its_member_holds_is_refused_before_any_allocation(tmp_path):
    data = np.zeros(10, np.float32)
    _npz(tmp_path / "honest.npz", {"x.npy": _npy_claiming(data, "(10,)")})
    assert load_arrays(tmp_path / "honest.npz", ("x",))["x"].shape == (10,)
    _npz(tmp_path / "lying.npz", {"x.npy": _npy_claiming(data, "(9999999999999,)")})  # 40 TB
    with pytest.raises(Unreadable) as info:
        NpzFile(tmp_path / "lying.npz")
    assert info.value.reason == "damaged array data" and "9999999999999" not in info.value.reason


def test_object_arrays_and_unknown_versions_are_errors(tmp_path):
    np.savez(tmp_path / "objects.npz", x=np.array([{}, None], dtype=object))
    with pytest.raises(RecordingError, match="pickled data"):
        read_layout(tmp_path / "objects.npz")
    _npz(tmp_path / "v3.npz", {"x.npy": _npy(np.arange(3), (3, 0))})
    with pytest.raises(RecordingError, match="version"):
        read_layout(tmp_path / "v3.npz")


@pytest.mark.parametrize("content, reason", [(b"", "zero bytes"), (b"\0" * 100, "not a zip archive"),
                                             (b"PK\x03\x04" + b"\0" * 60, "zip archive cut short")])
def test_unreadable_files_say_why(tmp_path, content, reason):
    (tmp_path / "s.npz").write_bytes(content)
    with pytest.raises(Unreadable) as info:
        read_layout(tmp_path / "s.npz")
    assert info.value.reason == reason
    assert pickle.loads(pickle.dumps(info.value)).reason == reason  # crosses process boundaries


def test_recording_errors_cross_process_boundaries():
    exc = pickle.loads(pickle.dumps(RecordingError("a.npz", "x", "not a finite number")))
    assert (exc.file, exc.where, exc.what) == ("a.npz", "x", "not a finite number")


def test_the_packet_clock_skips_packets_outside_the_run_and_going_back():
    clock, stats = PacketClock((-60.0, 66.0)), ReadStats()
    s = 1_000_000_000
    keep = clock.keep(np.array([0, 1, -100 * s, 2, 1, 3, 10**18]) * np.array([s, s, 1, s, s, s, 1]), stats)
    assert keep.tolist() == [True, True, False, True, False, True, False]
    assert stats.warnings == {OUTSIDE: 2, BACK: 1}
    assert clock.keep(np.array([2 * s, 4 * s]), stats).tolist() == [False, True]  # the state carries over


def test_the_output_epochs_are_those_of_the_array_they_replace():
    for duration_s, rate_hz in ((300.0, 1.0), (20.0, 3.0), (7.3, 0.7), (60.0, 50.0)):
        n = int(np.floor(duration_s * rate_hz + 1e-9))
        lazy, eager = _EpochTimes(n, rate_hz), np.arange(1, n + 1) / rate_hz
        assert len(lazy) == eager.size and all(lazy[k] == eager[k] for k in range(n))  # bit for bit


def test_numbers_are_finite_and_bounded():
    assert number(5, "f", "k", 0.0, 10.0, low_open=True) == 5.0
    for bad in (float("nan"), float("inf"), True, "5", None, 0.0, 11.0):
        with pytest.raises(RecordingError):
            number(bad, "f", "k", 0.0, 10.0, low_open=True)
    assert integer(2048.0, "f", "k", 1, 65536) == 2048
    with pytest.raises(RecordingError, match="whole number"):
        integer(2048.5, "f", "k", 1, 65536)


def test_a_plain_stored_archives_directory_is_read_as_zipfile_reads_it(tmp_path):
    from groundfloor.zip_stored import stored_members

    np.savez(tmp_path / "a.npz", x=np.arange(10.0), ring=np.arange(4, dtype=np.uint8), empty=np.zeros(0))
    data = (tmp_path / "a.npz").read_bytes()
    members = stored_members(data)
    with zipfile.ZipFile(tmp_path / "a.npz") as zf:
        infos = zf.infolist()
        assert [(m.filename, m.file_size, m.CRC) for m in members] == [(i.filename, i.file_size, i.CRC) for i in infos]
        for member, info in zip(members, infos):
            assert data[member.data_start:member.data_start + member.file_size] == zf.read(info)
    # anything else is left to zipfile: compressed, a comment, data in front, a cut directory
    np.savez_compressed(tmp_path / "c.npz", x=np.arange(10.0))
    with zipfile.ZipFile(tmp_path / "m.npz", "w") as zf:
        zf.writestr("x.npy", _npy(np.arange(3)))
        zf.comment = b"made by hand"
    assert stored_members((tmp_path / "c.npz").read_bytes()) is None
    assert stored_members((tmp_path / "m.npz").read_bytes()) is None
    assert stored_members(b"junk" + data) is None
    assert stored_members(data[:-30] + data[-22:]) is None
    assert stored_members(data[:10]) is None


@pytest.mark.parametrize("bad", [None, "nan", "inf", "below", "above", "early", "late", "at_bounds"])
@pytest.mark.parametrize("dtype", ["float32", "float64"])
def test_sweep_values_pass_on_their_extremes_alone_and_fail_as_the_checks_one_by_one(bad, dtype):
    """check_values' shortcut (least and greatest value) passes exactly the arrays the checks one by one pass,
    and a failing array still gets the message naming its first bad value."""
    from groundfloor.recording import ArraySpec, SweepSchema
    from tdm.recording.sweeps import _plainly_good, check_values
    spec = ArraySpec("v", dtype, ("points",), low=-2.0, high=3.0)
    schema = SweepSchema("lidar", (spec, ArraySpec("time", "float64", ("points",))))
    window_s = (10.0, 20.0)
    rng = np.random.default_rng(5)
    v = rng.uniform(-1.9, 2.9, 50).astype(dtype)
    time = rng.uniform(10.5, 19.5, 50)
    place = {"nan": ("v", np.nan), "inf": ("v", np.inf), "below": ("v", -2.5), "above": ("v", 3.5),
             "early": ("time", 9.0), "late": ("time", 21.0)}.get(bad)
    if bad == "at_bounds":
        v[3], v[4], time[5], time[6] = -2.0, 3.0, 10.0, 20.0
    if place is not None:
        (v if place[0] == "v" else time)[17] = place[1]
    arrays = {"v": v, "time": time}
    one_by_one_passes = not (~np.isfinite(v) | (v < -2.0) | (v > 3.0)).any() and not ((time < 10) | (time > 20)).any()
    shortcut = all(_plainly_good(n, a, schema.spec(n), window_s) for n, a in arrays.items())
    assert shortcut == one_by_one_passes == (bad in (None, "at_bounds"))
    if one_by_one_passes:
        check_values(Path("s.npz"), arrays, schema, window_s)
    else:
        with pytest.raises(RecordingError, match=f"s.npz: {place[0]}: .* at index 17"):
            check_values(Path("s.npz"), arrays, schema, window_s)

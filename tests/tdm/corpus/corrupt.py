"""Helpers of the corpus of broken recordings: outcomes, cases, copying and corrupting a recording.

A copy is made of hard links to the valid recording (:func:`materialise`); a corruption never
writes into a linked file, it replaces it (:func:`replace`), so the original stays intact.
"""

from __future__ import annotations

import json
import os
import shutil
import struct
from dataclasses import dataclass
from functools import reduce
from pathlib import Path
from typing import Callable

import numpy as np

SKIPPED = ("rosbag", "bev", "ppi", "tdm", "map.png")
M, S, O, T, A, P = "manifest.json", "scenario.yaml", "ownship.jsonl", "truth.jsonl", "ais/ais.nmea", "lidar/hdl32e.pcap"
TARGETS = "tdm/detected_targets.jsonl"


def lidar(i: int) -> str:
    return f"lidar/sweeps/{i:06d}.npz"


def radar(i: int) -> str:
    return f"radar/sweeps/{i:06d}.npz"


# ----------------------------------------------------------------------------- outcomes


@dataclass(frozen=True)
class Outcome:
    """What a command must do: exit ``code``; on error the line starts ``error: <rec>/<file>: <place>: ``
    and holds ``what``; on success the warnings are exactly ``warnings`` (run and info)."""

    code: int
    file: str = ""
    place: str = ""
    what: str = ""
    warnings: tuple[tuple[str, int], ...] = ()

    def text(self) -> str:
        if self.code and not self.place:
            return f"error: `{self.file or '.'}: ...` (its reader's message)"
        if self.code:
            return f"error: `{self.file or '.'}: {self.place}: ...{self.what + '...' if self.what else ''}`"
        return "ok" + "".join(f"; {k}: {n}" for k, n in self.warnings)


def warn(*pairs: tuple[str, int]) -> Outcome:
    return Outcome(0, warnings=tuple(sorted(pairs)))


def err(file: str, place: str, what: str = "") -> Outcome:
    return Outcome(2, file, place, what)


OK = Outcome(0)
CUT_LINE = ("ownship.jsonl: cut last line skipped (file ends inside a line)", 1)
LGAP, RGAP = "lidar: sweep files missing from the numbering", "radar: sweep files missing from the numbering"
UNREADABLE = "{}/sweeps: unreadable sweep files ({})"
PCAP_CUT = "lidar/pcap: truncated last record skipped (file cut)"
PCAP_BAD = "lidar/pcap: record with a bad header or length skipped"
PCAP_OUT = "lidar/pcap: packet with a time outside the run skipped"
PCAP_BACK = "lidar/pcap: packet with a time going back skipped"
PCAP_CLOCK = "lidar/pcap: packet clock off the capture time by > 10 s (capture time used)"
AIS = "ais/nmea: "


@dataclass(frozen=True)
class Case:
    """One corrupted copy.

    Attributes
    ----------
    name, description : str
    corrupt : callable
        Breaks a fresh copy (its argument: the copy's directory).
    info, run, evaluate : Outcome
    run_args : tuple of str
        Extra ``tdm run`` arguments (``--lidar-source pcap``).
    as_user : bool
        Only meaningful for a user other than root (root reads any file).
    outputs : callable, optional
        Breaks ``tdm/`` after the run, before ``tdm evaluate``.
    """

    name: str
    description: str
    corrupt: Callable[[Path], None]
    info: Outcome
    run: Outcome
    evaluate: Outcome
    run_args: tuple[str, ...] = ()
    as_user: bool = False
    outputs: Callable[[Path], None] | None = None


# ----------------------------------------------------------------------------- copying and corrupting


def materialise(base: Path, dest: Path) -> Path:
    """A copy of ``base`` made of hard links (the pictures, the bag and tdm/ left out)."""
    for folder, dirs, files in os.walk(base):
        rel = Path(folder).relative_to(base)
        dirs[:] = [d for d in dirs if d not in SKIPPED]
        (dest / rel).mkdir(parents=True, exist_ok=True)
        for name in files:
            if name not in SKIPPED:
                os.link(Path(folder) / name, dest / rel / name)
    return dest


def replace(path: Path, data: bytes) -> None:
    """Write ``data`` as a new file at ``path`` (never into a linked one)."""
    if os.path.lexists(path):
        path.unlink()
    path.write_bytes(data)


def remove(path: Path) -> None:
    shutil.rmtree(path) if path.is_dir() and not path.is_symlink() else path.unlink()


def as_dir(path: Path) -> None:
    remove(path)
    path.mkdir()


def link_loop(path: Path) -> None:
    remove(path)
    path.symlink_to(path.name)


def no_permission(path: Path) -> None:
    replace(path, path.read_bytes())
    path.chmod(0)


def cut(path: Path, keep: float | int) -> None:
    """Keep the first ``keep`` bytes (a negative int drops that many from the end; a float: a fraction)."""
    data = path.read_bytes()
    replace(path, data[: keep if isinstance(keep, int) else int(len(data) * keep)])


def json_edit(path: Path, edit: Callable[[dict], object]) -> None:
    """Edit a JSON object file in place (``edit`` changes the dict)."""
    data = json.loads(path.read_text())
    edit(data)
    replace(path, json.dumps(data).encode())


def text_edit(path: Path, edit: Callable[[str], str]) -> None:
    replace(path, edit(path.read_text(encoding="utf-8")).encode("utf-8", "surrogateescape"))


def line_edit(path: Path, index: int, edit: Callable[[str], str]) -> None:
    lines = path.read_text().splitlines()
    lines[index] = edit(lines[index])
    replace(path, ("\n".join(lines) + "\n").encode("utf-8", "surrogateescape"))


def swap_lines(path: Path, i: int, j: int) -> None:
    lines = path.read_text().splitlines()
    lines[i], lines[j] = lines[j], lines[i]
    replace(path, ("\n".join(lines) + "\n").encode())


def yaml_set(path: Path, key_path: str, text: str) -> None:
    """Set a nested key of scenario.yaml to the YAML ``text`` (a line edit of the resolved file)."""
    import yaml

    data = yaml.safe_load(path.read_text())
    *parents, last = key_path.split(".")
    reduce(lambda node, key: node[key], parents, data)[last] = yaml.safe_load(text)
    replace(path, yaml.safe_dump(data, sort_keys=False).encode())


def npz_edit(path: Path, edit: Callable[[dict], None], compressed: bool = False) -> None:
    with np.load(path) as z:
        arrays = {k: z[k] for k in z.files}
    edit(arrays)
    path.unlink()
    with open(path, "wb") as handle:
        (np.savez_compressed if compressed else np.savez)(handle, **arrays)


def npz_set(name: str, value: Callable[[np.ndarray], np.ndarray]) -> Callable[[dict], None]:
    return lambda arrays: arrays.__setitem__(name, value(arrays[name]))


def npz_drop(name: str) -> Callable[[dict], None]:
    return lambda arrays: arrays.pop(name)


def with_at(values: np.ndarray, index: int, x) -> np.ndarray:
    out = values.copy()
    out.flat[index] = x
    return out


def huge_header(path: Path) -> None:
    """The ``x.npy`` member's header claims 10^12 points (its data unchanged, the header's length kept)."""
    import zipfile

    with zipfile.ZipFile(path) as zf:
        members = {i.filename: zf.read(i) for i in zf.infolist()}
    raw = members["x.npy"]
    length = struct.unpack_from("<H", raw, 8)[0]
    header = raw[10: 10 + length].decode("latin1")
    start = header.index("'shape': (") + len("'shape': (")
    header = header[:start] + header[header.index(",", start):]  # drop the length
    header = (header[:start] + "1000000000000" + header[start:]).rstrip("\n").rstrip(" ")
    members["x.npy"] = raw[:10] + (header.ljust(length - 1) + "\n").encode("latin1") + raw[10 + length:]
    path.unlink()
    with zipfile.ZipFile(path, "w") as zf:
        for name, data in members.items():
            zf.writestr(name, data)


def rename(rec: Path, pairs: list[tuple[str, str]]) -> None:
    """Rename files at once (a cycle of names swaps them)."""
    for a, _ in pairs:
        os.rename(rec / a, rec / (a + ".tmp"))
    for a, b in pairs:
        os.rename(rec / (a + ".tmp"), rec / b)


def nmea_checksum(body: str) -> str:
    return f"{reduce(lambda c, ch: c ^ ord(ch), body, 0):02X}"


def nmea_sentence(body: str) -> str:
    """``!body*hh`` with its checksum."""
    return f"!{body}*{nmea_checksum(body)}"


def tag_line(unix_s: str, sentence: str) -> str:
    return f"\\c:{unix_s}*{nmea_checksum('c:' + unix_s)}\\{sentence}"


def pcap_records(data: bytes) -> list[tuple[int, int]]:
    """(offset, destination port) of each record of a little-endian Ethernet PCAP."""
    out, pos = [], 24
    while pos + 16 <= len(data):
        size = 16 + struct.unpack_from("<I", data, pos + 8)[0]
        out.append((pos, struct.unpack_from(">H", data, pos + 16 + 36)[0]))
        pos += size
    return out


def pcap_times(path: Path, first: int, count: int, change: Callable[[int], int]) -> None:
    """Change the capture seconds of ``count`` data records from the ``first``-th record on."""
    data = bytearray(path.read_bytes())
    records = [off for off, port in pcap_records(bytes(data))[first:] if port == 2368][:count]
    for off in records:
        struct.pack_into("<I", data, off, change(struct.unpack_from("<I", data, off)[0]))
    replace(path, bytes(data))


def pcap_patch(offset: int, value: bytes) -> Callable[[Path], None]:
    def patch(rec: Path) -> None:
        data = bytearray((rec / P).read_bytes())
        data[offset: offset + len(value)] = value
        replace(rec / P, bytes(data))
    return patch


def pcap_record_length(rec: Path) -> None:
    data = bytearray((rec / P).read_bytes())
    off = [o for o, port in pcap_records(bytes(data))[2000:] if port == 2368][0]
    struct.pack_into("<I", data, off + 8, 0xFFFF0000)
    replace(rec / P, bytes(data))


def each(*steps: Callable[[Path], None]) -> Callable[[Path], None]:
    """A corruption made of several."""
    def run(rec: Path) -> None:
        for step in steps:
            step(rec)
    return run


def at(rel: str, fn: Callable, *args) -> Callable[[Path], None]:
    """A corruption applying ``fn(rec / rel, *args)``."""
    return lambda rec: fn(rec / rel, *args)

"""JSON-lines files (``ownship.jsonl``, ``truth.jsonl``, the TDM's outputs): one JSON object per line.

Every line is UTF-8 JSON holding an object; blank lines are skipped. A line that is not JSON, not
UTF-8, or holds a number, a string, ``null`` or a list is an error naming its line. The one
exception is a last line the file ends inside of (no final newline, not parsable): that is what a
logger killed mid-write leaves, so with a :class:`~tdm.detections.ReadStats` it is counted as a
warning and skipped; without one (``tdm evaluate``, which needs whole files) it is an error.
Field values are checked by the readers of each file (:mod:`tdm.recording.ownship`, ...).
"""

from __future__ import annotations

import json
from pathlib import Path

from tdm.detections import ReadStats
from tdm.errors import RecordingError
from tdm.recording import values
from tdm.recording.files import read_bytes

__all__ = ["read_jsonl", "read_jsonl_lines", "cut_line_warning"]


def cut_line_warning(path: Path) -> str:
    """The warning key of a cut last line of ``path``."""
    return f"{Path(path).name}: cut last line skipped (file ends inside a line)"


def _parse(raw: bytes, path: Path, number: int) -> object:
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise RecordingError(str(path), f"line {number}", f"not UTF-8 text (byte 0x{raw[exc.start]:02x})") from None
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise RecordingError(str(path), f"line {number}", f"not valid JSON: {exc.msg}") from None
    except RecursionError:
        raise RecordingError(str(path), f"line {number}", "not valid JSON: nested too deeply") from None


def read_jsonl_lines(path: Path, stats: ReadStats | None = None,
                     missing: str = "missing") -> tuple[list[dict], list[int]]:
    """The objects of a JSON-lines file and the line number of each.

    Parameters
    ----------
    path : Path
        The file.
    stats : ReadStats, optional
        When given, a cut last line is counted (:func:`cut_line_warning`) and skipped; when not, it
        is an error.
    missing : str
        The message for a missing file.

    Returns
    -------
    rows : list of dict
    line_numbers : list of int
        1-based file line of each row.
    """
    path = Path(path)
    data = read_bytes(path, missing=missing)
    lines = data.split(b"\n")
    cut_candidate = not data.endswith(b"\n") and bool(lines[-1].strip())
    rows: list[dict] = []
    numbers: list[int] = []
    for number, raw in enumerate(lines, start=1):
        if not raw.strip():
            continue
        try:
            row = _parse(raw, path, number)
        except RecordingError:
            if cut_candidate and number == len(lines) and stats is not None:
                stats.count(cut_line_warning(path))
                continue
            raise
        if not isinstance(row, dict):
            raise RecordingError(str(path), f"line {number}", f"not a JSON object but {values.describe(row)}")
        rows.append(row)
        numbers.append(number)
    return rows, numbers


def read_jsonl(path: Path, stats: ReadStats | None = None) -> list[dict]:
    """All objects of a JSON-lines file (module docstring); a bad line is an error naming its number."""
    return read_jsonl_lines(path, stats)[0]

"""``manifest.json``: a JSON object whose keys the TDM uses are present and of their types.

Checked (docs/formats.md "Reading a recording: warnings and errors"): the file is readable UTF-8
JSON holding an object; ``start_time`` is an ISO 8601 time (UTC when it has no offset);
``duration_s`` a finite number in ``(0, MAX_DURATION_S]``; ``format`` (when present)
``"raysim-recording"`` and ``format_version`` at most :data:`FORMAT_VERSION`; ``seed`` an integer or
null, ``scenario`` a string, ``sensors_enabled`` / ``sensors_rendered`` lists of strings, ``counts``
a mapping. Keys the TDM does not use are not checked.
"""

from __future__ import annotations

import json
from pathlib import Path

from groundfloor.recording import FORMAT, FORMAT_VERSION, MANIFEST, parse_start_time as _parse_iso
from tdm.errors import RecordingError
from tdm.recording import values
from tdm.recording.files import decode_utf8, read_bytes

__all__ = ["read_manifest", "start_time_unix_s", "MAX_DURATION_S", "FORMAT", "FORMAT_VERSION"]

#: Longest run the TDM reads, s (7 days): every size derived from a duration is bounded by it.
MAX_DURATION_S = 7 * 86_400.0
#: A manifest is a few kB; a bigger file is not one (read whole, so bounded).
MAX_MANIFEST_BYTES = 16 << 20


def _load_json(path: Path, data: bytes) -> object:
    text = decode_utf8(data, path)
    if not text.strip():
        raise RecordingError(str(path), "(file)", "empty: not a manifest")
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise RecordingError(str(path), f"line {exc.lineno}", f"not valid JSON: {exc.msg}") from None
    except RecursionError:
        raise RecordingError(str(path), "(file)", "not valid JSON: nested too deeply") from None


def _string_list(value: object, path: Path, key: str) -> None:
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        raise RecordingError(str(path), key, f"must be a list of strings, not {values.describe(value)}")


def check_manifest(manifest: object, path: Path) -> dict:
    """The manifest's content if its keys are as module docstring says; else a RecordingError."""
    if not isinstance(manifest, dict):
        raise RecordingError(str(path), "(top level)", f"must be a JSON object, not {values.describe(manifest)}")
    if "format" in manifest and manifest["format"] != FORMAT:
        raise RecordingError(str(path), "format", f"{manifest['format']!r}: not a {FORMAT} manifest")
    if "format_version" in manifest:
        values.integer(manifest["format_version"], path, "format_version", 1, FORMAT_VERSION)
    for key in ("start_time", "duration_s"):
        if key not in manifest:
            raise RecordingError(str(path), key, "missing")
    parse_start_time(manifest["start_time"], path)
    values.number(manifest["duration_s"], path, "duration_s", 0.0, MAX_DURATION_S, low_open=True, unit=" s")
    values.optional(manifest, "seed", values.integer, path)
    values.optional(manifest, "scenario", values.text, path)
    for key in ("sensors_enabled", "sensors_rendered", "sensors_not_available"):
        if manifest.get(key) is not None:
            _string_list(manifest[key], path, key)
    values.optional(manifest, "counts", values.mapping, path)
    return manifest


def read_manifest(recording: Path) -> dict:
    """The recording's ``manifest.json``, checked (module docstring).

    Parameters
    ----------
    recording : Path
        The recording directory.

    Returns
    -------
    dict
        The parsed manifest (unchanged: keys the TDM does not use are kept as they are).

    Raises
    ------
    RecordingError
        ``recording`` is not a directory; the manifest is missing, unreadable, not JSON, or a key
        the TDM uses is missing or malformed.
    """
    recording = Path(recording)
    if not recording.is_dir():
        raise RecordingError(str(recording), "(directory)", "not a directory")
    path = recording / MANIFEST
    data = read_bytes(path, missing="missing: not a recording directory", max_bytes=MAX_MANIFEST_BYTES)
    return check_manifest(_load_json(path, data), path)


def parse_start_time(text: object, path: Path) -> float:
    """UNIX time (s) of an ISO 8601 ``start_time`` (``Z`` or an offset; none = UTC)."""
    if not isinstance(text, str):
        raise RecordingError(str(path), "start_time", f"must be an ISO 8601 time string, not {values.describe(text)}")
    try:
        return _parse_iso(text)
    except ValueError:
        raise RecordingError(str(path), "start_time", f"not an ISO 8601 time: {text[:40]!r}") from None


def start_time_unix_s(manifest: dict, recording: Path) -> float:
    """UNIX time of the recording's start, s (``manifest.json: start_time``)."""
    return parse_start_time(manifest.get("start_time"), Path(recording) / MANIFEST)

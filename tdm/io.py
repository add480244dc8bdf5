"""Readers of a recording directory (docs/contracts.md "Recording directory").

Only the files' formats are used: these readers work on any directory laid out
as the contract says, whoever wrote it.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import yaml

from tdm.errors import RecordingError

OWNSHIP_FIELDS = ("t", "lat", "lon", "x", "y", "z", "heading_deg", "roll_deg", "pitch_deg", "cog_deg", "sog_mps")


def read_manifest(recording: Path) -> dict:
    """The recording's manifest.json as a dict."""
    path = Path(recording) / "manifest.json"
    if not Path(recording).is_dir():
        raise RecordingError(str(recording), "(directory)", "not a directory")
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise RecordingError(str(path), "(file)", "missing: not a recording directory") from None
    except json.JSONDecodeError as exc:
        raise RecordingError(str(path), f"line {exc.lineno}", f"not valid JSON: {exc.msg}") from None


def read_jsonl(path: Path) -> list[dict]:
    """All objects of a JSON-lines file; a bad line is an error naming its number."""
    rows = []
    try:
        with open(path, encoding="utf-8") as handle:
            for number, line in enumerate(handle, start=1):
                if not line.strip():
                    continue
                try:
                    rows.append(json.loads(line))
                except json.JSONDecodeError as exc:
                    raise RecordingError(str(path), f"line {number}", f"not valid JSON: {exc.msg}") from None
    except FileNotFoundError:
        raise RecordingError(str(path), "(file)", "missing") from None
    return rows


def read_ownship(recording: Path) -> dict[str, np.ndarray]:
    """ownship.jsonl as columns: (N,) float64 arrays named as the contract's fields."""
    path = Path(recording) / "ownship.jsonl"
    rows = read_jsonl(path)
    if not rows:
        raise RecordingError(str(path), "(file)", "holds no navigation samples")
    out = {}
    for key in OWNSHIP_FIELDS:
        try:
            out[key] = np.array([r[key] for r in rows], dtype=float)
        except KeyError:
            raise RecordingError(str(path), key, "field missing on some line") from None
    return out


def read_truth(recording: Path) -> list[dict]:
    """truth.jsonl rows (only evaluation may use truth)."""
    return read_jsonl(Path(recording) / "truth.jsonl")


def read_scenario(recording: Path) -> dict:
    """The recording's resolved scenario.yaml (sensor mounts, own-ship size, TDM rate)."""
    path = Path(recording) / "scenario.yaml"
    try:
        data = yaml.safe_load(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise RecordingError(str(path), "(file)", "missing: not a recording directory") from None
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        raise RecordingError(str(path), f"line {mark.line + 1}" if mark else "(file)", "not valid YAML") from None
    if not isinstance(data, dict):
        raise RecordingError(str(path), "(top level)", "must be a mapping")
    return data

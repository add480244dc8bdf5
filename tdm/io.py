"""Readers of a recording directory (docs/contracts.md "Recording directory").

Only the files' formats are used: these readers work on any directory laid out
as the contract says, whoever wrote it. Each checks what it reads (:mod:`tdm.recording`; the
warnings and errors: docs/formats.md, "Reading a recording: warnings and errors").
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from tdm.detections import ReadStats
from tdm.recording import jsonl, manifest, ownship, scenario
from tdm.recording.ownship import OWNSHIP_FIELDS

__all__ = ["read_manifest", "read_jsonl", "read_ownship", "read_truth", "read_scenario", "OWNSHIP_FIELDS"]


def read_manifest(recording: Path) -> dict:
    """The recording's manifest.json as a dict, checked (:func:`tdm.recording.manifest.read_manifest`)."""
    return manifest.read_manifest(recording)


def read_jsonl(path: Path, stats: ReadStats | None = None) -> list[dict]:
    """All objects of a JSON-lines file; a bad line is an error naming its number (:mod:`tdm.recording.jsonl`)."""
    return jsonl.read_jsonl(path, stats)


def read_ownship(recording: Path, stats: ReadStats | None = None) -> dict[str, np.ndarray]:
    """ownship.jsonl as columns: (N,) float64 arrays named as the contract's fields, checked
    (:func:`tdm.recording.ownship.read_ownship`; with ``stats`` a cut last line is a counted warning)."""
    return ownship.read_ownship(recording, stats)


def read_truth(recording: Path) -> list[dict]:
    """truth.jsonl rows (only evaluation may use truth)."""
    return read_jsonl(Path(recording) / "truth.jsonl")


def read_scenario(recording: Path) -> dict:
    """The recording's resolved scenario.yaml (sensor mounts, own-ship size, TDM rate), the values the TDM
    uses checked (:func:`tdm.recording.scenario.read_scenario`)."""
    return scenario.read_scenario(recording)

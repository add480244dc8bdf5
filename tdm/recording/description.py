"""A recording's typed description (:class:`groundfloor.recording.RecordingDescription`), from checked files.

``manifest.json`` and ``scenario.yaml`` are read by their checked readers (:mod:`~tdm.recording.manifest`,
:mod:`~tdm.recording.scenario`: each defect a one-line :class:`tdm.errors.RecordingError`), then
typed by the recording contract both raysim and the TDM build on.
"""

from __future__ import annotations

from pathlib import Path

from groundfloor.recording import LidarDescription, RadarDescription, RecordingDescription
from tdm.recording.manifest import read_manifest
from tdm.recording.scenario import read_scenario

__all__ = ["describe", "LidarDescription", "RadarDescription", "RecordingDescription"]


def describe(recording: Path, manifest: dict | None = None, scenario: dict | None = None) -> RecordingDescription:
    """The recording's description; ``manifest`` and ``scenario`` when already read (else read and checked here)."""
    manifest = read_manifest(recording) if manifest is None else manifest
    scenario = read_scenario(recording) if scenario is None else scenario
    return RecordingDescription.from_dicts(manifest, scenario)

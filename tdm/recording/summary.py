"""``tdm info``: a recording checked file by file without running the TDM, and summarised.

Reads what ``tdm run`` reads, as far as it can be checked without decoding the sensor data:
``manifest.json``, ``scenario.yaml`` and ``ownship.jsonl`` in full; every sweep file's listing and
array headers (names, dtypes, shapes, lengths: :func:`tdm.recording.sweeps.read_sweep_layout`, no
array loaded); the PCAP's global header (whenever the file is there: ``tdm run`` reads it with
``--lidar-source pcap`` or without NPZ sweeps); that ``ais/ais.nmea`` is a readable file;
``land.geojson`` in full (:mod:`~tdm.recording.land`). The same
defects give the same errors and warnings as in ``tdm run``; defects only the data shows (a NaN in
a sweep, packets out of time, bad NMEA lines, sweeps out of order, an empty sweep) are left to
``tdm run``.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path

from groundfloor.recording import AIS_NMEA, LIDAR_PCAP
from tdm.detections import ReadStats
from tdm.pcap import check_pcap_header
from tdm.recording.files import directory_present, is_present, regular_file
from tdm.recording.land import read_land
from tdm.recording.manifest import read_manifest
from tdm.recording.npz import Unreadable
from tdm.recording.ownship import check_covers_run, read_ownship
from tdm.recording.scenario import read_scenario
from tdm.recording.sweep_files import list_sweeps
from tdm.recording.sweeps import SCHEMAS, read_sweep_layout, unreadable_warning

__all__ = ["RecordingSummary", "summarise"]


@dataclass
class RecordingSummary:
    """What ``tdm info`` found.

    Attributes
    ----------
    manifest : dict
    nav_samples : int
        Lines of ``ownship.jsonl`` read.
    nav_span_s : float
        Time of the last navigation sample, s.
    sweep_files : dict of str to int
        Per sensor with a sweeps directory, its numbered files (readable or not).
    pcap_bytes : int or None
        Size of ``lidar/hdl32e.pcap`` (None: absent).
    ais_lines : int or None
        Lines of ``ais/ais.nmea`` (None: absent).
    land_polygons : int or None
        Polygons of ``land.geojson`` (None: absent, no land).
    warnings : dict of str to int
        Counted warnings (keys as ``tdm run``'s).
    """

    manifest: dict
    nav_samples: int
    nav_span_s: float
    sweep_files: dict[str, int] = field(default_factory=dict)
    pcap_bytes: int | None = None
    ais_lines: int | None = None
    land_polygons: int | None = None
    warnings: dict[str, int] = field(default_factory=dict)

    def lines(self, recording: Path) -> list[str]:
        """The summary as printed by ``tdm info``."""
        m = self.manifest
        out = [f"{recording}: scenario {m.get('scenario')}, seed {m.get('seed')}, {m.get('duration_s')} s, "
               f"sensors {', '.join(m.get('sensors_rendered') or []) or 'none'}",
               f"  own ship: {self.nav_samples} navigation samples, {self.nav_span_s:.1f} s"]
        parts = [f"{sensor} {n} sweep files" for sensor, n in self.sweep_files.items()]
        if self.pcap_bytes is not None:
            parts.append(f"LiDAR PCAP {self.pcap_bytes / 1e6:.1f} MB")
        if self.ais_lines is not None:
            parts.append(f"AIS {self.ais_lines} lines")
        out.append(f"  sensor data: {', '.join(parts) or 'none'}")
        if self.land_polygons is not None:
            out.append(f"  land: {self.land_polygons} polygons (land.geojson, the TDM's land mask)")
        return out


def _check_sweeps(recording: Path, scenario: dict, stats: ReadStats) -> dict[str, int]:
    counts = {}
    radar = (scenario.get("sensors") or {}).get("radar") or {}
    expected = {"radar": {a: int(radar[a]) for a in ("spokes", "samples") if radar.get(a) is not None} or None}
    for sensor in ("lidar", "radar"):
        directory = recording / sensor / "sweeps"
        if not directory_present(directory):
            continue
        files = list_sweeps(directory, sensor, stats)
        for path in files:  # headers only: a few hundred bytes a file
            try:
                read_sweep_layout(path, SCHEMAS[sensor], expected.get(sensor))
            except Unreadable as exc:
                stats.count(unreadable_warning(sensor, exc.reason))
        counts[sensor] = len(files)
    return counts


def summarise(recording: Path) -> RecordingSummary:
    """Check a recording as the module docstring says and summarise it.

    Raises
    ------
    RecordingError
        The first defect that ``tdm run`` would refuse too (one line: file, place, what).
    """
    rec = Path(recording)
    stats = ReadStats()
    manifest = read_manifest(rec)
    scenario = read_scenario(rec)
    nav = read_ownship(rec, stats)
    check_covers_run(nav["t"], float(manifest["duration_s"]), rec)
    summary = RecordingSummary(manifest, int(nav["t"].shape[0]), float(nav["t"][-1]))
    summary.sweep_files = _check_sweeps(rec, scenario, stats)
    pcap = rec / LIDAR_PCAP
    if is_present(pcap):
        check_pcap_header(pcap)
        summary.pcap_bytes = os.stat(pcap).st_size
    ais = rec / AIS_NMEA
    if is_present(ais):
        regular_file(ais)
        with open(ais, "rb") as handle:  # in blocks: memory flat whatever the file's size
            summary.ais_lines = sum(block.count(b"\n") for block in iter(lambda: handle.read(1 << 20), b""))
    land = read_land(rec)  # read and checked in full, as tdm run and tdm evaluate read it
    summary.land_polygons = None if land is None else len(land.polygons)
    summary.warnings = dict(stats.warnings)
    return summary

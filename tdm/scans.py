"""The scan sources of ``tdm run``: every sensor's scans of a recording, in time order.

LiDAR sweeps come from the NPZ files or the Velodyne PCAP, radar sweeps from their NPZ files, AIS
reports from ``ais/ais.nmea``; :class:`DetectionStream` merges the front ends' detections
(:mod:`tdm.workers`) with the AIS reports into the one time-ordered stream the trackers consume.
"""

from __future__ import annotations

import heapq
from pathlib import Path
from typing import Iterator

from tdm.detections import ReadStats
from tdm.errors import RecordingError
from tdm.frames import OwnshipTrack
from tdm.frontend.ais import read_ais
from tdm.frontend.lidar import LidarFrontEndConfig
from tdm.frontend.radar import RadarFrontEndConfig
from tdm.io import read_manifest, read_ownship, read_scenario
from tdm.land import DETECTION_MARGIN_M, LandMask
from tdm.recording.files import directory_present, is_present, regular_file
from tdm.recording.land import read_land
from tdm.recording.manifest import start_time_unix_s as _start_time_unix_s
from tdm.recording.description import RecordingDescription, describe
from tdm.recording.sweep_files import list_sweeps, sweep_window_s
from tdm.run_config import TdmConfig
from tdm.workers import BATCH_SCANS, detections_in_time_order

__all__ = ["DetectionStream", "interleaved", "start_time_unix_s"]

#: Defaults of the scan periods when scenario.yaml does not state the rates: the HDL-32E's 10 Hz
#: (docs/reference.md section 2) and a marine radar's 24 rpm (docs/reference.md section 3 table).
DEFAULT_LIDAR_ROTATION_HZ = 10.0
DEFAULT_RADAR_RPM = 24.0
SECONDS_PER_MINUTE = 60.0

#: Per sensor: (iterator of front-end jobs in time order, scan period in s).
Jobs = dict[str, tuple[Iterator, float]]


def start_time_unix_s(manifest: dict, recording: Path) -> float:
    """UNIX time of the recording's start, s (:func:`tdm.recording.manifest.start_time_unix_s`)."""
    return _start_time_unix_s(manifest, recording)


def _lidar_jobs(rec: Path, lidar_source: str, manifest: dict, stats: ReadStats,
                sweep_files: dict[str, int]) -> Iterator | None:
    """The LiDAR's front-end jobs (sweep files, or sweeps of the PCAP), or None when it has none; how many sweep
    files it reads goes into ``sweep_files`` (not for the PCAP)."""
    lidar_dir, pcap = rec / "lidar" / "sweeps", rec / "lidar" / "hdl32e.pcap"
    source = lidar_source
    has_npz = directory_present(lidar_dir)  # a file where the directory belongs is an error
    if source == "auto":
        source = "npz" if has_npz else "pcap"
    if source == "npz" and has_npz:
        files = list_sweeps(lidar_dir, "lidar", stats)
        sweep_files["lidar"] = len(files)
        return (("lidar", p) for p in files)
    if source == "pcap" and is_present(pcap):
        from tdm.pcap import check_pcap_header, iter_pcap_sweeps

        check_pcap_header(pcap)
        sweeps = iter_pcap_sweeps(pcap, start_time_unix_s(manifest, rec), stats,
                                  window_s=sweep_window_s(float(manifest["duration_s"])))
        return (("lidar", s) for s in sweeps)
    if lidar_source != "auto":
        raise RecordingError(str(pcap if source == "pcap" else lidar_dir), "(file)", f"missing: --lidar-source {source}")
    return None


def _scan_jobs(recording: Path, config: TdmConfig, manifest: dict, description: RecordingDescription,
               stats: ReadStats, sweep_files: dict[str, int]) -> Jobs:
    """Per sensor: (iterator of front-end jobs in time order, scan period in s); how many sweep files each sensor
    read from files has goes into ``sweep_files``."""
    rec = Path(recording)
    jobs: Jobs = {}
    lidar_period_s = description.lidar.period_s or 1.0 / DEFAULT_LIDAR_ROTATION_HZ
    lidar = _lidar_jobs(rec, config.lidar_source, manifest, stats, sweep_files)
    if lidar is not None:
        jobs["lidar"] = (lidar, lidar_period_s)
    radar_dir = rec / "radar" / "sweeps"
    if directory_present(radar_dir):
        radar_period_s = description.radar.period_s or SECONDS_PER_MINUTE / DEFAULT_RADAR_RPM
        files = list_sweeps(radar_dir, "radar", stats)
        sweep_files["radar"] = len(files)
        jobs["radar"] = ((("radar", p) for p in files), radar_period_s)
    return jobs


def _sweep_limits(description: RecordingDescription) -> dict[str, tuple[tuple[float, float], dict[str, int] | None]]:
    """Per sensor: the times its sweeps may hold (s) and the axis lengths scenario.yaml states (radar)."""
    window_s = sweep_window_s(description.duration_s)
    radar = description.radar
    expected = {axis: n for axis, n in (("spokes", radar.spokes), ("samples", radar.samples)) if n is not None}
    return {"lidar": (window_s, None), "radar": (window_s, expected or None)}


def interleaved(jobs: Jobs) -> Iterator[tuple[str, object]]:
    """All sensors' jobs in the order of their scans' expected times (k-th scan at k periods)."""
    def keyed(name: str, it: Iterator, period_s: float) -> Iterator:
        for k, job in enumerate(it):
            yield k * period_s, name, job

    streams = [keyed(name, it, period) for name, (it, period) in jobs.items()]
    for _, _, job in heapq.merge(*streams, key=lambda item: (item[0], item[1])):
        yield job


class DetectionStream:
    """Every sensor's detections of a recording in time order: what the trackers consume.

    Also the input of benchmarks that run other trackers on the same detections.

    Parameters
    ----------
    recording : Path
    config : TdmConfig
    stats : ReadStats
        Collects counted warnings.

    Attributes
    ----------
    ownship : OwnshipTrack
    nav : dict of (M,) arrays
        ownship.jsonl columns.
    reports : list of AisReport
    static : dict of int to AisStatic
    land : tdm.recording.land.ChartLand or None
        The recording's land (``land.geojson``, :func:`tdm.recording.land.read_land`); the front
        ends' detections on it (within :data:`tdm.land.DETECTION_MARGIN_M`) are dropped.
    description : RecordingDescription
        The recording's typed description (:func:`tdm.recording.description.describe`): its
        duration, the sensors' periods, ranges and mounts, read once for the whole run.
    sweep_files : dict of str to int
        How many sweep files each sensor read from ``<sensor>/sweeps`` has (not the LiDAR read from its PCAP).
    """

    def __init__(self, recording: Path, config: TdmConfig, stats: ReadStats, manifest: dict | None = None,
                 scenario: dict | None = None):
        rec = Path(recording)
        manifest = manifest if manifest is not None else read_manifest(rec)
        scenario = scenario if scenario is not None else read_scenario(rec)
        self.config, self.stats = config, stats
        self.nav = read_ownship(rec, stats)
        self.ownship = OwnshipTrack(self.nav)
        self.description = describe(rec, manifest, scenario)
        lidar_cfg = LidarFrontEndConfig.from_scenario(scenario)
        radar_cfg = RadarFrontEndConfig.from_scenario(scenario)
        self.land = read_land(rec)
        detection_mask = None if self.land is None else LandMask(self.land, self.ownship.frame, DETECTION_MARGIN_M)
        self._initargs = (self.ownship, self.description.lidar.mount, lidar_cfg, self.description.radar.mount,
                          radar_cfg, _sweep_limits(self.description), detection_mask)
        self.sweep_files: dict[str, int] = {}
        self._jobs = _scan_jobs(rec, config, manifest, self.description, stats, self.sweep_files)
        self._chunk_scans = BATCH_SCANS
        ais_path = rec / "ais" / "ais.nmea"
        self.reports, self.static = [], {}
        has_ais = is_present(ais_path)
        if has_ais:
            regular_file(ais_path)  # a directory, a link loop, no permission: an error
            reports, self.static = read_ais(ais_path, self.ownship.frame, start_time_unix_s(manifest, rec), stats)
            self.reports = _reports_in_run(reports, float(manifest["duration_s"]), stats)
        if not self._jobs and not has_ais:
            raise RecordingError(str(rec), "(directory)", "holds no LiDAR, radar or AIS data to detect targets in")

    @property
    def scanned_sensors(self) -> tuple[str, ...]:
        """The sensors whose scans the stream reads (``lidar``, ``radar``), in its order."""
        return tuple(self._jobs)

    def follow(self, jobs: Jobs, ownship: OwnshipTrack | None = None) -> None:
        """Take the scans from ``jobs`` instead of the recording's files (live mode: scans that arrive while
        the stream runs; per sensor an iterator of ``(sensor, sweep path)`` in time order and the scan period, s),
        and the own ship from ``ownship`` if given (a track that grows while the stream runs; the front ends
        must then run in this process, ``workers`` 0, to see it grow)."""
        self._jobs = dict(jobs)
        self._chunk_scans = 1  # each scan on its own as it arrives
        if ownship is not None:
            self.ownship = ownship
            self._initargs = (ownship,) + self._initargs[1:]

    def events(self) -> Iterator[tuple[float, str, object]]:
        """(time s, sensor, Detections or AisReport) in time order (a scan at its last point's time)."""
        longest_period_s = max((period for _, period in self._jobs.values()), default=0.0)
        scans = detections_in_time_order(interleaved(self._jobs), longest_period_s, self.config.workers,
                                         self._initargs, self.stats, self._chunk_scans)
        return heapq.merge(scans, ((r.time_s, "ais", r) for r in self.reports), key=lambda item: item[0])


def _reports_in_run(reports: list, duration_s: float, stats: ReadStats) -> list:
    """The AIS reports whose times lie within the run (+- the sweeps' margin); the others counted and dropped.

    A receiver clock that jumps (or a TAG block edited by hand) gives times that belong to no epoch.
    """
    low, high = sweep_window_s(duration_s)
    kept = [r for r in reports if low <= r.time_s <= high]
    if len(kept) < len(reports):
        stats.count("ais/nmea: message with a time outside the run skipped", len(reports) - len(kept))
    return kept

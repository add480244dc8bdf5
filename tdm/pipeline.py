"""``tdm run``: a recording in, detected targets out.

Scans are read in time order from every sensor the recording holds (LiDAR sweeps from the
NPZ files or the Velodyne PCAP, radar sweeps, AIS lines), turned into detections by the
front ends (in a pool of worker processes: scans are independent), and fed to one tracker per
sensor in the order they end. At every output epoch ``k / update_rate_hz`` the fuser takes the
confirmed tracks of all sensors and the detected targets are written.

Problems that leave the rest readable (a missing or unreadable sweep file, a cut PCAP, bad
NMEA lines) are counted as warnings; a recording with nothing to read is an error.
"""

from __future__ import annotations

import heapq
from collections import deque
import re
import shutil
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field
from datetime import datetime
from pathlib import Path
from typing import Iterator

import numpy as np

from tdm.detections import Detections, ReadStats
from tdm.errors import RecordingError
from tdm.frames import Mount, OwnshipTrack
from tdm.frontend.ais import read_ais
from tdm.frontend.lidar import LidarFrontEndConfig, lidar_detections
from tdm.frontend.radar import RadarFrontEndConfig, radar_detections
from tdm.fusion import Fuser, FusionConfig
from tdm.io import read_manifest, read_ownship, read_scenario
from tdm.messages import jsonl_writer, target_record
from tdm.tracker import AisTracker, AisTrackerConfig, PositionTracker, TrackerConfig

LIDAR_SOURCES = ("auto", "npz", "pcap")
FUSION_RULES = ("simple", "ci")


@dataclass(frozen=True)
class TdmConfig:
    """Everything ``tdm run`` can be told (defaults from the recording's scenario.yaml).

    Attributes
    ----------
    update_rate_hz : float
        Output rate of detected targets (scenario ``tdm.update_rate_hz``; thesis TDM_update_rate_Hz).
    fusion : str
        ``simple`` (thesis eq. 3.2) or ``ci`` (covariance intersection).
    lidar_source : str
        ``npz`` sweeps, ``pcap``, or ``auto`` (NPZ when present, else the PCAP).
    workers : int
        Front-end worker processes (0: in this process).
    """

    update_rate_hz: float = 1.0
    fusion: str = "simple"
    lidar_source: str = "auto"
    workers: int = 2
    lidar_tracker: TrackerConfig = field(default_factory=lambda: TrackerConfig(
        confirm_m=6, confirm_n=10, coast_s=2.0, position_floor_m2=1.0, max_range_m=100.0))
    radar_tracker: TrackerConfig = field(default_factory=lambda: TrackerConfig(
        confirm_m=3, confirm_n=4, coast_s=8.0, position_floor_m2=4.0, max_range_m=1852.0,
        merge_distance_m=25.0, cross_section_sigma_m2=300.0,
        # a radar track's second plot is looked for within 4 m/s (8 kn) of standing still, at most
        # 15 m/s (29 kn): sea-clutter pairs far apart no longer start tracks (busy_open_sea, 300 s:
        # 4.2 -> 3.2 false targets a minute)
        init_speed_sigma_mps=4.0, max_speed_mps=15.0,
        # plots barely over the clutter count half a hit, plots well over it 1.5 (TrackerConfig; busy_open_sea,
        # 300 s: 3.2 -> 0.8 false targets a minute, and strong new objects confirm a scan sooner)
        weak_below_db=13.0, strong_from_db=15.0,
        # a plot narrower than the beam paints is a sea spike, however strong: a weak hit (Detections.beam_fill;
        # busy_open_sea seeds 7-11, 300 s: 0.6-1.0 -> 0-0.4 false targets a minute)
        min_beam_fill=0.5))
    ais_tracker: AisTrackerConfig = field(default_factory=AisTrackerConfig)
    fusion_config: FusionConfig = field(default_factory=FusionConfig)

    @classmethod
    def for_recording(cls, recording: Path, **changes) -> "TdmConfig":
        """The defaults with ``update_rate_hz`` from the recording's scenario.yaml, then ``changes``."""
        rate = float((read_scenario(recording).get("tdm") or {}).get("update_rate_hz", 1.0))
        return cls(**{"update_rate_hz": rate, **changes})


@dataclass
class RunResult:
    """What ``run_tdm`` wrote and met."""

    out_dir: Path
    n_epochs: int
    n_target_lines: int
    n_targets: int
    scans: dict[str, int]
    warnings: dict[str, int]


def start_time_unix_s(manifest: dict, recording: Path) -> float:
    text = manifest.get("start_time")
    try:
        return datetime.fromisoformat(str(text).replace("Z", "+00:00")).timestamp()
    except ValueError:
        raise RecordingError(str(Path(recording) / "manifest.json"), "start_time", f"not an ISO 8601 time: {text!r}") from None


# ---- scan sources ----------------------------------------------------------------------------

_NUMBERED = re.compile(r"^(\d+)\.npz$")


def _numbered_files(directory: Path, what: str, stats: ReadStats) -> list[Path]:
    files = sorted(p for p in directory.glob("*.npz") if _NUMBERED.match(p.name))
    numbers = [int(_NUMBERED.match(p.name).group(1)) for p in files]
    if numbers:
        missing = (numbers[-1] - numbers[0] + 1) - len(numbers)
        if missing:
            stats.count(f"{what}: sweep files missing from the numbering", missing)
    return files


def _load_npz(path: Path, fields: tuple[str, ...]) -> dict | str:
    try:
        with np.load(path) as data:
            return {k: data[k] for k in fields}
    except Exception as exc:  # a cut or corrupt file: counted, skipped
        return f"{type(exc).__name__}"


LIDAR_FIELDS = ("x", "y", "z", "ring", "time")  # what the LiDAR front end reads
RADAR_FIELDS = ("echo", "azimuth_deg", "heading_deg", "time", "range_m")

_WORKER: dict = {}


def _init_worker(track, lidar_mount, lidar_cfg, radar_mount, radar_cfg) -> None:
    _WORKER.update(track=track, lidar=(lidar_mount, lidar_cfg), radar=(radar_mount, radar_cfg))


def _frontend(job: tuple[str, object]) -> tuple[str, float, Detections | None, str | None]:
    """Detections of one scan: (sensor, end time s, detections or None, problem or None)."""
    sensor, source = job
    if isinstance(source, (str, Path)):
        sweep = _load_npz(Path(source), LIDAR_FIELDS if sensor == "lidar" else RADAR_FIELDS)
        if isinstance(sweep, str):
            return sensor, -1.0, None, f"{sensor}/sweeps: unreadable sweep files ({sweep})"
    else:
        sweep = source
    times = sweep["time"]
    if times.size == 0:
        return sensor, -1.0, None, f"{sensor}: empty sweeps"
    mount, cfg = _WORKER[sensor]
    func = lidar_detections if sensor == "lidar" else radar_detections
    return sensor, float(np.max(times)), func(sweep, _WORKER["track"], mount, cfg), None


#: Scans per worker task: enough to hide the inter-process overhead (about a millisecond a task).
BATCH_SCANS = 16


def _frontend_batch(batch: list) -> list:
    return [_frontend(job) for job in batch]


def _scan_jobs(recording: Path, config: TdmConfig, manifest: dict, scenario: dict,
               stats: ReadStats) -> dict[str, tuple[Iterator, float]]:
    """Per sensor: (iterator of front-end jobs in time order, scan period in s)."""
    rec = Path(recording)
    sensors = scenario.get("sensors") or {}
    jobs: dict[str, tuple[Iterator, float]] = {}
    lidar_dir, pcap = rec / "lidar" / "sweeps", rec / "lidar" / "hdl32e.pcap"
    lidar_period_s = 1.0 / float((sensors.get("lidar") or {}).get("rotation_hz", 10.0))
    source = config.lidar_source
    if source == "auto":
        source = "npz" if lidar_dir.is_dir() else "pcap"
    if source == "npz" and lidar_dir.is_dir():
        jobs["lidar"] = ((("lidar", p) for p in _numbered_files(lidar_dir, "lidar", stats)), lidar_period_s)
    elif source == "pcap" and pcap.is_file():
        from tdm.pcap import iter_pcap_sweeps

        sweeps = iter_pcap_sweeps(pcap, start_time_unix_s(manifest, rec), stats)
        jobs["lidar"] = ((("lidar", s) for s in sweeps), lidar_period_s)
    elif config.lidar_source != "auto":
        raise RecordingError(str(pcap if source == "pcap" else lidar_dir), "(file)", f"missing: --lidar-source {source}")
    radar_dir = rec / "radar" / "sweeps"
    if radar_dir.is_dir():
        radar_period_s = 60.0 / float((sensors.get("radar") or {}).get("rpm", 24.0))
        jobs["radar"] = ((("radar", p) for p in _numbered_files(radar_dir, "radar", stats)), radar_period_s)
    return jobs


def _interleaved(jobs: dict[str, tuple[Iterator, float]]) -> Iterator[tuple[str, object]]:
    """All sensors' jobs in the order of their scans' expected times (k-th scan at k periods)."""
    def keyed(name: str, it: Iterator, period_s: float) -> Iterator:
        for k, job in enumerate(it):
            yield k * period_s, name, job

    streams = [keyed(name, it, period) for name, (it, period) in jobs.items()]
    for _, _, job in heapq.merge(*streams, key=lambda item: (item[0], item[1])):
        yield job


def _scans(jobs: dict[str, tuple[Iterator, float]], workers: int, initargs,
           stats: ReadStats) -> Iterator[tuple[float, str, object]]:
    """(end time, sensor, Detections) of every scan of every sensor, in time order.

    Jobs go to the workers in expected-time order with a bounded number in flight (memory
    stays flat, and the trackers start at once); results come back in submission order and
    pass a reorder buffer one scan period long, which puts them in exact end-time order.
    """
    lag_s = max((period for _, period in jobs.values()), default=0.0) + 0.5
    if workers > 0:
        executor = ProcessPoolExecutor(max_workers=workers, initializer=_init_worker, initargs=initargs)
    else:
        executor = None
        _init_worker(*initargs)
    in_flight = 3 * max(workers, 1)  # batches submitted ahead
    buffer: list = []
    seq = 0

    def results() -> Iterator:
        if executor is None:
            yield from map(_frontend, _interleaved(jobs))
            return
        pending: deque = deque()
        batch: list = []
        for job in _interleaved(jobs):
            batch.append(job)
            if len(batch) == BATCH_SCANS:
                pending.append(executor.submit(_frontend_batch, batch))
                batch = []
            if len(pending) > in_flight:
                yield from pending.popleft().result()
        if batch:
            pending.append(executor.submit(_frontend_batch, batch))
        while pending:
            yield from pending.popleft().result()

    last = -np.inf
    try:
        for sensor, t_end, dets, problem in results():
            if problem:
                stats.count(problem)
                continue
            heapq.heappush(buffer, (t_end, seq, sensor, dets))
            seq += 1
            while buffer and buffer[0][0] < t_end - lag_s:
                t, _, name, item = heapq.heappop(buffer)
                if t < last:
                    raise RuntimeError(f"scans out of order: {name} at {t} s after {last} s")
                last = t
                yield t, name, item
        while buffer:
            t, _, name, item = heapq.heappop(buffer)
            yield t, name, item
    finally:
        if executor:
            executor.shutdown(cancel_futures=True)


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
    """

    def __init__(self, recording: Path, config: TdmConfig, stats: ReadStats, manifest: dict | None = None,
                 scenario: dict | None = None):
        rec = Path(recording)
        manifest = manifest if manifest is not None else read_manifest(rec)
        scenario = scenario if scenario is not None else read_scenario(rec)
        self.config, self.stats = config, stats
        self.nav = read_ownship(rec)
        self.ownship = OwnshipTrack(self.nav)
        sensors_cfg = scenario.get("sensors") or {}
        lidar_cfg = LidarFrontEndConfig.from_scenario(scenario)
        radar_cfg = RadarFrontEndConfig.from_scenario(scenario)
        lidar_mount = Mount.from_dict((sensors_cfg.get("lidar") or {}).get("mount"))
        radar_mount = Mount.from_dict((sensors_cfg.get("radar") or {}).get("mount"))
        self._initargs = (self.ownship, lidar_mount, lidar_cfg, radar_mount, radar_cfg)
        self._jobs = _scan_jobs(rec, config, manifest, scenario, stats)
        ais_path = rec / "ais" / "ais.nmea"
        self.reports, self.static = [], {}
        if ais_path.is_file():
            self.reports, self.static = read_ais(ais_path, self.ownship.frame, start_time_unix_s(manifest, rec), stats)
        if not self._jobs and not ais_path.is_file():
            raise RecordingError(str(rec), "(directory)", "holds no LiDAR, radar or AIS data to detect targets in")

    def events(self) -> Iterator[tuple[float, str, object]]:
        """(time s, sensor, Detections or AisReport) in time order (a scan at its last point's time)."""
        return heapq.merge(_scans(self._jobs, self.config.workers, self._initargs, self.stats),
                           ((r.time_s, "ais", r) for r in self.reports), key=lambda item: item[0])


# ---- the run ---------------------------------------------------------------------------------

def run_tdm(recording: Path, out_dir: Path | None = None, config: TdmConfig | None = None,
            progress: bool = False) -> RunResult:
    """Run the TDM on a recording and write ``detected_targets.jsonl`` and ``sensor_tracks.jsonl``.

    Parameters
    ----------
    recording : Path
        A recording directory (docs/contracts.md).
    out_dir : Path, optional
        Where to write; default ``RECORDING/tdm``.
    config : TdmConfig, optional
        Default: :class:`TdmConfig` with ``update_rate_hz`` from the recording's scenario.
    progress : bool
        Show a progress bar (tqdm) on stderr.
    """
    rec = Path(recording)
    manifest = read_manifest(rec)
    scenario = read_scenario(rec)
    config = config if config is not None else TdmConfig.for_recording(rec)
    if config.update_rate_hz <= 0:
        raise RecordingError(str(rec / "scenario.yaml"), "tdm.update_rate_hz", "must be > 0")
    out = Path(out_dir) if out_dir is not None else rec / "tdm"
    stats = ReadStats()
    stream = DetectionStream(rec, config, stats, manifest=manifest, scenario=scenario)
    track, reports = stream.ownship, stream.reports
    nav = stream.nav
    sensors_cfg = scenario.get("sensors") or {}
    lidar_tcfg = _with_range(config.lidar_tracker, (sensors_cfg.get("lidar") or {}).get("range_max_m"))
    radar_tcfg = _with_range(config.radar_tracker, (sensors_cfg.get("radar") or {}).get("range_m"))

    duration_s = float(manifest.get("duration_s") or nav["t"][-1])
    epochs = np.arange(1, int(np.floor(duration_s * config.update_rate_hz + 1e-9)) + 1) / config.update_rate_hz
    trackers = {"lidar": PositionTracker("lidar", lidar_tcfg), "radar": PositionTracker("radar", radar_tcfg)}
    ais = AisTracker(config.ais_tracker)
    ais.set_static(stream.static)
    fuser = Fuser(FusionConfig(**{**config.fusion_config.__dict__, "rule": config.fusion}))
    fuser.lengths_by_mmsi = {m: s.length_m for m, s in stream.static.items() if np.isfinite(s.length_m)}
    scans = {"lidar": 0, "radar": 0, "ais": len(reports)}
    n_lines = 0
    target_ids: set[int] = set()
    events = stream.events()
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=len(epochs), desc="tdm", unit="epoch", leave=False)
    created = not out.exists()
    try:
        with jsonl_writer(out / "detected_targets.jsonl") as write_target, \
                jsonl_writer(out / "sensor_tracks.jsonl") as write_track:
            k = 0

            def emit(t_out: float) -> None:
                nonlocal n_lines
                ais.expire(t_out)
                by_sensor = {s: tr.confirmed_tracks() for s, tr in trackers.items()}
                by_sensor["ais"] = ais.confirmed_tracks()
                for estimate in fuser.step(t_out, by_sensor):
                    tgt = estimate.target
                    write_target(target_record(t_out, tgt.target_id, tgt.descriptor, estimate.x, estimate.p,
                                               estimate.sources, track.frame, tgt.mmsi))
                    target_ids.add(tgt.target_id)
                    n_lines += 1
                descriptors = {(s, i): t.descriptor for t in fuser.targets for s, i in t.members.items()}
                for sensor, tracks in by_sensor.items():
                    for tr in tracks:
                        x, p = tr.predicted(t_out)
                        write_track(target_record(t_out, tr.track_id, descriptors.get((sensor, tr.track_id), "unknown"),
                                                  x, p, [sensor], track.frame, tr.mmsi, sensor=sensor))
                if bar is not None:
                    bar.update(1)

            for t_end, sensor, payload in events:
                while k < len(epochs) and t_end > epochs[k]:
                    emit(float(epochs[k]))
                    k += 1
                scans[sensor] += sensor != "ais"
                if sensor == "ais":
                    ais.process(payload)
                else:
                    own = track.position_m(np.array([t_end]))[0, :2]
                    trackers[sensor].process(payload, own)
            while k < len(epochs):
                emit(float(epochs[k]))
                k += 1
    except BaseException:
        if created:
            shutil.rmtree(out, ignore_errors=True)
        raise
    finally:
        if bar is not None:
            bar.close()
    return RunResult(out, len(epochs), n_lines, len(target_ids), scans, dict(stats.warnings))


def _with_range(cfg: TrackerConfig, range_m) -> TrackerConfig:
    if range_m is None:
        return cfg
    from dataclasses import replace

    return replace(cfg, max_range_m=float(range_m))

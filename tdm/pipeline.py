"""``tdm run``: a recording in, detected targets out.

Scans are read in time order from every sensor the recording holds (LiDAR sweeps from the
NPZ files or the Velodyne PCAP, radar sweeps, AIS lines), turned into detections by the
front ends (in a pool of worker processes: scans are independent), and fed to one tracker per
sensor in the order they end. At every output epoch ``k / update_rate_hz`` the fuser takes the
confirmed tracks of all sensors and the detected targets are written.

Every file is read through :mod:`tdm.recording` (docs/formats.md, "Reading a recording: warnings
and errors"). Problems a real logger leaves and that leave the rest readable (a missing or
unreadable sweep file, a cut PCAP, bad NMEA lines, a cut last line of ownship.jsonl) are counted as
warnings; anything else that breaks the format (a wrong dtype, shape or length, a value out of
bounds, sweeps out of order) and a recording with nothing to read are errors, raised before any
output file is renamed into place.
"""

from __future__ import annotations

import heapq
from collections import deque
import shutil
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field
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
from tdm.recording.files import directory_present, is_present, regular_file
from tdm.recording.manifest import start_time_unix_s as _start_time_unix_s
from tdm.recording.npz import Unreadable
from tdm.recording.scenario import MAX_UPDATE_RATE_HZ
from tdm.recording.sweep_files import SweepOrder, list_sweeps, sweep_window_s
from tdm.recording.sweeps import SCHEMAS, read_sweep, unreadable_warning
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
    """UNIX time of the recording's start, s (:func:`tdm.recording.manifest.start_time_unix_s`)."""
    return _start_time_unix_s(manifest, recording)


# ---- scan sources ----------------------------------------------------------------------------

LIDAR_FIELDS = ("x", "y", "z", "ring", "time")  # what the LiDAR front end reads
RADAR_FIELDS = ("echo", "azimuth_deg", "heading_deg", "time", "range_m")

_WORKER: dict = {}


def _init_worker(track, lidar_mount, lidar_cfg, radar_mount, radar_cfg, limits=None) -> None:
    _WORKER.update(track=track, lidar=(lidar_mount, lidar_cfg), radar=(radar_mount, radar_cfg),
                   limits=limits or {})


def _read_sweep_file(sensor: str, path: Path) -> dict | str:
    """A sweep file's arrays, checked (:func:`tdm.recording.sweeps.read_sweep`), or the reason it is unreadable."""
    window_s, expected = _WORKER["limits"].get(sensor, ((-np.inf, np.inf), None))
    try:
        return read_sweep(path, SCHEMAS[sensor], LIDAR_FIELDS if sensor == "lidar" else RADAR_FIELDS, window_s,
                          expected)
    except Unreadable as exc:  # zero bytes, cut short, not a zip: counted, skipped
        return exc.reason


def _frontend(job: tuple[str, object]) -> tuple[str, float, float, Detections | None, str | None, Path | None]:
    """Detections of one scan: (sensor, start and end time s, detections or None, problem or None, file or None).

    A sweep file that breaks the format raises :class:`tdm.errors.RecordingError` (also from a worker).
    """
    sensor, source = job
    path = Path(source) if isinstance(source, (str, Path)) else None
    if path is not None:
        sweep = _read_sweep_file(sensor, path)
        if isinstance(sweep, str):
            return sensor, -1.0, -1.0, None, unreadable_warning(sensor, sweep), path
    else:
        sweep = source
    times = sweep["time"]
    if times.size == 0:
        return sensor, -1.0, -1.0, None, f"{sensor}: empty sweeps", path
    mount, cfg = _WORKER[sensor]
    func = lidar_detections if sensor == "lidar" else radar_detections
    dets = func(sweep, _WORKER["track"], mount, cfg)
    return sensor, float(np.min(times)), float(np.max(times)), dets, None, path


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
    has_npz = directory_present(lidar_dir)  # a file where the directory belongs is an error
    if source == "auto":
        source = "npz" if has_npz else "pcap"
    if source == "npz" and has_npz:
        jobs["lidar"] = ((("lidar", p) for p in list_sweeps(lidar_dir, "lidar", stats)), lidar_period_s)
    elif source == "pcap" and is_present(pcap):
        from tdm.pcap import check_pcap_header, iter_pcap_sweeps

        check_pcap_header(pcap)
        sweeps = iter_pcap_sweeps(pcap, start_time_unix_s(manifest, rec), stats,
                                  window_s=sweep_window_s(float(manifest["duration_s"])))
        jobs["lidar"] = ((("lidar", s) for s in sweeps), lidar_period_s)
    elif config.lidar_source != "auto":
        raise RecordingError(str(pcap if source == "pcap" else lidar_dir), "(file)", f"missing: --lidar-source {source}")
    radar_dir = rec / "radar" / "sweeps"
    if directory_present(radar_dir):
        radar_period_s = 60.0 / float((sensors.get("radar") or {}).get("rpm", 24.0))
        jobs["radar"] = ((("radar", p) for p in list_sweeps(radar_dir, "radar", stats)), radar_period_s)
    return jobs


def _sweep_limits(manifest: dict, scenario: dict) -> dict[str, tuple[tuple[float, float], dict[str, int] | None]]:
    """Per sensor: the times its sweeps may hold (s) and the axis lengths scenario.yaml states (radar)."""
    window_s = sweep_window_s(float(manifest["duration_s"]))
    radar = (scenario.get("sensors") or {}).get("radar") or {}
    expected = {axis: int(radar[axis]) for axis in ("spokes", "samples") if radar.get(axis) is not None}
    return {"lidar": (window_s, None), "radar": (window_s, expected or None)}


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
    order = SweepOrder()
    try:
        for sensor, t_start, t_end, dets, problem, path in results():
            if problem:
                stats.count(problem)
                continue
            if path is not None:  # sweep files renamed out of order or duplicated (a PCAP's are in order)
                order.check(sensor, path, t_start, t_end)
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
        self.nav = read_ownship(rec, stats)
        self.ownship = OwnshipTrack(self.nav)
        sensors_cfg = scenario.get("sensors") or {}
        lidar_cfg = LidarFrontEndConfig.from_scenario(scenario)
        radar_cfg = RadarFrontEndConfig.from_scenario(scenario)
        lidar_mount = Mount.from_dict((sensors_cfg.get("lidar") or {}).get("mount"))
        radar_mount = Mount.from_dict((sensors_cfg.get("radar") or {}).get("mount"))
        self._initargs = (self.ownship, lidar_mount, lidar_cfg, radar_mount, radar_cfg,
                          _sweep_limits(manifest, scenario))
        self._jobs = _scan_jobs(rec, config, manifest, scenario, stats)
        ais_path = rec / "ais" / "ais.nmea"
        self.reports, self.static = [], {}
        has_ais = is_present(ais_path)
        if has_ais:
            regular_file(ais_path)  # a directory, a link loop, no permission: an error
            reports, self.static = read_ais(ais_path, self.ownship.frame, start_time_unix_s(manifest, rec), stats)
            self.reports = _reports_in_run(reports, float(manifest["duration_s"]), stats)
        if not self._jobs and not has_ais:
            raise RecordingError(str(rec), "(directory)", "holds no LiDAR, radar or AIS data to detect targets in")

    def events(self) -> Iterator[tuple[float, str, object]]:
        """(time s, sensor, Detections or AisReport) in time order (a scan at its last point's time)."""
        return heapq.merge(_scans(self._jobs, self.config.workers, self._initargs, self.stats),
                           ((r.time_s, "ais", r) for r in self.reports), key=lambda item: item[0])


def _reports_in_run(reports: list, duration_s: float, stats: ReadStats) -> list:
    """The AIS reports whose times lie within the run (+- the sweeps' margin); the others counted and dropped.

    A receiver clock that jumps (or a TAG block edited by hand) gives times that belong to no epoch.
    """
    low, high = sweep_window_s(duration_s)
    kept = [r for r in reports if low <= r.time_s <= high]
    if len(kept) < len(reports):
        stats.count("ais/nmea: message with a time outside the run skipped", len(reports) - len(kept))
    return kept


# ---- the run ---------------------------------------------------------------------------------


class _EpochTimes:
    """The output epochs ``k / rate_hz``, k = 1..n, s, made on demand: no array sized by the recording's numbers."""

    def __init__(self, n: int, rate_hz: float):
        self.n, self.rate_hz = int(n), float(rate_hz)

    def __len__(self) -> int:
        return self.n

    def __getitem__(self, k: int) -> float:
        return (k + 1) / self.rate_hz  # as np.arange(1, n + 1) / rate_hz, element by element

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
    if not 0 < config.update_rate_hz <= MAX_UPDATE_RATE_HZ:  # NaN too
        raise RecordingError(str(rec / "scenario.yaml"), "tdm.update_rate_hz",
                             f"{config.update_rate_hz!r} must be > 0 and at most {MAX_UPDATE_RATE_HZ:g} Hz")
    out = Path(out_dir) if out_dir is not None else rec / "tdm"
    stats = ReadStats()
    stream = DetectionStream(rec, config, stats, manifest=manifest, scenario=scenario)
    track, reports = stream.ownship, stream.reports
    nav = stream.nav
    sensors_cfg = scenario.get("sensors") or {}
    lidar_tcfg = _with_range(config.lidar_tracker, (sensors_cfg.get("lidar") or {}).get("range_max_m"))
    radar_tcfg = _with_range(config.radar_tracker, (sensors_cfg.get("radar") or {}).get("range_m"))

    duration_s = float(manifest.get("duration_s") or nav["t"][-1])
    epochs = _EpochTimes(int(np.floor(duration_s * config.update_rate_hz + 1e-9)), config.update_rate_hz)
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

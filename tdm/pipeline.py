"""``tdm run``: a recording in, detected targets out.

Scans are read in time order from every sensor the recording holds (LiDAR sweeps from the
NPZ files or the Velodyne PCAP, radar sweeps, AIS lines), turned into detections by the
front ends (in a pool of worker processes: scans are independent), and fed to one tracker per
sensor in the order they end. At every output epoch ``k / update_rate_hz`` the fuser takes the
confirmed tracks of all sensors and the detected targets are written.

The recording's land (``land.geojson``) is the TDM's chart (:mod:`tdm.land`): detections on it are
dropped in the front ends' workers, and a target or sensor track whose estimate lies on it at an
output epoch is not written at that epoch (its track goes on).

Every file is read through :mod:`tdm.recording` (docs/formats.md, "Reading a recording: warnings
and errors"). Problems a real logger leaves and that leave the rest readable (a missing or
unreadable sweep file, a cut PCAP, bad NMEA lines, a cut last line of ownship.jsonl) are counted as
warnings; anything else that breaks the format (a wrong dtype, shape or length, a value out of
bounds, sweeps out of order) and a recording with nothing to read are errors, raised before any
output file is renamed into place.

The scan sources are :mod:`tdm.scans` (:class:`DetectionStream`), the front ends' worker pool
:mod:`tdm.workers`; this module holds the run: its settings, the trackers and the fuser, the epochs
and the output files.
"""

from __future__ import annotations

import shutil
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Callable, Iterable, Iterator

import numpy as np

from tdm import ekf
from tdm.detections import ReadStats
from tdm.errors import RecordingError
from tdm.fusion import Fuser, FusionConfig
from tdm.fusion_face import sensor_report
from tdm.io import read_manifest, read_scenario
from tdm.land import LandMask
from tdm.messages import jsonl_writer, target_records
from tdm.recording.ownship import check_covers_run
from tdm.recording.scenario import MAX_UPDATE_RATE_HZ
from tdm.run_config import FUSION_RULES, LIDAR_SOURCES, TdmConfig
from tdm.scans import DetectionStream, start_time_unix_s
from tdm.ais_tracker import AisTracker
from tdm.tracker import PositionTracker, TrackerConfig
from tdm.workers import BATCH_SCANS, LIDAR_FIELDS, RADAR_FIELDS

__all__ = ["BATCH_SCANS", "DetectionStream", "FUSION_RULES", "LIDAR_FIELDS", "LIDAR_SOURCES", "RADAR_FIELDS",
           "RunResult", "TdmConfig", "run_tdm", "start_time_unix_s", "targets_by_epoch"]

#: Tolerance of the epoch count ``floor(duration x rate)``: a product that falls a rounding error
#: short of a whole number still counts its last epoch.
_EPOCH_COUNT_TOLERANCE = 1e-9


@dataclass
class RunResult:
    """What ``run_tdm`` wrote and met."""

    out_dir: Path
    n_epochs: int
    n_target_lines: int
    n_targets: int
    scans: dict[str, int]
    warnings: dict[str, int]


# ---- the run ---------------------------------------------------------------------------------


class _EpochTimes:
    """The output epochs ``k / rate_hz``, k = 1..n, s, made on demand: no array sized by the recording's numbers."""

    def __init__(self, n: int, rate_hz: float):
        self.n, self.rate_hz = int(n), float(rate_hz)

    def __len__(self) -> int:
        return self.n

    def __getitem__(self, k: int) -> float:
        return (k + 1) / self.rate_hz  # as np.arange(1, n + 1) / rate_hz, element by element


class _Tracking:
    """A run's trackers (one per sensor) and fuser, and what they have written."""

    def __init__(self, stream: DetectionStream, config: TdmConfig):
        lidar_tcfg = _with_range(config.lidar_tracker, stream.description.lidar.range_max_m)
        radar_tcfg = _with_range(config.radar_tracker, stream.description.radar.range_m)
        if radar_tcfg.echo_hold_beam_deg is not None and stream.description.radar.beam_az_deg:
            radar_tcfg = replace(radar_tcfg, echo_hold_beam_deg=float(stream.description.radar.beam_az_deg))
        self.ownship = stream.ownship
        self.trackers = {"lidar": PositionTracker("lidar", lidar_tcfg), "radar": PositionTracker("radar", radar_tcfg)}
        self.ais = AisTracker(config.ais_tracker)
        self.ais.set_static(stream.static)
        self.fuser = Fuser(FusionConfig(**{**config.fusion_config.__dict__, "rule": config.fusion}))
        self.fuser.lengths_by_mmsi = {m: s.length_m for m, s in stream.static.items() if np.isfinite(s.length_m)}
        self.fuser.beams_by_mmsi = {m: s.beam_m for m, s in stream.static.items() if np.isfinite(s.beam_m)}
        self.scans = {"lidar": 0, "radar": 0, "ais": len(stream.reports)}
        self.n_lines = 0
        self.target_ids: set[int] = set()
        self.chart = None if stream.land is None else LandMask(stream.land, self.ownship.frame, 0.0)

    def on_land(self, x: np.ndarray) -> bool:
        """Whether the state ``x`` (:mod:`tdm.ekf`) lies on the chart's land (no margin): not reported."""
        return self.chart is not None and bool(self.chart.contains(x[ekf.E:ekf.E + 1], x[ekf.N:ekf.N + 1])[0])

    def process(self, t_end: float, sensor: str, payload) -> None:
        """One scan's detections (at its end time, s) or one AIS report into its tracker."""
        self.scans[sensor] += sensor != "ais"
        if sensor == "ais":
            self.ais.process(payload)
        else:
            own = self.ownship.position_m(np.array([t_end]))[0, :2]
            self.trackers[sensor].process(payload, own)

    def emit(self, t_out: float, write_target: Callable[[dict], None], write_track: Callable[[dict], None]) -> None:
        """The fused targets and every sensor's confirmed tracks at the epoch ``t_out`` (s), written."""
        frame = self.ownship.frame
        self.ais.expire(t_out)
        by_sensor = {s: tr.confirmed_tracks() for s, tr in self.trackers.items()}
        by_sensor["ais"] = self.ais.confirmed_tracks()
        own = self.ownship.position_m(np.array([t_out]))[0, :2]
        targets = []
        own_velocity = self.ownship.velocity_mps(np.array([t_out]))[0]
        for estimate in self.fuser.step(t_out, by_sensor, own, own_velocity):
            tgt = estimate.target
            if self.on_land(estimate.x):
                continue
            targets.append((tgt.target_id, tgt.descriptor, estimate.x, estimate.p, estimate.sources, tgt.mmsi, None))
            self.target_ids.add(tgt.target_id)
            self.n_lines += 1
        descriptors = {(s, i): t.descriptor for t in self.fuser.targets for s, i in t.members.items()}
        tracks = []
        for sensor, trs in by_sensor.items():
            for tr in trs:
                x, p = sensor_report(sensor, tr, t_out, own, self.fuser.config)
                if self.on_land(x):
                    continue
                tracks.append((tr.track_id, descriptors.get((sensor, tr.track_id), "unknown"), x, p, [sensor], tr.mmsi,
                               sensor))
        records = target_records(t_out, targets + tracks, frame)  # one lat/lon conversion for the epoch
        for record in records[:len(targets)]:
            write_target(record)
        for record in records[len(targets):]:
            write_track(record)


def _check_rendered_scans(rec: Path, manifest: dict, scanned: tuple[str, ...], sweep_files: dict[str, int]) -> None:
    """An error where the manifest lists the LiDAR or the radar as rendered and the recording holds none of its scans
    (a partial copy: the run would go on without that sensor and say nothing): no sweeps directory (nor, for the
    LiDAR, a PCAP), or one that holds no sweep file where manifest.json counts some (a run shorter than a radar
    revolution has none, rightly)."""
    counts = manifest.get("counts") if isinstance(manifest.get("counts"), dict) else {}
    for sensor in ("lidar", "radar"):
        if sensor not in (manifest.get("sensors_rendered") or []):
            continue
        if sensor not in scanned:
            also = " and no lidar/hdl32e.pcap" if sensor == "lidar" else ""
            raise RecordingError(str(rec / sensor / "sweeps"), "(directory)",
                                 f"missing{also}, though manifest.json lists {sensor} as rendered (a partial copy?)")
        expected = counts.get(f"{sensor}/sweeps")
        if sweep_files.get(sensor) == 0 and isinstance(expected, int) and expected > 0:
            raise RecordingError(str(rec / sensor / "sweeps"), "(directory)",
                                 f"holds none of the {expected} sweep files manifest.json counts (a partial copy?)")


def _checked_config(rec: Path, config: TdmConfig | None) -> TdmConfig:
    """``config``, or the recording's (:meth:`TdmConfig.for_recording`), with its output rate checked."""
    config = config if config is not None else TdmConfig.for_recording(rec)
    if not 0 < config.update_rate_hz <= MAX_UPDATE_RATE_HZ:  # NaN too
        raise RecordingError(str(rec / "scenario.yaml"), "tdm.update_rate_hz",
                             f"{config.update_rate_hz!r} must be > 0 and at most {MAX_UPDATE_RATE_HZ:g} Hz")
    return config


def _track_and_write(tracking: _Tracking, events: Iterable, epochs: _EpochTimes, out: Path, bar) -> None:
    """Every event into its tracker; at each epoch the fused targets and the tracks written to ``out``."""
    with jsonl_writer(out / "detected_targets.jsonl") as write_target, \
            jsonl_writer(out / "sensor_tracks.jsonl") as write_track:
        k = 0

        def emit(t_out: float) -> None:
            tracking.emit(t_out, write_target, write_track)
            if bar is not None:
                bar.update(1)

        for t_end, sensor, payload in events:
            while k < len(epochs) and t_end > epochs[k]:
                emit(float(epochs[k]))
                k += 1
            tracking.process(t_end, sensor, payload)
        while k < len(epochs):
            emit(float(epochs[k]))
            k += 1


def targets_by_epoch(stream: DetectionStream, config: TdmConfig, duration_s: float
                     ) -> Iterator[tuple[float, list[dict]]]:
    """The detected-target records of every output epoch ``k / update_rate_hz`` (s), as the events pass it.

    The same trackers and fuser as :func:`run_tdm`, yielding instead of writing: live mode's TDM, whose
    scans arrive while it runs (:meth:`DetectionStream.follow`).
    """
    tracking = _Tracking(stream, config)
    epochs = _EpochTimes(int(np.floor(duration_s * config.update_rate_hz + _EPOCH_COUNT_TOLERANCE)),
                         config.update_rate_hz)
    k = 0

    def emitted(t_out: float) -> tuple[float, list[dict]]:
        records: list[dict] = []
        tracking.emit(t_out, records.append, lambda record: None)
        return t_out, records

    for t_end, sensor, payload in stream.events():
        while k < len(epochs) and t_end > epochs[k]:
            yield emitted(float(epochs[k]))
            k += 1
        tracking.process(t_end, sensor, payload)
    while k < len(epochs):
        yield emitted(float(epochs[k]))
        k += 1


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
    config = _checked_config(rec, config)
    out = Path(out_dir) if out_dir is not None else rec / "tdm"
    stats = ReadStats()
    stream = DetectionStream(rec, config, stats, manifest=manifest, scenario=scenario)
    _check_rendered_scans(rec, manifest, stream.scanned_sensors, stream.sweep_files)
    duration_s = float(manifest.get("duration_s") or stream.nav["t"][-1])
    check_covers_run(stream.nav["t"], duration_s, rec)
    epochs = _EpochTimes(int(np.floor(duration_s * config.update_rate_hz + _EPOCH_COUNT_TOLERANCE)),
                         config.update_rate_hz)
    tracking = _Tracking(stream, config)
    events = stream.events()
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=len(epochs), desc="tdm", unit="epoch", leave=False)
    created = not out.exists()
    try:
        _track_and_write(tracking, events, epochs, out, bar)
    except BaseException:
        if created:
            shutil.rmtree(out, ignore_errors=True)
        raise
    finally:
        if bar is not None:
            bar.close()
    return RunResult(out, len(epochs), tracking.n_lines, len(tracking.target_ids), tracking.scans,
                     dict(stats.warnings))


def _with_range(cfg: TrackerConfig, range_m: float | None) -> TrackerConfig:
    if range_m is None:
        return cfg
    return replace(cfg, max_range_m=float(range_m))

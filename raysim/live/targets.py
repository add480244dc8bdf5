"""The TDM on the live data (``--targets-port``): detected targets as JSON lines, epoch by epoch.

The live session keeps a working recording directory: the parts known before the run (scenario,
truth, the own ship's navigation, AIS, land) are written at the start, and the LiDAR and radar
producers write each sweep there as they render it. The TDM (:func:`tdm.pipeline.targets_by_epoch`)
follows those sweeps as they appear and yields each epoch's detected targets, the same records as
``tdm/detected_targets.jsonl``; they are sent as soon as they exist, one JSON line a datagram, and
their lateness is the TDM's latency (an epoch's targets wait for the scans that end after it).
"""

from __future__ import annotations

import json
import threading
import time
from pathlib import Path
from typing import Iterator

import numpy as np

from raysim.live.streams import Batch
from raysim.scenario import Scenario, scenario_to_yaml, with_overrides

__all__ = ["prepare_working_recording", "target_batches", "follow_sweeps", "TDM_WORKERS"]

#: Front-end worker processes of the live TDM (one: the rendering and the send loop need the other core).
TDM_WORKERS = 1
#: How often a follower looks for the next sweep file, s.
FOLLOW_POLL_S = 0.02


def prepare_working_recording(scenario: Scenario, folder: Path) -> None:
    """Write what the TDM reads besides the sweeps: scenario.yaml, manifest, ownship, truth, AIS, land."""
    from raysim.render import render

    enabled = scenario.sensors.enabled_names()
    known = tuple(name for name in ("ais", "nav") if name in enabled) or ("nav",)
    render(with_overrides(scenario, sensors=known), folder, progress=False, derived=False)
    (folder / "scenario.yaml").write_text(scenario_to_yaml(scenario), encoding="utf-8")  # every sensor's settings
    for sensor in ("lidar", "radar"):
        if sensor in enabled:
            (folder / sensor / "sweeps").mkdir(parents=True, exist_ok=True)


def follow_sweeps(sensor: str, sweeps_dir: Path, done: threading.Event, stop: threading.Event
                  ) -> Iterator[tuple[str, Path]]:
    """``(sensor, path)`` of sweep 0, 1, ... as each file appears; ends when the producer is done and the
    next file does not exist, or on ``stop``."""
    k = 0
    while not stop.is_set():
        path = Path(sweeps_dir) / f"{k:06d}.npz"
        if path.exists():
            yield sensor, path
            k += 1
        elif done.is_set() and not path.exists():
            return
        else:
            time.sleep(FOLLOW_POLL_S)


def target_batches(folder: Path, done: dict[str, threading.Event], stop: threading.Event, fed_motion=None,
                   world_frame=None) -> Iterator[Batch]:
    """Each output epoch's detected targets (one JSON line a datagram) at the epoch's time, s.

    Parameters
    ----------
    folder : Path
        The working recording (:func:`prepare_working_recording`), its sweeps written while this runs.
    done : dict of str to threading.Event
        Per sensor with sweeps (``lidar``, ``radar``): set when its producer has written its last sweep.
    stop : threading.Event
    fed_motion : raysim.live.ownship_in.FedMotion, optional
        The fed own ship (``--ownship-in``): the TDM places its detections with it
        (:class:`raysim.live.fed_track.FedOwnshipTrack`, in world frame ``world_frame``), its front ends in
        this process so that they see the fixes as they arrive.
    """
    from tdm.detections import ReadStats
    from tdm.pipeline import DetectionStream, TdmConfig, targets_by_epoch
    from tdm.scans import DEFAULT_LIDAR_ROTATION_HZ, DEFAULT_RADAR_RPM, SECONDS_PER_MINUTE

    config = TdmConfig.for_recording(folder, workers=TDM_WORKERS if fed_motion is None else 0)
    stream = DetectionStream(folder, config, ReadStats())
    ownship = None
    if fed_motion is not None:
        from raysim.live.fed_track import FedOwnshipTrack

        ownship = FedOwnshipTrack(fed_motion, world_frame, stream.ownship.frame)
    periods = {"lidar": stream.description.lidar.period_s or 1.0 / DEFAULT_LIDAR_ROTATION_HZ,
               "radar": stream.description.radar.period_s or SECONDS_PER_MINUTE / DEFAULT_RADAR_RPM}
    stream.follow({sensor: (follow_sweeps(sensor, folder / sensor / "sweeps", event, stop), periods[sensor])
                   for sensor, event in done.items()}, ownship=ownship)
    for t_s, records in targets_by_epoch(stream, config, stream.description.duration_s):
        if stop.is_set():
            return
        if records:
            yield Batch(np.full(len(records), t_s), [(json.dumps(r, separators=(", ", ": ")) + "\n").encode("utf-8") for r in records])

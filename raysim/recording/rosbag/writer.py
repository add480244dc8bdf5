"""Write a recording's ROS 2 bag: every topic's stream merged into one log-time order.

Each topic family is a generator in time order (:mod:`.sensors`, :mod:`.ownship`,
:mod:`.objects`); :func:`heapq.merge` interleaves them by (log time, stream rank, sequence), so
the bag's messages are in log-time order across topics, ties broken by a fixed stream order
(same inputs, same bytes), and memory holds one pending message per stream.
"""

from __future__ import annotations

import heapq
from pathlib import Path
from typing import Iterable, Iterator

from raysim.recording.rosbag.msgs import BagMessage, typestore
from raysim.recording.rosbag.objects import target_streams, truth_streams
from raysim.recording.rosbag.ownship import ownship_streams
from raysim.recording.rosbag.qos import offered_qos
from raysim.recording.rosbag.sensors import ais_sentences, lidar_clouds, radar_sectors, static_transforms
from raysim.recording.rosbag.storage import bag_writer

__all__ = ["write_rosbag"]


def _ranked(rank: int, stream: Iterable[BagMessage]) -> Iterator[tuple[int, int, int, BagMessage]]:
    """(t_ns, rank, sequence, message): sort keys that never compare the messages themselves."""
    last = None
    for seq, message in enumerate(stream):
        if last is not None and message.t_ns < last:
            raise RuntimeError(f"bag stream of {message.topic} goes back in time at message {seq}")
        last = message.t_ns
        yield message.t_ns, rank, seq, message


def _streams(recording: Path, scenario, t0_ns: int) -> list[Iterable[BagMessage]]:
    """Every stream of the bag, in the order that breaks ties of equal log time."""
    from raysim.geodesy import LocalFrame

    def ns_of(t_s: float) -> int:
        return t0_ns + int(round(t_s * 1e9))

    frame = LocalFrame(scenario.origin.lat, scenario.origin.lon)
    return [static_transforms(scenario, t0_ns), ownship_streams(recording, scenario, t0_ns),
            lidar_clouds(recording, ns_of), radar_sectors(recording, ns_of), ais_sentences(recording, ns_of),
            truth_streams(recording, ns_of),
            target_streams(recording, frame, ns_of, 1.0 / scenario.tdm.update_rate_hz)]


def write_rosbag(recording: Path, scenario, out: Path | None = None) -> dict[str, int]:
    """Write ``recording/rosbag`` (or ``out``) from the recording's files.

    Parameters
    ----------
    recording : Path
        A (staged) recording directory holding the sensor files.
    scenario : raysim.scenario.Scenario
        Its resolved scenario (start time, origin, mounts, navigation errors, TDM rate).
    out : Path, optional
        The bag directory; default ``recording/rosbag``.

    Returns
    -------
    dict
        Messages written per topic.
    """
    recording = Path(recording)
    out = Path(out) if out is not None else recording / "rosbag"
    store = typestore()
    t0_ns = int(round(scenario.start_time.timestamp() * 1e9))
    counts: dict[str, int] = {}
    streams = [_ranked(rank, stream) for rank, stream in enumerate(_streams(recording, scenario, t0_ns))]
    with bag_writer(out) as writer:
        connections = {}
        for t_ns, _, _, message in heapq.merge(*streams):
            topic = message.topic
            if topic not in connections:
                connections[topic] = writer.add_connection(topic, message.msgtype, typestore=store,
                                                           offered_qos_profiles=offered_qos(topic))
            writer.write(connections[topic], t_ns, store.serialize_cdr(message.msg, message.msgtype))
            counts[topic] = counts.get(topic, 0) + 1
    return counts

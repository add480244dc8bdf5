"""Packet times of a Velodyne PCAP (``lidar/hdl32e.pcap``): inside the run and never going back.

A packet's time comes from its capture record (the hour) and its own timestamp (microseconds past
the hour), or from the capture record alone when the two disagree (:mod:`tdm.pcap`). A capture
clock that was never set (record time 0, 1970) or that jumps puts packets far outside the run, and
a clock stepped back puts them before packets already read; LiDAR revolutions built from them would
run backwards in time. Loggers do produce both, so each such packet is counted as a warning and
skipped (:class:`PacketClock`):

* ``"lidar/pcap: packet with a time outside the run skipped"``: its first firing lies outside the
  run +- :data:`tdm.recording.sweep_files.TIME_MARGIN_S`;
* ``"lidar/pcap: packet with a time going back skipped"``: it is earlier than a packet before it.
"""

from __future__ import annotations

import numpy as np

from tdm.detections import ReadStats

__all__ = ["PacketClock", "OUTSIDE", "BACK"]

OUTSIDE = "lidar/pcap: packet with a time outside the run skipped"
BACK = "lidar/pcap: packet with a time going back skipped"
_FLOOR = np.iinfo(np.int64).min


class PacketClock:
    """Keeps the packets of a PCAP whose times are inside the run and not going back.

    Parameters
    ----------
    window_s : (float, float)
        Earliest and latest first-firing time of a packet, s since the recording's start.
    """

    def __init__(self, window_s: tuple[float, float]):
        self.low_ns, self.high_ns = (int(round(w * 1e9)) for w in window_s)
        self.last_ns = _FLOOR

    def keep(self, rel_ns: np.ndarray, stats: ReadStats) -> np.ndarray:
        """Which packets to keep, in file order (the state carries over to the next call).

        Parameters
        ----------
        rel_ns : (P,) int64
            First-firing time of each packet, ns since the recording's start.
        stats : ReadStats
            Receives the counts of skipped packets.

        Returns
        -------
        (P,) bool
        """
        rel_ns = np.asarray(rel_ns, dtype=np.int64)
        inside = (rel_ns >= self.low_ns) & (rel_ns <= self.high_ns)
        times = np.where(inside, rel_ns, _FLOOR)
        before = np.maximum.accumulate(np.concatenate([[self.last_ns], times[:-1]])) if times.size else times
        back = inside & (rel_ns < before)
        if (~inside).any():
            stats.count(OUTSIDE, int((~inside).sum()))
        if back.any():
            stats.count(BACK, int(back.sum()))
        if times.size:
            self.last_ns = max(self.last_ns, int(times.max()))
        return inside & ~back

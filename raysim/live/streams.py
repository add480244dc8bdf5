"""What each live stream sends and when: batches of UDP payloads with their scenario send times.

Every stream is a generator of :class:`Batch` in time order, rendered by the same code as the files
(:meth:`raysim.sensors.lidar.LidarRenderer.chunks`, :meth:`raysim.sensors.radar.RadarRenderer.revolution`,
:func:`raysim.sensors.ais.ais_sentences`, :func:`raysim.sensors.nav.navigation_chunks`), so what goes on the
wire is what the recording holds for the same scenario and seed.
"""

from __future__ import annotations

import datetime as dt
import threading
from dataclasses import dataclass
from pathlib import Path
from typing import Iterator

import numpy as np

from groundfloor import hdl32e
from groundfloor.recording import RADAR_SWEEP
from raysim.live.navico import SPOKES_PER_FRAME, spoke_frames
from raysim.recording import nmea
from raysim.recording.npz import write_sweep
from raysim.world import World

__all__ = ["Batch", "lidar_data_batches", "lidar_position_batches", "radar_batches", "ais_batches", "nav_batches",
           "NAV_CHUNK_S", "announcements"]

#: Seconds of navigation formatted at a time (a short look-ahead, so a fed own ship is followed).
NAV_CHUNK_S = 1.0
#: Seconds of AIS lines put in one batch.
AIS_CHUNK_S = 1.0


@dataclass
class Batch:
    """Payloads of one stream with their send times.

    Attributes
    ----------
    times_s : (n,) float64
        Send time of each payload, s since the scenario start, increasing.
    payloads : list of bytes
        n datagrams.
    """

    times_s: np.ndarray
    payloads: list

    @property
    def end_s(self) -> float:
        """Time of the last payload, s."""
        return float(self.times_s[-1]) if len(self.payloads) else -np.inf


def lidar_data_batches(renderer, sweeps_dir: Path | None = None, done: threading.Event | None = None,
                       cast_ahead: bool = True) -> Iterator[Batch]:
    """The HDL-32E's 1206-byte data packets, a chunk (about one revolution) a batch, each at its send time.

    With ``sweeps_dir`` the revolutions' sweep files are written there too (the live TDM reads them);
    ``done`` is set once the last one is written. ``cast_ahead``: as in ``LidarRenderer.chunks`` (off for a
    fed own ship, whose pose is not to be extrapolated a chunk further).
    """
    from raysim.sensors.lidar_sweeps import LidarSweeps

    sweeps = LidarSweeps(renderer, sweeps_dir) if sweeps_dir is not None else None
    try:
        for chunk in renderer.chunks(cast_ahead=cast_ahead):
            if sweeps is not None:
                sweeps.add(chunk)
            yield Batch(chunk.sent_s, [bytes(p) for p in chunk.payloads])
        if sweeps is not None:
            sweeps.finish()
    finally:
        if done is not None:
            done.set()


def lidar_position_batches(renderer) -> Iterator[Batch]:
    """The 512-byte position packets ($GPRMC of the own ship), one a batch, at the sensor's rate (1 Hz).

    The times are those of the file render: ``k / rate`` up to the end of the last data packet's cycle.
    """
    rate = renderer.cfg.position_packet_rate_hz
    if rate <= 0:
        return
    end_s = renderer.n_packets * renderer.cycles_per_packet * hdl32e.CYCLE_DT_S
    k = 0
    while k / rate < end_s:
        yield Batch(np.array([k / rate]), [renderer.position_packet(k / rate)])
        k += 1


def radar_batches(renderer, spokes_per_frame: int = SPOKES_PER_FRAME, sweeps_dir: Path | None = None,
                  done: threading.Event | None = None, sectors: int = 1) -> Iterator[Batch]:
    """Spoke frames in the Navico Broadband 3G/4G format, a revolution (or a sector of one) a batch.

    A frame leaves when its last spoke has been received: at that spoke's time. With ``sweeps_dir`` each
    revolution's NPZ sweep is written there too (the live TDM reads them); ``done`` is set after the last.

    With ``sectors`` > 1 (a fed own ship) the revolution is rendered anew for each of its sectors, just
    before the sector is due, and the sector's spokes are taken from that render: their poses come from
    the fixes received by then, not from a pose extrapolated over the whole revolution. The random
    streams are named after the revolution, so the renders differ only by the own ship's poses; the
    sweep written for the TDM is the sent spokes' levels.
    """
    s = renderer.spokes
    index = np.arange(s)
    starts = np.arange(0, s, spokes_per_frame)
    last = np.minimum(starts + spokes_per_frame - 1, s - 1)
    sector_of_frame = (starts * sectors) // s
    try:
        for rev in range(renderer.n_revolutions):
            sent = None
            for sector in range(sectors):
                r = renderer.revolution(rev)
                frames_here = np.flatnonzero(sector_of_frame == sector)
                rows = slice(int(starts[frames_here[0]]), int(last[frames_here[-1]]) + 1)
                sent = r.arrays() if sent is None else sent
                for name in ("echo", "heading_deg"):  # what the own ship's poses change
                    sent[name][rows] = getattr(r, name)[rows]
                frames = spoke_frames(r.echo[rows], index[rows], s, r.heading_deg[rows], float(renderer.cfg.range_m),
                                      spokes_per_frame)
                yield Batch(np.asarray(r.time, np.float64)[last[frames_here]], frames)
            if sweeps_dir is not None:
                write_sweep(sweeps_dir, rev, RADAR_SWEEP, sent)
    finally:
        if done is not None:
            done.set()


def ais_batches(world: World) -> Iterator[Batch]:
    """``!AIVDM`` sentences (CR LF, no TAG block), one a datagram, at their reception times, a second a batch."""
    from raysim.sensors.ais import ais_sentences, received_messages, ship_messages

    ships = {ship.name: ship for ship in world.scenario.ships}
    received = []
    for obj in world.objects:
        if obj.kind == "ship" and obj.ais is not None and obj.ais.enabled:
            received += received_messages(world, ship_messages(world, obj, ships[obj.name]), obj)
    lines = ais_sentences(received)
    times = np.array([t for t, _ in lines], np.float64)
    for a, b in _runs_by_time(times, AIS_CHUNK_S):
        yield Batch(times[a:b], [(sentence + "\r\n").encode("ascii") for _, sentence in lines[a:b]])


def nav_batches(world: World) -> Iterator[Batch]:
    """The own ship's $GPRMC, $GPGGA, $GPVTG, $GPZDA and $HEHDT at the NMEA rate, one sentence a datagram."""
    from raysim.sensors.nav import navigation_chunks, nmea_indices

    s = world.scenario
    cfg = s.sensors.nav
    indices = nmea_indices(s.duration_s, cfg.rate_hz, cfg.nmea_rate_hz)
    step = max(1, int(round(NAV_CHUNK_S * cfg.rate_hz)))
    for t, c in navigation_chunks(world, step, indices):
        times, payloads = [], []
        for k, t_s in enumerate(t.tolist()):
            utc = s.start_time + dt.timedelta(seconds=t_s)
            epoch = nmea.nav_epoch(utc, float(c["lat"][k]), float(c["lon"][k]), float(c["z"][k]),
                                   float(c["sog_mps"][k]), float(c["cog_deg"][k]), float(c["heading_deg"][k]),
                                   cfg.geoid_separation_m)
            times += [t_s] * len(epoch)
            payloads += [(sentence + "\r\n").encode("ascii") for sentence in epoch]
        yield Batch(np.array(times, np.float64), payloads)


def announcements(duration_s: float, payload: bytes, period_s: float = 1.0) -> Iterator[Batch]:
    """One payload every ``period_s`` from t = 0 (the Navico beacon and status report), 10 s a batch."""
    times = np.arange(0.0, duration_s, period_s)
    for a in range(0, times.size, 10):
        yield Batch(times[a:a + 10], [payload] * len(times[a:a + 10]))


def _runs_by_time(times_s: np.ndarray, span_s: float) -> Iterator[tuple[int, int]]:
    """Index ranges [a, b) of sorted times, one per ``span_s`` window that holds any."""
    if times_s.size == 0:
        return
    window = np.floor(times_s / span_s).astype(np.int64)
    cuts = np.flatnonzero(np.diff(window)) + 1
    starts = np.r_[0, cuts]
    ends = np.r_[cuts, times_s.size]
    yield from zip(starts.tolist(), ends.tolist())

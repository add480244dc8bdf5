"""The own ship driven from outside: NMEA 0183 fixes by UDP (``raysim live --ownship-in PORT``).

raysim listens on 127.0.0.1:PORT for NMEA 0183 sentences by UDP, one or more per
datagram: GGA (position), HDT (true heading), VTG (course and speed over ground) and
Kongsberg Seapath's proprietary ``$PSXN,23`` (roll, pitch, heading, heave). Any
talker is accepted (GP, GN, IN, HE, ...). Each sentence is stamped with the scenario
clock when it arrives (the live pacer's clock), not with the UTC it may carry.

:class:`OwnShipFeed` keeps the latest fixes of each kind in thread-safe ring
buffers; :class:`FedMotion` implements the :class:`raysim.motion.Motion` protocol
from them, so it can replace ``world.own_ship.motion``:

- position: linear between GGA fixes; past the last fix, extrapolated with the last
  velocity (VTG, else the difference of the last two fixes) for at most
  :data:`MAX_EXTRAPOLATION_S`; beyond that held at that extrapolation, and the feed
  is *stale* (reported once per episode);
- heading (HDT; PSXN,23's heading only while no HDT has arrived): unwrapped and
  linear between sentences, extrapolated with the last yaw rate for at most
  :data:`MAX_EXTRAPOLATION_S`;
- roll, pitch, heave (PSXN,23): linear between sentences, held after the last;
- whatever the feed has never carried (everything before the first GGA; heading,
  attitude or heave without their sentences) comes from the scenario's motion.

Sign conventions. ``$PSXN,23,roll,pitch,heading,heave``: roll in degrees positive
with port side up, pitch in degrees positive with bow up, heave in metres positive
down (Kongsberg Seapath manuals, as transcribed in the field descriptions of pynmea2
1.19 ``pynmea2/types/proprietary/sxn.py``, class ``SXN23``). :func:`parse_fix`
returns the marine convention of raysim's trajectory files: ``roll_deg`` positive
starboard down (= port up, so unchanged), ``pitch_deg`` positive bow up (unchanged),
``heave_m`` positive up (the sentence's value negated). :class:`FedMotion` converts
to the FLU angles of :mod:`raysim.pose`: ``roll_rad = radians(roll_deg)``,
``pitch_rad = -radians(pitch_deg)`` (FLU pitch is positive bow down), ``z = heave_m``.
"""

from __future__ import annotations

import socket
import threading
from collections.abc import Callable

import numpy as np
import pynmea2

from raysim.geodesy import LocalFrame
from raysim.motion import Motion
from raysim.pose import Poses, yaw_from_heading_deg

#: Knots to metres per second (1 NM = 1852 m, exact).
KNOTS_TO_MPS = 1852.0 / 3600.0
#: Longest extrapolation past the last fix, s (issue 21).
MAX_EXTRAPOLATION_S = 1.0
#: Receive timeout of the listener's socket, s: bounds how long ``close()`` waits.
SOCKET_TIMEOUT_S = 0.2
#: Samples kept per kind of fix.
RING_CAPACITY = 512
#: Default bound of the own ship's speed announced to the scene's culling, m/s (50 kn).
DEFAULT_MAX_SPEED_MPS = 50.0 * KNOTS_TO_MPS


def _float(value) -> float | None:
    """``float(value)``, or None for an empty or unparsable field."""
    try:
        out = float(value)
    except (TypeError, ValueError):
        return None
    return out if np.isfinite(out) else None


def _fields_of(msg) -> dict | None:
    """What a parsed pynmea2 sentence carries (see :func:`parse_fix`)."""
    if isinstance(msg, pynmea2.types.talker.GGA):
        quality = _float(msg.gps_qual)
        if not msg.lat or not msg.lon or not quality:
            return None  # no fix (quality 0 or empty position)
        return {"kind": "GGA", "lat_deg": float(msg.latitude), "lon_deg": float(msg.longitude)}
    if isinstance(msg, pynmea2.types.talker.HDT):
        heading = _float(msg.heading)
        return None if heading is None else {"kind": "HDT", "heading_deg": heading % 360.0}
    if isinstance(msg, pynmea2.types.talker.VTG):
        cog, knots, kmh = _float(msg.true_track), _float(msg.spd_over_grnd_kts), _float(msg.spd_over_grnd_kmph)
        sog = knots * KNOTS_TO_MPS if knots is not None else (kmh / 3.6 if kmh is not None else None)
        if sog is None or (cog is None and sog > 0.0):
            return None
        return {"kind": "VTG", "cog_deg": (cog or 0.0) % 360.0, "sog_mps": sog}
    if isinstance(msg, pynmea2.types.proprietary.sxn.SXN23):
        roll, pitch, heave = _float(msg.roll), _float(msg.pitch), _float(msg.heave)
        if roll is None or pitch is None:
            return None
        out = {"kind": "PSXN23", "roll_deg": roll, "pitch_deg": pitch, "heave_m": -heave if heave is not None else 0.0}
        heading = _float(msg.head)
        if heading is not None:
            out["heading_deg"] = heading % 360.0
        return out
    return None


def parse_fix(line: str) -> dict | None:
    """What one NMEA 0183 sentence tells about the own ship.

    Parameters
    ----------
    line : str
        One sentence, with or without its line ending. A checksum, when present,
        must match (a sentence without one is accepted).

    Returns
    -------
    dict or None
        ``kind`` (``"GGA"``, ``"HDT"``, ``"VTG"`` or ``"PSXN23"``) and

        - GGA: ``lat_deg``, ``lon_deg`` (WGS84; the altitude is ignored); None without a fix;
        - HDT: ``heading_deg`` (true, clockwise from north, [0, 360));
        - VTG: ``cog_deg`` (true), ``sog_mps`` (the knots field times 1852/3600, else km/h / 3.6);
        - PSXN,23: ``roll_deg`` (positive starboard down), ``pitch_deg`` (positive bow up),
          ``heave_m`` (positive up: the sentence's heave, positive down, negated) and
          ``heading_deg``; module docstring for the source of the signs.

        None for any other sentence, a bad checksum or garbage (never raises).
    """
    text = line.strip() if isinstance(line, str) else ""
    if not text.startswith("$"):
        return None
    try:
        return _fields_of(pynmea2.parse(text, check=False))
    except Exception:  # pynmea2 raises ParseError, ChecksumError, ValueError, ... on garbage
        return None


class _Ring:
    """A fixed-capacity buffer of rows with strictly increasing times in column 0 (not locked)."""

    def __init__(self, capacity: int, n_columns: int) -> None:
        self.data = np.zeros((int(capacity), int(n_columns)))
        self.count = 0
        self.head = 0  # index of the next write

    def append(self, row) -> None:
        last = (self.head - 1) % self.data.shape[0]
        if self.count and row[0] <= self.data[last, 0]:
            self.data[last] = row  # same instant (one datagram): the newer value wins
            return
        self.data[self.head] = row
        self.head = (self.head + 1) % self.data.shape[0]
        self.count = min(self.count + 1, self.data.shape[0])

    def rows(self) -> np.ndarray:
        """(K, C) copy of the rows, oldest first."""
        if self.count < self.data.shape[0]:
            return self.data[: self.count].copy()
        return np.roll(self.data, -self.head, axis=0)


class OwnShipFeed:
    """A UDP listener for the own ship's NMEA 0183 fixes.

    Parameters
    ----------
    port : int
        UDP port on ``host``; 0 picks a free port (see :attr:`port`).
    frame : LocalFrame
        The world's local frame (``World.frame``): GGA positions become east/north metres.
    clock : callable
        Returns the scenario time in seconds; each sentence is stamped with it on arrival.
    host : str
        Address to bind, 127.0.0.1 by default.
    capacity : int
        Samples kept per kind of fix.

    Attributes
    ----------
    port : int
        The bound port.
    thread : threading.Thread
        The daemon thread receiving datagrams.
    sentences_used, sentences_ignored : int
        Sentences that updated the feed, and the others (unknown kinds, bad checksums, garbage).
    version : int
        Incremented at every update (readers cache on it).

    Notes
    -----
    Rows kept: position ``(t_s, east_m, north_m)`` per GGA; heading ``(t_s, yaw_rad)``
    per HDT (per PSXN,23 while no HDT has arrived); attitude ``(t_s, roll_rad,
    pitch_rad, z_m)`` per PSXN,23, FLU angles of :mod:`raysim.pose`; velocity
    ``(t_s, east_mps, north_mps)`` per VTG.
    """

    def __init__(self, port: int, frame: LocalFrame, clock: Callable[[], float], host: str = "127.0.0.1",
                 capacity: int = RING_CAPACITY) -> None:
        self.frame = frame
        self.clock = clock
        self.sentences_used = 0
        self.sentences_ignored = 0
        self.version = 0
        self._had_hdt = False
        self._lock = threading.Lock()
        self._rings = {"position": _Ring(capacity, 3), "heading": _Ring(capacity, 2),
                       "attitude": _Ring(capacity, 4), "velocity": _Ring(capacity, 3)}
        self._socket = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self._socket.bind((host, int(port)))
        self._socket.settimeout(SOCKET_TIMEOUT_S)
        self.port: int = self._socket.getsockname()[1]
        self._stop = threading.Event()
        self.thread = threading.Thread(target=self._run, name=f"raysim-ownship-in:{self.port}", daemon=True)
        self.thread.start()

    def _run(self) -> None:
        while not self._stop.is_set():
            try:
                data = self._socket.recv(65535)
            except socket.timeout:
                continue
            except OSError:
                break  # socket closed
            self.feed_datagram(data)

    def feed_datagram(self, data: bytes, t_s: float | None = None) -> int:
        """Take every sentence of one datagram; returns how many were used.

        Parameters
        ----------
        data : bytes
            ASCII sentences separated by line endings.
        t_s : float, optional
            Arrival time (scenario seconds); default ``clock()``.
        """
        t_s = self.clock() if t_s is None else float(t_s)
        text = data.decode("ascii", errors="replace")
        return sum(self.feed_line(line, t_s) for line in text.splitlines() if line.strip())

    def feed_line(self, line: str, t_s: float | None = None) -> bool:
        """Take one sentence stamped ``t_s`` (default ``clock()``); True if it updated the feed."""
        fix = parse_fix(line)
        if fix is None:
            self.sentences_ignored += 1
            return False
        t_s = self.clock() if t_s is None else float(t_s)
        kind = fix["kind"]
        with self._lock:
            if kind == "GGA":
                east_m, north_m = self.frame.to_local(fix["lat_deg"], fix["lon_deg"])
                self._rings["position"].append((t_s, float(east_m), float(north_m)))
            elif kind == "HDT":
                self._had_hdt = True
                self._rings["heading"].append((t_s, float(yaw_from_heading_deg(fix["heading_deg"]))))
            elif kind == "VTG":
                course_rad = np.radians(fix["cog_deg"])
                sog = fix["sog_mps"]
                self._rings["velocity"].append((t_s, sog * np.sin(course_rad), sog * np.cos(course_rad)))
            else:
                self._rings["attitude"].append((t_s, np.radians(fix["roll_deg"]), -np.radians(fix["pitch_deg"]),
                                                fix["heave_m"]))
                if not self._had_hdt and "heading_deg" in fix:
                    self._rings["heading"].append((t_s, float(yaw_from_heading_deg(fix["heading_deg"]))))
            self.version += 1
        self.sentences_used += 1
        return True

    def rows(self, kind: str) -> np.ndarray:
        """(K, C) rows of one kind (``position``, ``heading``, ``attitude``, ``velocity``), oldest first."""
        with self._lock:
            return self._rings[kind].rows()

    def snapshot(self) -> tuple[int, dict[str, np.ndarray]]:
        """``(version, rows of every kind)`` read under one lock."""
        with self._lock:
            return self.version, {k: r.rows() for k, r in self._rings.items()}

    @property
    def last_fix_s(self) -> float | None:
        """Scenario time of the last GGA fix, s, or None before the first."""
        with self._lock:
            ring = self._rings["position"]
            return None if ring.count == 0 else float(ring.data[(ring.head - 1) % ring.data.shape[0], 0])

    def close(self) -> None:
        """Stop the listener (within ``SOCKET_TIMEOUT_S`` plus a little) and close its socket."""
        self._stop.set()
        self.thread.join(timeout=2.0 * SOCKET_TIMEOUT_S + 0.1)
        self._socket.close()

    def __enter__(self) -> "OwnShipFeed":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


class _Tables:
    """The feed's rows prepared for evaluation (unwrapped yaw, extrapolation rates)."""

    def __init__(self, rows: dict[str, np.ndarray]) -> None:
        self.position = rows["position"]
        self.heading = rows["heading"].copy()
        if self.heading.shape[0]:
            self.heading[:, 1] = np.unwrap(self.heading[:, 1])
        self.attitude = rows["attitude"]
        self.velocity = rows["velocity"]
        self.last_velocity = self._last_velocity()
        self.last_yaw_rate = _last_rate(self.heading)

    def _last_velocity(self) -> np.ndarray:
        """(2,) east/north m/s for extrapolation: the last VTG, else the last two fixes."""
        if self.velocity.shape[0]:
            return self.velocity[-1, 1:3].copy()
        return np.array([_last_rate(self.position, 1), _last_rate(self.position, 2)])


def _last_rate(table: np.ndarray, column: int = 1) -> float:
    """Rate of change of ``column`` between the last two rows (0 with fewer)."""
    if table.shape[0] < 2:
        return 0.0
    dt = table[-1, 0] - table[-2, 0]
    return float((table[-1, column] - table[-2, column]) / dt) if dt > 0 else 0.0


def _interp(table: np.ndarray, column: int, t_s: np.ndarray) -> np.ndarray:
    """Linear in time between rows, ends held."""
    return np.interp(t_s, table[:, 0], table[:, column])


def _segment_rate(table: np.ndarray, column: int, t_s: np.ndarray) -> np.ndarray:
    """Rate of change of ``column`` over the segment holding each time (0 outside and with < 2 rows)."""
    out = np.zeros(t_s.shape[0])
    if table.shape[0] < 2:
        return out
    times = table[:, 0]
    i = np.clip(np.searchsorted(times, t_s, side="right") - 1, 0, times.shape[0] - 2)
    rate = (table[i + 1, column] - table[i, column]) / (times[i + 1] - times[i])
    inside = (t_s >= times[0]) & (t_s <= times[-1])
    out[inside] = rate[inside]
    return out


class FedMotion:
    """The own ship's motion from an :class:`OwnShipFeed` (the :class:`raysim.motion.Motion` protocol).

    Parameters
    ----------
    feed : OwnShipFeed
        The fixes.
    fallback : Motion
        The scenario's own-ship motion: used before the first GGA fix, and for what
        the feed has never carried (heading without HDT or PSXN,23; roll, pitch and
        heave without PSXN,23).
    max_extrapolation_s : float
        Longest extrapolation past the last fix, s; later times hold that pose and
        the feed is stale.
    max_speed_mps : float, optional
        Bound of the speed announced to the scene (``max_speed_mps``); default the larger
        of the fallback's and 50 kn.
    on_message : callable, optional
        Called with each message (also appended to :attr:`messages`).

    Attributes
    ----------
    stale_events : int
        Stale episodes so far (one per gap of more than ``max_extrapolation_s`` between fixes).
    messages : list of str
        ``"own-ship feed stale: no fix for X s"`` when an episode starts, ``"own-ship
        feed resumed after X s"`` when a fix ends it.

    Notes
    -----
    Past the extrapolation limit the pose is held, so :meth:`velocity_mps` and
    :meth:`yaw_rate_rps` are zero there (consistent with the held pose).
    """

    def __init__(self, feed: OwnShipFeed, fallback: Motion, max_extrapolation_s: float = MAX_EXTRAPOLATION_S,
                 max_speed_mps: float | None = None, on_message: Callable[[str], None] | None = None) -> None:
        self.feed = feed
        self.fallback = fallback
        self.max_extrapolation_s = float(max_extrapolation_s)
        self.max_speed_mps = (max(float(fallback.max_speed_mps), DEFAULT_MAX_SPEED_MPS) if max_speed_mps is None
                              else float(max_speed_mps))
        self.on_message = on_message
        self.messages: list[str] = []
        self.stale_events = 0
        self._in_stale = False
        self._stale_since_s = 0.0
        self._lock = threading.Lock()
        self._cache: tuple[int, _Tables | None] = (-1, None)

    def _tables(self) -> _Tables | None:
        """The feed's rows (cached per feed version); None before the first GGA fix."""
        version, tables = self._cache
        if version != self.feed.version or tables is None:
            version, rows = self.feed.snapshot()
            tables = _Tables(rows)
            self._cache = (version, tables)
        return tables if tables.position.shape[0] else None

    def _say(self, text: str) -> None:
        self.messages.append(text)
        if self.on_message is not None:
            self.on_message(text)

    def _refresh_stale(self, tables: _Tables | None) -> bool:
        """Update the stale state from the feed's clock; True while stale."""
        if tables is None:
            return False
        last_fix_s = float(tables.position[-1, 0])
        age_s = float(self.feed.clock()) - last_fix_s
        with self._lock:
            if age_s > self.max_extrapolation_s and not self._in_stale:
                self._in_stale, self._stale_since_s = True, last_fix_s
                self.stale_events += 1
                self._say(f"own-ship feed stale: no fix for {age_s:.1f} s")
            elif age_s <= self.max_extrapolation_s and self._in_stale:
                self._in_stale = False
                gap_s = last_fix_s - self._stale_since_s
                self._say(f"own-ship feed resumed after {gap_s:.1f} s")
            return self._in_stale

    @property
    def stale(self) -> bool:
        """True when the last GGA fix is older than ``max_extrapolation_s`` by the feed's clock."""
        return self._refresh_stale(self._tables())

    def _ahead_s(self, t_s: np.ndarray, last_s: float) -> np.ndarray:
        """Time past ``last_s``, clipped to [0, max_extrapolation_s]."""
        return np.clip(t_s - last_s, 0.0, self.max_extrapolation_s)

    def poses(self, t_s: np.ndarray) -> Poses:
        """Poses at the (N,) times ``t_s`` (scenario seconds)."""
        t = np.atleast_1d(np.asarray(t_s, dtype=float))
        tables = self._tables()
        if tables is None:
            return self.fallback.poses(t)
        self._refresh_stale(tables)
        pos = tables.position
        ahead_s = self._ahead_s(t, pos[-1, 0])
        east_m = _interp(pos, 1, t) + tables.last_velocity[0] * ahead_s
        north_m = _interp(pos, 2, t) + tables.last_velocity[1] * ahead_s
        fallback = self.fallback.poses(t) if (not tables.heading.shape[0] or not tables.attitude.shape[0]) else None
        if tables.heading.shape[0]:
            head = tables.heading
            yaw_rad = _interp(head, 1, t) + tables.last_yaw_rate * self._ahead_s(t, head[-1, 0])
        else:
            yaw_rad = fallback.yaw_rad
        if tables.attitude.shape[0]:
            att = tables.attitude
            roll_rad, pitch_rad, z_m = _interp(att, 1, t), _interp(att, 2, t), _interp(att, 3, t)
        else:
            roll_rad, pitch_rad, z_m = fallback.roll_rad, fallback.pitch_rad, fallback.position_m[:, 2]
        position_m = np.stack([east_m, north_m, np.asarray(z_m, dtype=float)], axis=1)
        return Poses(position_m, np.asarray(yaw_rad, dtype=float), np.asarray(pitch_rad, dtype=float),
                     np.asarray(roll_rad, dtype=float))

    def _extrapolated(self, t: np.ndarray, last_s: float, inside: np.ndarray, rate) -> np.ndarray:
        """``inside`` up to ``last_s``, ``rate`` within the extrapolation, 0 beyond."""
        out = np.where(t <= last_s, inside, rate)
        out[t > last_s + self.max_extrapolation_s] = 0.0
        return out

    def velocity_mps(self, t_s: np.ndarray) -> np.ndarray:
        """(N, 3) ENU velocity, m/s: VTG (else the fixes' differences), heave rate from PSXN,23."""
        t = np.atleast_1d(np.asarray(t_s, dtype=float))
        tables = self._tables()
        if tables is None:
            return self.fallback.velocity_mps(t)
        pos, vel = tables.position, tables.velocity
        last_s = pos[-1, 0]
        out = np.zeros((t.shape[0], 3))
        for axis in range(2):
            inside = _interp(vel, 1 + axis, t) if vel.shape[0] else _segment_rate(pos, 1 + axis, t)
            out[:, axis] = self._extrapolated(t, last_s, inside, tables.last_velocity[axis])
        if tables.attitude.shape[0]:
            out[:, 2] = _segment_rate(tables.attitude, 3, t)
        else:
            out[:, 2] = self.fallback.velocity_mps(t)[:, 2]
        return out

    def yaw_rate_rps(self, t_s: np.ndarray) -> np.ndarray:
        """(N,) yaw rate, rad/s, counter-clockwise positive."""
        t = np.atleast_1d(np.asarray(t_s, dtype=float))
        tables = self._tables()
        if tables is None or not tables.heading.shape[0]:
            return self.fallback.yaw_rate_rps(t)
        head = tables.heading
        return self._extrapolated(t, head[-1, 0], _segment_rate(head, 1, t), tables.last_yaw_rate)

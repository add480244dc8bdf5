r"""AIS front end: ``ais/ais.nmea`` to position reports in ENU and static data per MMSI.

Each line of the file is an ``!AIVDM`` sentence prefixed by an NMEA 4.10 TAG block
carrying its reception time, ``\c:<unix s>*hh\!AIVDM,...*hh`` (docs/reference.md section 4).
Sentences are parsed with pyais (``NMEASentenceFactory``; multi-sentence messages joined
with ``NMEAMessage.assemble_from_iterable``), so any receiver's log in that form reads.

Decisions (each problem is counted in :class:`tdm.detections.ReadStats` under a key
starting with ``"ais/nmea: "`` and the line or message is skipped):

* Time: the TAG block's ``c:`` field, UNIX seconds (a value above 1e11 is taken as
  milliseconds, as some receivers write), minus the recording's start. A line without a
  TAG block time (or with a bad TAG block checksum) is counted and skipped: borrowing
  the previous line's time would invent a time the receiver never gave. A time in whole
  seconds stands for the second the sentence arrived in, so its middle (+0.5 s) is used:
  unbiased, where the second's start is 0.5 s early on average (2.5 m at 5 m/s).
* A bad sentence checksum, an unparsable line (garbage, non-ASCII, a sentence other
  than ``!xxVDM``/``!xxVDO``), a fragment without its partners (an orphan), a message too
  short for the fields read, a message type that is not used here, and a position report
  without a position (lon 181 / lat 91) are counted and skipped.
* ``!AIVDO`` sentences (the own ship's transponder) are not targets: skipped, not counted.
* Types 1, 2, 3 (Class A), 18 and 19 (Class B) give an :class:`AisReport`; types 5, 19
  and 24 (parts A and B) fill an :class:`AisStatic` per MMSI (later messages update it).
* Units: SOG knots -> m/s (1 kn = 1852/3600 m/s, docs/reference.md section 1); SOG 102.3
  (1023), COG 360 (3600) and heading 511 mean not available -> NaN.
* ROT: decoded from the raw indicator bits (pyais rounds its deg/min to whole degrees):
  ``ROT = sign(k) (k / 4.733)^2`` deg/min (ITU-R M.1371: ``k = 4.733 sqrt(ROT)``, sign
  kept). ``-128`` (not available) -> NaN. ``+-127`` (turning faster than 5 deg per 30 s,
  no turn indicator) -> NaN as well: the sign says which way, but there is no rate to
  filter with, and a clamped 10 deg/min would be a made-up measurement. ``+-126`` is
  708 deg/min or more.
* Dimensions: length = to_bow + to_stern, beam = to_port + to_starboard, metres; a sum
  of 0 means not available -> NaN.
* Reference point: a report's position is its ship's GNSS antenna, which the static data place
  (A, B, C, D = to_bow, to_stern, to_port, to_starboard); each report is moved to its hull's
  centre with the static data received before it (:mod:`tdm.frontend.ais_reference`).
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
from pyais import NMEAMessage, bit_vector
from pyais.exceptions import AISBaseException, UnknownMessageException
from pyais.messages import NMEASentenceFactory

from groundfloor.ais import NAV_STATUS_NOT_DEFINED
from groundfloor.units import MPS_PER_KNOT  # docs/reference.md section 1
from tdm.detections import AisReport, AisStatic, ReadStats
from tdm.frames import EnuFrame
from tdm.frontend.ais_reference import centred_reports

__all__ = ["read_ais", "rot_deg_per_min", "MPS_PER_KNOT"]

ROT_SCALE = 4.733  # ITU-R M.1371 ROT indicator: k = 4.733 sqrt(ROT deg/min) (docs/reference.md section 4)
ROT_NOT_AVAILABLE = -128
ROT_NO_INDICATOR = 127  # +-127: turning at more than 5 deg / 30 s, no turn indicator
ROT_BIT, ROT_WIDTH = 42, 8  # types 1-3: signed 8-bit ROT indicator at bit 42 (gpsd AIVDM)
SOG_NOT_AVAILABLE_KN = 102.3
COG_NOT_AVAILABLE_DEG = 360.0
HEADING_NOT_AVAILABLE = 511
LON_NOT_AVAILABLE, LAT_NOT_AVAILABLE = 181.0, 91.0
MILLISECOND_TIMES_ABOVE = 1e11  # a c: value above this (year 5138 in seconds) is in milliseconds

POSITION_TYPES = (1, 2, 3, 18, 19)
STATIC_TYPES = (5, 19, 24)
#: Bits a message must hold for the fields read here: the end of its last field used (gpsd AIVDM tables).
MIN_BITS = {1: 137, 2: 137, 3: 137, 18: 133, 19: 301, 5: 270}
MIN_BITS_24 = {0: 160, 1: 162}  # part A: name; part B: dimensions
PREFIX = "ais/nmea: "
_OTHER_SENTENCE = re.compile(rb"^[$!][A-Z]{5},")  # a well-formed NMEA 0183 sentence of another kind


def rot_deg_per_min(indicator):
    """Rate of turn from the AIS ROT indicator (module docstring).

    Parameters
    ----------
    indicator : int or array of int
        Raw signed ROT field, -128..127.

    Returns
    -------
    float or ndarray of float64
        Rate of turn, deg/min (positive = turning right, clockwise); NaN for -128 and +-127.
    """
    k = np.asarray(indicator, dtype=float)
    rot = np.sign(k) * (k / ROT_SCALE) ** 2
    rot = np.where((k == ROT_NOT_AVAILABLE) | (np.abs(k) == ROT_NO_INDICATOR) | (np.abs(k) > 128), np.nan, rot)
    return float(rot) if rot.ndim == 0 else rot


def _tag_time_s(sentence) -> float | None:
    """UNIX time of a sentence's TAG block, s (None: no TAG block, bad checksum or no ``c:``)."""
    tb = sentence.tag_block
    if tb is None:
        return None
    tb.init()
    if not tb.is_valid or tb.receiver_timestamp is None:
        return None
    try:
        value = float(tb.receiver_timestamp)
    except ValueError:
        return None
    if not math.isfinite(value):
        return None
    if value > MILLISECOND_TIMES_ABOVE:
        return value / 1000.0
    return value + 0.5 if value == math.floor(value) else value  # a whole second: its middle


def _payload_bits(sentence) -> int:
    return 6 * len(sentence.payload) - int(sentence.fill_bits)


def _dimension(a, b) -> float:
    total = (a or 0) + (b or 0)
    return float(total) if total > 0 else float("nan")


def _text(value) -> str:
    return str(value or "").replace("@", " ").strip()


def _not_available(value, code: float) -> float:
    return float("nan") if value is None or float(value) >= code else float(value)


#: Messages whose dimensions and type are read (types 5 and 19 carry them with the name).
_NAME_AND_SHIP_TYPES = (5, 19)
#: Types whose ROT indicator and navigational status are read (Class A position reports).
_CLASS_A_POSITION_TYPES = (1, 2, 3)
#: Payload bits of a type 24 message of an unknown part (the longer, part B).
_MIN_BITS_24_OTHER = 168
#: Highest valid true heading, deg (511: not available).
_HEADING_LIMIT_DEG = 360


class _AisDecoder:
    """Decodes the sentences of one NMEA log into report rows and static data, counting what it skips."""

    def __init__(self, start_time_unix_s: float, stats: ReadStats):
        self.start_time_unix_s = float(start_time_unix_s)
        self.stats = stats
        self.rows: list[tuple[float, int, int, float, float, float, float, float, float]] = []
        self.static: dict[int, AisStatic] = {}
        #: Per MMSI, each static message's dimensions as received: (t_s, A, B, C, D).
        self.references: dict[int, list[tuple[float, float, float, float, float]]] = {}
        self.pending: dict[tuple, list] = {}  # (fragment count, sequence id, channel) -> [(sentence, time), ...]

    def skip(self, what: str, n: int = 1) -> None:
        self.stats.count(PREFIX + what, n)

    def line(self, line: bytes) -> None:
        """One line of the log: a sentence, a fragment of a multi-sentence message, or a line skipped."""
        line = line.strip()
        if not line:
            return
        sentence = self._sentence(line)
        if sentence is None:
            return
        t_unix = _tag_time_s(sentence)
        if t_unix is None:
            self.skip("line without a (valid) TAG block time skipped")
            return
        if sentence.type == "VDO":
            return
        if sentence.frag_cnt == 1:
            self.message(sentence, t_unix)
        else:
            self._fragment(sentence, t_unix)

    def _sentence(self, line: bytes):
        """The line's !AIVDM sentence with a good checksum, or None (counted)."""
        try:
            sentence = NMEASentenceFactory.produce(line)
        except UnknownMessageException:
            other = _OTHER_SENTENCE.match(line.rsplit(b"\\", 1)[-1])
            self.skip("sentence other than !AIVDM skipped" if other else "unparsable line skipped")
            return None
        except (AISBaseException, ValueError, IndexError, TypeError, UnicodeError):
            self.skip("unparsable line skipped")
            return None
        if getattr(sentence, "TYPE", None) != NMEAMessage.TYPE:
            self.skip("sentence other than !AIVDM skipped")
            return None
        if not sentence.is_valid:
            self.skip("bad checksum skipped")
            return None
        return sentence

    def _fragment(self, sentence, t_unix: float) -> None:
        """A fragment: kept until its message is whole (then decoded at its first fragment's time)."""
        key = (sentence.frag_cnt, sentence.seq_id, sentence.channel)
        group = self.pending.get(key)
        if sentence.frag_num == 1:
            if group:
                self.skip("orphan fragment skipped", len(group))
            self.pending[key] = [(sentence, t_unix)]
            return
        if not group or group[-1][0].frag_num != sentence.frag_num - 1:
            self.skip("orphan fragment skipped", 1 + len(group or []))
            self.pending.pop(key, None)
            return
        group.append((sentence, t_unix))
        if len(group) == sentence.frag_cnt:
            del self.pending[key]
            self.message(NMEAMessage.assemble_from_iterable([s for s, _ in group]), group[0][1])

    def finish(self) -> None:
        """Count the fragments of messages never completed."""
        for group in self.pending.values():
            self.skip("orphan fragment skipped", len(group))

    def message(self, sentence, time_unix_s: float) -> None:
        """A whole message: static data and/or a position report row, or skipped (counted)."""
        try:
            msg = sentence.decode()
        except AISBaseException:
            self.skip(f"message type {sentence.ais_id} skipped (not used)")
            return
        except (ValueError, IndexError, TypeError, KeyError):
            self.skip("undecodable message skipped")
            return
        kind = int(msg.msg_type)
        bits = _payload_bits(sentence)
        if kind == 24:
            need = MIN_BITS_24.get(int(msg.partno or 0), _MIN_BITS_24_OTHER)
        elif kind in MIN_BITS:
            need = MIN_BITS[kind]
        else:
            self.skip(f"message type {kind} skipped (not used)")
            return
        if bits < need:
            self.skip("message too short for its type skipped")
            return
        if kind in STATIC_TYPES:
            self._static(msg, kind, time_unix_s - self.start_time_unix_s)
        if kind in POSITION_TYPES:
            self._position(sentence, msg, kind, time_unix_s)

    def _static(self, msg, kind: int, time_s: float) -> None:
        entry = self.static.setdefault(int(msg.mmsi), AisStatic(int(msg.mmsi)))
        if kind in _NAME_AND_SHIP_TYPES or (kind == 24 and msg.partno == 0):
            entry.name = _text(msg.shipname)
        if kind in _NAME_AND_SHIP_TYPES or (kind == 24 and msg.partno == 1):
            entry.ship_type = int(msg.ship_type or 0)
            if hasattr(msg, "to_bow"):  # a type 24 B of an auxiliary craft has a mothership instead
                a, b, c, d = (float(v or 0) for v in (msg.to_bow, msg.to_stern, msg.to_port, msg.to_starboard))
                entry.length_m = _dimension(msg.to_bow, msg.to_stern)
                entry.beam_m = _dimension(msg.to_port, msg.to_starboard)
                entry.to_bow_m, entry.to_stern_m, entry.to_port_m, entry.to_starboard_m = a, b, c, d
                self.references.setdefault(int(msg.mmsi), []).append((time_s, a, b, c, d))

    def _position(self, sentence, msg, kind: int, time_unix_s: float) -> None:
        lon, lat = msg.lon, msg.lat
        if lon is None or lat is None or abs(lon) >= LON_NOT_AVAILABLE or abs(lat) >= LAT_NOT_AVAILABLE \
                or abs(lat) > 90.0 or abs(lon) > 180.0:
            self.skip("position report without a position (lon 181 / lat 91) skipped")
            return
        sog = _not_available(msg.speed, SOG_NOT_AVAILABLE_KN) * MPS_PER_KNOT
        cog = _not_available(msg.course, COG_NOT_AVAILABLE_DEG)
        heading = float("nan") if msg.heading is None or msg.heading >= _HEADING_LIMIT_DEG else float(msg.heading)
        rot, status = float("nan"), NAV_STATUS_NOT_DEFINED
        if kind in _CLASS_A_POSITION_TYPES:
            rot = rot_deg_per_min(bit_vector(sentence.payload, sentence.fill_bits).get_num(ROT_BIT, ROT_WIDTH, True))
            status = int(msg.status)
        self.rows.append((time_unix_s - self.start_time_unix_s, int(msg.mmsi), kind, float(lat), float(lon), cog, sog,
                          heading, rot, status))

    def reports(self, frame: EnuFrame) -> list[AisReport]:
        """The position reports, sorted by time (stable: file order within a second), in ENU."""
        if not self.rows:
            return []
        rows = sorted(self.rows, key=lambda r: r[0])
        lat = np.array([r[3] for r in rows])
        lon = np.array([r[4] for r in rows])
        east, north = frame.to_enu(lat, lon)
        reports = [AisReport(time_s=r[0], mmsi=r[1], position_m=np.array([e, n]), cog_deg=r[5], sog_mps=r[6],
                             heading_deg=r[7], rot_deg_per_min=r[8], msg_type=r[2], nav_status=r[9])
                   for r, e, n in zip(rows, east, north)]
        return centred_reports(reports, self.references)


def read_ais(path: Path, frame: EnuFrame, start_time_unix_s: float,
             stats: ReadStats) -> tuple[list[AisReport], dict[int, AisStatic]]:
    """Position reports and static data of an AIS NMEA log.

    Parameters
    ----------
    path : Path
        ``ais/ais.nmea``: one TAG-blocked ``!AIVDM`` sentence per line.
    frame : EnuFrame
        The TDM's local frame; positions are mapped with ``frame.to_enu``.
    start_time_unix_s : float
        UNIX time of the recording's start (manifest.json ``start_time``), s.
    stats : ReadStats
        Receives a count for every line or message skipped (module docstring).

    Returns
    -------
    reports : list of AisReport
        Types 1/2/3/18/19, sorted by time (stable: file order within a second). ``time_s``
        is the TAG block time minus the start, s (1 s resolution when the receiver writes whole
        seconds); ``position_m`` (2,) ENU metres, of the hull's centre where the static data
        received before the report place its reference point (:mod:`tdm.frontend.ais_reference`); ``sog_mps`` m/s; ``cog_deg``, ``heading_deg``
        compass degrees; ``rot_deg_per_min`` (NaN for Class B).
    static : dict of int to AisStatic
        Name, ship type, length and beam (m) and the reference point's dimensions A-D (m) per MMSI,
        from types 5, 19 and 24 (the latest received).

    Notes
    -----
    A missing file returns ``([], {})``: AIS may be absent from a recording, and the caller
    decides whether that matters.
    """
    path = Path(path)
    try:
        raw = path.read_bytes()
    except FileNotFoundError:
        return [], {}

    decoder = _AisDecoder(start_time_unix_s, stats)
    for line in raw.splitlines():
        decoder.line(line)
    decoder.finish()
    return decoder.reports(frame), decoder.static

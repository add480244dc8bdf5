"""AIS traffic as the own ship's receiver hears it: ``ais/ais.nmea``.

For every ship with an enabled transponder (docs/reference.md section 4):

1. Kinematics on a 0.5 s grid from its motion: SOG, COG, true heading and the rate of turn
   (deg/min, from the heading's time derivative).
2. Schedule (:mod:`raysim.sensors.ais_schedule`): Class A position reports (type 1; type 3 for
   the first report after the reporting rate changes, as ITDMA announces new slots) at the
   ITU-R M.1371 intervals for its speed, turning and navigation status, type 5 at start and every
   6 min; Class B type 18 every 30 s / 3 min and type 24 parts A and B every 6 min. Channels
   alternate A/B per transmission.
3. Errors (:mod:`raysim.sensors.gauss_markov`): every transmitted quantity gets the thesis's white
   noise plus first-order Gauss-Markov bias (``sensors.ais.noise``, named as in the thesis); the
   position error is drawn per axis (east and north) with the configured variance, SOG in knots,
   COG and heading in degrees, ROT in deg/min. A configured ``position_offset_m`` is added to
   every reported position (spoofing, a misplaced antenna). Fields are clamped before encoding
   (:mod:`raysim.ais_fields`).
4. Failures and reception: nothing while the transponder is off (``off_periods_s``, or disabled:
   a silent ship), each transmission lost with ``dropout_probability``, and only what is within
   ``sensors.ais.range_m`` and the VHF radio horizon ``4.12 (sqrt(h_tx) + sqrt(h_rx))`` km
   (4/3 earth) of the own ship at the time is received.
5. Output: every received message as ``!AIVDM`` sentences (pyais), each line prefixed by an NMEA
   4.10 TAG block with its reception time ``\\c:<unix s>*hh\\``; multi-sentence messages (type 5)
   carry a sequential message id 0..9. Lines are in time order; the file is deterministic. In the
   same pass: ``ais/ais_plain.nmea``, the same sentences without TAG blocks and with CR LF line ends
   (what a chart plotter's serial or UDP input sees), and ``ais/ais_received.jsonl``, one
   ``{"t": <reception time, s since start>, "sentence": ...}`` per line of ``ais/ais.nmea``, in its
   order (the TAG block keeps only whole seconds).
"""

from __future__ import annotations

import datetime as dt
import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from pyais import encode_dict

from groundfloor.units import KNOTS_PER_MPS
from raysim.pose import heading_deg_from_yaw
from raysim.random_streams import stream
from raysim.recording.jsonl import centre_positions_m, course_and_speed
from raysim.recording.nmea import tag_block
from raysim.recording.staging import atomic_path
from raysim.scenario import AisNoise, Ship, ShipAis
from raysim import ais_fields as fields
from raysim.sensors import ais_schedule as schedule
from raysim.sensors.gauss_markov import white_plus_bias
from raysim.sensors.context import SensorContext
from raysim.world import World, WorldObject

__all__ = ["AisMessage", "ship_messages", "received_messages", "ais_sentences", "ais_lines", "write_ais_files",
           "render_ais", "radio_horizon_m"]

GRID_S = 0.5  # kinematics grid (finer than the 2 s shortest interval)

#: Ship type reported when a Class A transponder gives none: 70, cargo (ITU-R M.1371 table 53).
DEFAULT_SHIP_TYPE_CLASS_A = 70
#: Ship type reported when a Class B transponder gives none: 37, pleasure craft (ITU-R M.1371 table 53).
DEFAULT_SHIP_TYPE_CLASS_B = 37
#: Default draught per metre of length (unverified rule of thumb), and the largest draught a
#: type 5 message holds, m (ITU-R M.1371: 0.1 m steps, 25.5 m = 25.5 m or more).
DRAUGHT_PER_LENGTH = 0.06
MAX_DRAUGHT_M = 25.5
#: Position accuracy flag: 1 (high) when the position error is at most this, m (ITU-R M.1371, < 10 m DGNSS).
HIGH_ACCURACY_M = 10.0
#: The first static message (type 5 or 24) goes out within this many seconds of the start, s.
FIRST_STATIC_WITHIN_S = 6.0
#: Reporting intervals further apart than this, s, are a change of rate (type 3 instead of 1).
RATE_CHANGE_TOLERANCE_S = 1e-6


def radio_horizon_m(tx_height_m: float, rx_height_m: float) -> float:
    """VHF radio horizon over a 4/3 earth: ``4.12 (sqrt(h_tx) + sqrt(h_rx))`` km."""
    return 4120.0 * (math.sqrt(max(tx_height_m, 0.0)) + math.sqrt(max(rx_height_m, 0.0)))


@dataclass(frozen=True)
class AisMessage:
    """One transmission: its time, sender, channel and pyais fields (``seq_id`` set when written)."""

    t_s: float
    mmsi: int
    channel: str
    data: dict


def reference_body_m(obj: WorldObject) -> tuple[float, float]:
    """Where the transponder's GNSS antenna stands in the body frame (x forward, y to port), m: its
    ``reference_point_m`` (from the bow, from the port side) on the length x beam box about the object's centre
    (truth.jsonl's centre, :attr:`raysim.world.WorldObject.centre_body_m`), or that centre (amidships on the centre
    line, as the static data then say: A = B, C = D)."""
    cx, cy = obj.centre_body_m
    point = obj.ais.reference_point_m if obj.ais is not None else None
    if point is None:
        return float(cx), float(cy)
    return float(cx + obj.length_m / 2.0 - point[0]), float(cy + obj.beam_m / 2.0 - point[1])


def _kinematics(obj: WorldObject, t: np.ndarray) -> dict:
    """The true motion of the transponder's antenna at times ``t`` (s): position (m, local frame), COG and heading
    (deg), SOG (kn) and rate of turn (deg/min)."""
    poses = obj.motion.poses(t)
    cog, sog_mps = course_and_speed(obj.motion.velocity_mps(t), poses.yaw_rad)
    heading = heading_deg_from_yaw(poses.yaw_rad)
    rot = np.gradient(np.degrees(np.unwrap(np.radians(heading))), t) * 60.0 if t.size > 1 else np.zeros(t.size)
    x, y = centre_positions_m(poses.position_m, poses.yaw_rad, reference_body_m(obj))
    return {"x": x, "y": y, "cog_deg": cog, "sog_kn": sog_mps * KNOTS_PER_MPS, "heading_deg": heading,
            "rot_deg_per_min": rot}


def ship_messages(world: World, obj: WorldObject, ship_cfg: Ship) -> list[AisMessage]:
    """Every message the transponder of ``obj`` transmits during the run (before reception).

    Parameters
    ----------
    world : raysim.world.World
    obj : raysim.world.WorldObject
        A ship with ``obj.ais`` set and enabled.
    ship_cfg : raysim.scenario.Ship
        Its scenario entry (speed, for the anchored status).
    """
    s = world.scenario
    cfg = obj.ais
    grid = np.arange(0.0, s.duration_s + GRID_S, GRID_S)
    kin = _kinematics(obj, grid)
    status_name = _nav_status_name(cfg, ship_cfg)
    rng = stream(s.seed, f"ais.{cfg.mmsi}.schedule")
    interval = _interval_s(cfg, kin, status_name)
    t = schedule.due_times(grid, interval, rng, s.duration_s)
    reported = _reported_values(world, cfg, grid, kin, t)
    messages = _position_reports(s.start_time, cfg, fields.NAV_STATUS[status_name], t, np.interp(t, grid, interval),
                                 reported, _high_accuracy(s.sensors.ais.noise))
    messages += _static_reports(cfg, obj, rng, s.duration_s)
    messages.sort(key=lambda m: (m[0], m[1]["msg_type"]))
    first = "A" if rng.uniform() < 0.5 else "B"
    other = {"A": "B", "B": "A"}
    return [AisMessage(tm, cfg.mmsi, first if i % 2 == 0 else other[first], data)
            for i, (tm, data) in enumerate(messages)]


def _nav_status_name(cfg: ShipAis, ship_cfg: Ship) -> str:
    """The navigation status's name: as configured, or from the speed (0 kn: at anchor) for ``auto``."""
    if cfg.nav_status == "auto":
        return "at_anchor" if ship_cfg.speed_kn == 0 else "under_way"
    return cfg.nav_status


def _interval_s(cfg: ShipAis, kin: dict, status_name: str) -> np.ndarray:
    """Reporting interval on the kinematics grid, s: Class A by speed, turning and status; Class B by speed."""
    if cfg.ais_class != "A":
        return schedule.class_b_interval_s(kin["sog_kn"])
    anchored = np.full(kin["sog_kn"].size, status_name in ("at_anchor", "moored"))
    turning = np.abs(kin["rot_deg_per_min"]) > schedule.TURNING_DEG_PER_MIN
    return schedule.class_a_interval_s(kin["sog_kn"], turning, anchored)


def _reported_values(world: World, cfg: ShipAis, grid: np.ndarray, kin: dict, t: np.ndarray) -> dict:
    """Position (lat, lon, deg), SOG (kn), COG and heading (deg) and ROT (deg/min) as reported at times ``t``.

    The true values interpolated from the grid plus the thesis's errors, one named stream per
    quantity (``ais.<mmsi>.<quantity>``), and the configured position offset.
    """
    s = world.scenario
    noise = s.sensors.ais.noise

    def err(name, var_w, var_b, tau):
        return white_plus_bias(stream(s.seed, f"ais.{cfg.mmsi}.{name}"), t, math.sqrt(var_w), math.sqrt(var_b), tau)

    east = np.interp(t, grid, kin["x"]) + cfg.position_offset_m[0] + err(
        "position_east", noise.position_measure_variance_m2, noise.position_bias_variance_m2,
        noise.position_bias_time_constant_sec)
    north = np.interp(t, grid, kin["y"]) + cfg.position_offset_m[1] + err(
        "position_north", noise.position_measure_variance_m2, noise.position_bias_variance_m2,
        noise.position_bias_time_constant_sec)
    lat, lon = world.frame.to_geodetic(east, north)
    sog = np.interp(t, grid, kin["sog_kn"]) + err("sog", noise.sog_measure_variance_knots2, noise.sog_bias_variance_knots2,
                                                 noise.sog_bias_time_constant_sec)
    cog_true = np.degrees(np.unwrap(np.radians(kin["cog_deg"])))
    cog = np.interp(t, grid, cog_true) + err("cog", noise.cog_measure_variance_deg2, noise.cog_bias_variance_deg2,
                                           noise.cog_bias_time_constant_sec)
    hdg_true = np.degrees(np.unwrap(np.radians(kin["heading_deg"])))
    heading = np.interp(t, grid, hdg_true) + err("heading", noise.track_measure_variance_deg2,
                                               noise.track_bias_variance_deg2, noise.track_bias_time_constant_sec)
    rot = np.interp(t, grid, kin["rot_deg_per_min"]) + err("rot", noise.rot_measure_variance_deg2_pr_min2,
                                                         noise.rot_bias_variance_deg2_pr_min2,
                                                         noise.rot_bias_time_constant_sec)
    return {"lat": lat, "lon": lon, "sog": sog, "cog": cog, "heading": heading, "rot": rot}


def _high_accuracy(noise: AisNoise) -> bool:
    """The position accuracy flag: the error's standard deviation at most :data:`HIGH_ACCURACY_M`."""
    return math.sqrt(noise.position_measure_variance_m2 + noise.position_bias_variance_m2) <= HIGH_ACCURACY_M


def _position_reports(start: dt.datetime, cfg: ShipAis, status: int, t: np.ndarray, interval_s: np.ndarray,
                      reported: dict, accuracy: bool) -> list[tuple[float, dict]]:
    """``(t_s, pyais fields)`` of every position report: types 1/3 (Class A) or 18 (Class B)."""
    seconds = np.floor((start.second + start.microsecond * 1e-6 + t) % 60.0)
    rate_changed = np.concatenate([[False], np.abs(np.diff(interval_s)) > RATE_CHANGE_TOLERANCE_S])
    lat, lon, sog, cog, heading, rot = (reported[k] for k in ("lat", "lon", "sog", "cog", "heading", "rot"))
    messages = []
    for k in range(t.size):  # one pyais field dict per transmission (pyais encodes message by message)
        if cfg.ais_class == "A":
            data = fields.position_report(3 if rate_changed[k] else 1, cfg.mmsi, status, float(rot[k]), float(sog[k]),
                                          accuracy, float(lon[k]), float(lat[k]), float(cog[k]), float(heading[k]),
                                          float(seconds[k]))
        else:
            data = fields.class_b_report(cfg.mmsi, float(sog[k]), accuracy, float(lon[k]), float(lat[k]),
                                         float(cog[k]), float(heading[k]), float(seconds[k]))
        messages.append((float(t[k]), data))
    return messages


def _static_reports(cfg: ShipAis, obj: WorldObject, rng: np.random.Generator,
                    duration_s: float) -> list[tuple[float, dict]]:
    """``(t_s, pyais fields)`` of the static data: at start (within the first 6 s) and every 6 min.

    Class A sends type 5; Class B type 24 part A and, one slot later, part B.
    """
    name = cfg.name or obj.name
    length, beam = obj.length_m, obj.beam_m
    t0 = float(np.round(rng.uniform(0.0, FIRST_STATIC_WITHIN_S) / schedule.SLOT_S) * schedule.SLOT_S)
    static_t = np.arange(t0, duration_s, schedule.STATIC_INTERVAL_S)
    if cfg.ais_class == "A":
        ship_type = DEFAULT_SHIP_TYPE_CLASS_A if cfg.ship_type is None else cfg.ship_type
        draught = min(DRAUGHT_PER_LENGTH * length, MAX_DRAUGHT_M) if cfg.draught_m is None else cfg.draught_m
        static = fields.static_report(cfg.mmsi, name, cfg.call_sign, ship_type, length, beam, draught, cfg.destination,
                                      cfg.reference_point_m)
        return [(float(ts), static) for ts in static_t]
    ship_type = DEFAULT_SHIP_TYPE_CLASS_B if cfg.ship_type is None else cfg.ship_type
    part_a = fields.static_report_b(cfg.mmsi, 0, name, cfg.call_sign, ship_type, length, beam)
    part_b = fields.static_report_b(cfg.mmsi, 1, name, cfg.call_sign, ship_type, length, beam, cfg.reference_point_m)
    return [(float(ts), part_a) for ts in static_t] + [(float(ts + schedule.SLOT_S), part_b) for ts in static_t]


def received_messages(world: World, messages: list[AisMessage], obj: WorldObject) -> list[AisMessage]:
    """The transmissions of ``obj`` the own ship receives: transponder on, not dropped, in range."""
    s = world.scenario
    cfg = obj.ais
    if not messages:
        return []
    t = np.array([m.t_s for m in messages])
    keep = np.ones(t.size, dtype=bool)
    for start, end in cfg.off_periods_s:
        keep &= ~((t >= start) & (t < end))
    if cfg.dropout_probability > 0:
        keep &= stream(s.seed, f"ais.{cfg.mmsi}.dropout").uniform(size=t.size) >= cfg.dropout_probability
    rx = s.sensors.ais
    own = world.own_ship.motion.poses(t).position_m
    ship = obj.motion.poses(t).position_m
    distance = np.hypot(ship[:, 0] - own[:, 0], ship[:, 1] - own[:, 1])
    limit = rx.range_m
    if rx.radio_horizon:
        tx_h = cfg.antenna_height_m if cfg.antenna_height_m is not None else obj.height_m
        limit = min(limit, radio_horizon_m(tx_h, rx.antenna_height_m))
    keep &= distance <= limit
    return [m for m, k in zip(messages, keep) if k]


def ais_sentences(messages: list[AisMessage]) -> list[tuple[float, str]]:
    """The ``!AIVDM`` sentences of the messages in time order, with their reception times.

    Parameters
    ----------
    messages : list of AisMessage
        Received messages, any order.

    Returns
    -------
    list of (float, str)
        ``(t_s, sentence)``: reception time, s since the scenario start, and the sentence with its
        checksum; ordered by time, MMSI and message type; the fragments of a multi-sentence message
        are consecutive, share its time and a sequential message id 0..9.
    """
    order = sorted(messages, key=lambda m: (m.t_s, m.mmsi, m.data["msg_type"]))
    out, seq = [], 0
    for m in order:
        sentences = encode_dict(m.data, talker_id="AI", sentence_type="VDM", radio_channel=m.channel, seq_id=seq)
        if len(sentences) > 1:
            seq = (seq + 1) % 10
        out += [(m.t_s, s) for s in sentences]
    return out


def ais_lines(messages: list[AisMessage], start_time: dt.datetime) -> list[str]:
    """NMEA lines of the messages in time order: TAG block + ``!AIVDM`` sentence; seq ids 0..9 for multi-part."""
    base = start_time.timestamp()
    return [tag_block(base + t_s) + s for t_s, s in ais_sentences(messages)]


def write_ais_files(directory: Path, messages: list[AisMessage], start_time: dt.datetime) -> int:
    r"""Write ``ais.nmea``, ``ais_plain.nmea`` and ``ais_received.jsonl`` into ``directory`` in one pass.

    Parameters
    ----------
    directory : Path
        The recording's ``ais`` directory (created if missing).
    messages : list of AisMessage
        The received messages.
    start_time : datetime.datetime
        Scenario start, UTC (the TAG blocks' UNIX seconds).

    Returns
    -------
    int
        Number of sentences: the line count of each of the three files.

    Notes
    -----
    Line k of each file is the same sentence: in ``ais.nmea`` behind its TAG block (``\n``), in
    ``ais_plain.nmea`` alone (CR LF, as NMEA 0183 on the wire), in ``ais_received.jsonl`` as
    ``{"t": <s since start, 6 decimals>, "sentence": ...}``.
    """
    directory = Path(directory)
    base = start_time.timestamp()
    n = 0
    with atomic_path(directory / "ais.nmea") as tagged_tmp, atomic_path(directory / "ais_plain.nmea") as plain_tmp, \
            atomic_path(directory / "ais_received.jsonl") as times_tmp, \
            open(tagged_tmp, "w", encoding="ascii", newline="\n") as tagged, \
            open(plain_tmp, "w", encoding="ascii", newline="\n") as plain, \
            open(times_tmp, "w", encoding="ascii", newline="\n") as times:
        for t_s, s in ais_sentences(messages):
            tagged.write(tag_block(base + t_s) + s + "\n")
            plain.write(s + "\r\n")
            times.write(f'{{"t": {t_s:.6f}, "sentence": {json.dumps(s)}}}\n')
            n += 1
    return n


def render_ais(ctx: SensorContext) -> None:
    """The ``ais`` entry for :data:`raysim.render.SENSOR_RENDERERS`: writes ``ais/`` (:func:`write_ais_files`)."""
    world = ctx.world
    ships = {ship.name: ship for ship in world.scenario.ships}
    received, transmitted = [], 0
    for obj in world.objects:
        if obj.kind != "ship" or obj.ais is None or not obj.ais.enabled:
            continue  # no transponder, or a silent ship: never transmits
        sent = ship_messages(world, obj, ships[obj.name])
        transmitted += len(sent)
        received += received_messages(world, sent, obj)
    lines = write_ais_files(Path(ctx.out_dir) / "ais", received, world.scenario.start_time)
    for name in ("ais.nmea", "ais_plain.nmea", "ais_received.jsonl"):
        ctx.counts[f"ais/{name}"] = lines
    ctx.counts["ais/messages_transmitted"] = transmitted
    ctx.counts["ais/messages_received"] = len(received)

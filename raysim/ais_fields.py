"""AIS message fields from physical values: units, legal ranges, "not available" codes (ITU-R M.1371).

pyais encodes what it is given and wraps silently outside a field's range (ROT 800 deg/min
becomes a left turn, SOG 150 kn becomes 47.6 kn, heading 600 becomes 88: docs/reference.md
section 4), so every value is clamped here first; NaN means "not available".

ROT uses the standard encoding ``ROT_AIS = round(4.733 sqrt(|ROT|))`` (deg/min, sign kept),
clamped to +-126 (708 deg/min); -128 = not available. pyais takes ROT in deg/min and applies
the same formula, except that it passes the values 127 and 128 through as raw codes, so the
code is computed here and handed to pyais as the deg/min value that encodes to it exactly.
"""

from __future__ import annotations

import math

from groundfloor.ais import NAV_STATUS

__all__ = ["NAV_STATUS", "UNIT_MODEL_CODE", "VENDOR_ID", "position_report", "class_b_report", "rot_code",
           "static_report", "static_report_b", "unit_serial", "ais_text"]

#: Message 24 part B's 42-bit vendor ID (ITU-R M.1371-5, message 24 and Annex 7): the manufacturer's
#: ID, 3 six-bit characters (18 bits; "RAYSIM" would be cut to "RAY"), then the unit model code
#: (4 bits, 0..15) and the unit serial number (20 bits, 0..1048575).
VENDOR_ID = "RSM"
UNIT_MODEL_CODE = 1
SERIAL_MAX = (1 << 20) - 1
SOG_MAX_KN = 102.2  # 1022: 102.2 kn or more; 1023 = not available
AIS_CHARS = "@ABCDEFGHIJKLMNOPQRSTUVWXYZ[\\]^_ !\"#$%&'()*+,-./0123456789:;<=>?"


def _nan(x) -> bool:
    return x is None or (isinstance(x, float) and math.isnan(x))


def rot_code(rot_deg_per_min: float) -> int:
    """ITU ROT code: ``round(4.733 sqrt(|ROT|))`` with the sign, clamped to +-126; -128 when not available."""
    if _nan(rot_deg_per_min):
        return -128
    code = round(4.733 * math.sqrt(abs(rot_deg_per_min)))
    return int(math.copysign(min(code, 126), rot_deg_per_min)) if code else 0


def _rot_for_pyais(code: int) -> float:
    """The deg/min value pyais encodes to ``code`` (its own formula inverted); raw for -128."""
    if code == -128:
        return -128
    return math.copysign((abs(code) / 4.733) ** 2, code) if code else 0.0


def _sog(sog_kn: float) -> float:
    return 102.3 if _nan(sog_kn) else round(min(max(sog_kn, 0.0), SOG_MAX_KN), 1)


def _cog(cog_deg: float) -> float:
    if _nan(cog_deg):
        return 360.0
    c = round(cog_deg % 360.0, 1)
    return 0.0 if c >= 360.0 else c


def _heading(heading_deg: float) -> int:
    if _nan(heading_deg):
        return 511
    h = int(round(heading_deg % 360.0))
    return 0 if h >= 360 else h


def _lon_lat(lon_deg: float, lat_deg: float) -> tuple[float, float]:
    if _nan(lon_deg) or _nan(lat_deg) or abs(lat_deg) > 90.0 or abs(lon_deg) > 180.0:
        return 181.0, 91.0
    return float(lon_deg), float(lat_deg)


def _second(second: float) -> int:
    return 60 if _nan(second) else int(min(max(second, 0), 59))


def position_report(msg_type: int, mmsi: int, status: int, rot_deg_per_min: float, sog_kn: float, accuracy: bool,
                    lon_deg: float, lat_deg: float, cog_deg: float, heading_deg: float, second: float,
                    raim: bool = False) -> dict:
    """Fields of a Class A position report (type 1, 2 or 3) for ``pyais.encode_dict``, clamped."""
    lon, lat = _lon_lat(lon_deg, lat_deg)
    return {"msg_type": msg_type, "repeat": 0, "mmsi": mmsi, "status": status,
            "turn": _rot_for_pyais(rot_code(rot_deg_per_min)), "speed": _sog(sog_kn), "accuracy": int(bool(accuracy)),
            "lon": lon, "lat": lat, "course": _cog(cog_deg), "heading": _heading(heading_deg), "second": _second(second),
            "maneuver": 0, "raim": int(bool(raim)), "radio": 0}


def class_b_report(mmsi: int, sog_kn: float, accuracy: bool, lon_deg: float, lat_deg: float, cog_deg: float,
                   heading_deg: float, second: float, raim: bool = False) -> dict:
    """Fields of a Class B CS position report (type 18), clamped."""
    lon, lat = _lon_lat(lon_deg, lat_deg)
    return {"msg_type": 18, "repeat": 0, "mmsi": mmsi, "speed": _sog(sog_kn), "accuracy": int(bool(accuracy)),
            "lon": lon, "lat": lat, "course": _cog(cog_deg), "heading": _heading(heading_deg), "second": _second(second),
            "cs": 1, "display": 0, "dsc": 0, "band": 1, "msg22": 0, "assigned": 0, "raim": int(bool(raim)), "radio": 0}


def ais_text(text: str | None, length: int) -> str:
    """Upper case, AIS 6-bit characters only (others become spaces), at most ``length`` characters."""
    if not text:
        return ""
    return "".join(c if c in AIS_CHARS else " " for c in text.upper())[:length].rstrip()


#: Largest dimensions the fields hold, m: A and B 9 bits, C and D 6 bits (ITU-R M.1371-5, message 5).
MAX_TO_BOW_M, MAX_TO_PORT_M = 511, 63


def _dimensions(length_m: float, beam_m: float, reference_point_m: tuple[float, float] | None = None) -> dict:
    """Dimensions A-D of the reference point (the GNSS antenna) from the bow, stern, port and starboard side, whole
    metres (ITU-R M.1371-5, message 5 "overall dimension/reference for position"): ``reference_point_m`` (to bow,
    to port), m, or None for amidships on the centre line (A = B, C = D)."""
    def whole(value_m: float, limit: int) -> int:
        return min(max(int(round(value_m)), 0), limit)

    if reference_point_m is None:
        half_l, half_b = whole(length_m / 2.0, MAX_TO_BOW_M), whole(beam_m / 2.0, MAX_TO_PORT_M)
        return {"to_bow": half_l, "to_stern": half_l, "to_port": half_b, "to_starboard": half_b}
    to_bow_m, to_port_m = reference_point_m
    return {"to_bow": whole(to_bow_m, MAX_TO_BOW_M), "to_stern": whole(length_m - to_bow_m, MAX_TO_BOW_M),
            "to_port": whole(to_port_m, MAX_TO_PORT_M), "to_starboard": whole(beam_m - to_port_m, MAX_TO_PORT_M)}


def static_report(mmsi: int, name: str, call_sign: str | None, ship_type: int, length_m: float, beam_m: float,
                  draught_m: float, destination: str | None, reference_point_m: tuple[float, float] | None = None) -> dict:
    """Fields of a type 5 static and voyage related data message (ETA not available); the reference point as for
    :func:`_dimensions`."""
    return {"msg_type": 5, "repeat": 0, "mmsi": mmsi, "ais_version": 0, "imo": 0,
            "callsign": ais_text(call_sign, 7), "shipname": ais_text(name, 20), "ship_type": int(ship_type),
            **_dimensions(length_m, beam_m, reference_point_m), "epfd": 1, "month": 0, "day": 0, "hour": 24, "minute": 60,
            "draught": round(min(max(draught_m, 0.0), 25.5), 1), "destination": ais_text(destination, 20), "dte": 0}


def unit_serial(mmsi: int) -> int:
    """The transponder's serial number in message 24 part B: the MMSI's last six digits (fit 20 bits)."""
    return int(mmsi) % 1_000_000


def static_report_b(mmsi: int, part: int, name: str, call_sign: str | None, ship_type: int, length_m: float,
                    beam_m: float, reference_point_m: tuple[float, float] | None = None) -> dict:
    """Fields of a type 24 static data report, part A (0: name) or B (1: type, vendor ID, call sign, dimensions; the
    reference point as for :func:`_dimensions`).

    Part B's vendor ID: manufacturer :data:`VENDOR_ID`, unit model :data:`UNIT_MODEL_CODE`, serial
    number :func:`unit_serial` (pyais's ``vendorid``, ``model`` and ``serial`` fields).
    """
    if part == 0:
        return {"msg_type": 24, "repeat": 0, "mmsi": mmsi, "partno": 0, "shipname": ais_text(name, 20)}
    return {"msg_type": 24, "repeat": 0, "mmsi": mmsi, "partno": 1, "ship_type": int(ship_type), "vendorid": VENDOR_ID,
            "model": UNIT_MODEL_CODE, "serial": unit_serial(mmsi), "callsign": ais_text(call_sign, 7),
            **_dimensions(length_m, beam_m, reference_point_m)}

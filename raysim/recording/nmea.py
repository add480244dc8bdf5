"""NMEA 0183 sentences and NMEA 4.10 TAG blocks (REFERENCE.md section 4)."""

from __future__ import annotations

import datetime as dt
from functools import reduce

KNOTS_PER_MPS = 3600.0 / 1852.0


def checksum(body: str) -> str:
    """Two hex digits: XOR of the characters between the start character and '*'."""
    return f"{reduce(lambda a, c: a ^ ord(c), body, 0):02X}"


def sentence(body: str, start: str = "$") -> str:
    """``$BODY*hh`` (or ``!BODY*hh``)."""
    return f"{start}{body}*{checksum(body)}"


def tag_block(unix_time_s: float) -> str:
    r"""NMEA 4.10 TAG block carrying a UNIX time: ``\c:1496318400*hh\``."""
    body = f"c:{int(unix_time_s)}"
    return f"\\{body}*{checksum(body)}\\"


def _lat(lat_deg: float) -> tuple[str, str]:
    a = abs(lat_deg)
    d = int(a)
    return f"{d:02d}{(a - d) * 60:07.4f}", "N" if lat_deg >= 0 else "S"


def _lon(lon_deg: float) -> tuple[str, str]:
    a = abs(lon_deg)
    d = int(a)
    return f"{d:03d}{(a - d) * 60:07.4f}", "E" if lon_deg >= 0 else "W"


def gprmc(utc: dt.datetime, lat_deg: float, lon_deg: float, sog_mps: float, cog_deg: float) -> str:
    """Recommended minimum GNSS sentence (``$GPRMC``), mode A (autonomous)."""
    lat, ns = _lat(lat_deg)
    lon, ew = _lon(lon_deg)
    hhmmss = utc.strftime("%H%M%S") + f".{utc.microsecond // 10000:02d}"
    body = (f"GPRMC,{hhmmss},A,{lat},{ns},{lon},{ew},{sog_mps * KNOTS_PER_MPS:.2f},{cog_deg % 360.0:.2f},"
            f"{utc.strftime('%d%m%y')},,,A")
    return sentence(body)

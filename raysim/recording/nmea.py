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


def _degrees_minutes(value_deg: float, degree_digits: int) -> str:
    """``DDDMM.MMMM``: whole degrees and minutes to 4 decimals, rounded once (never ``60.0000`` minutes)."""
    minutes = round(abs(value_deg) * 60.0, 4)
    whole = int(minutes // 60.0)
    return f"{whole:0{degree_digits}d}{minutes - 60.0 * whole:07.4f}"


def _lat(lat_deg: float) -> tuple[str, str]:
    return _degrees_minutes(lat_deg, 2), "N" if lat_deg >= 0 else "S"


def _lon(lon_deg: float) -> tuple[str, str]:
    return _degrees_minutes(lon_deg, 3), "E" if lon_deg >= 0 else "W"


def _hhmmss(utc: dt.datetime) -> str:
    """UTC time of day ``hhmmss.ss`` (hundredths truncated)."""
    return utc.strftime("%H%M%S") + f".{utc.microsecond // 10000:02d}"


def _angle(angle_deg: float, decimals: int = 2) -> str:
    """An angle in [0, 360) with fixed decimals; 359.999 prints as 0.00, never 360.00."""
    a = round(angle_deg % 360.0, decimals)
    if a >= 360.0:
        a -= 360.0
    return f"{a + 0.0:.{decimals}f}"


def gprmc(utc: dt.datetime, lat_deg: float, lon_deg: float, sog_mps: float, cog_deg: float) -> str:
    """Recommended minimum GNSS sentence (``$GPRMC``), mode A (autonomous)."""
    lat, ns = _lat(lat_deg)
    lon, ew = _lon(lon_deg)
    body = (f"GPRMC,{_hhmmss(utc)},A,{lat},{ns},{lon},{ew},{sog_mps * KNOTS_PER_MPS:.2f},{_angle(cog_deg)},"
            f"{utc.strftime('%d%m%y')},,,A")
    return sentence(body)


def gpgga(utc: dt.datetime, lat_deg: float, lon_deg: float, altitude_m: float, satellites: int = 10,
          hdop: float = 0.9) -> str:
    """GNSS fix data (``$GPGGA``): GPS fix (quality 1), antenna altitude above mean sea level.

    Parameters
    ----------
    utc : datetime.datetime
        Time of the fix, UTC.
    lat_deg, lon_deg : float
        WGS84 position, deg.
    altitude_m : float
        Antenna altitude above mean sea level, m (2 decimals); the geoid separation is given as 0.0.
    satellites : int
        Satellites in use.
    hdop : float
        Horizontal dilution of precision.
    """
    lat, ns = _lat(lat_deg)
    lon, ew = _lon(lon_deg)
    body = (f"GPGGA,{_hhmmss(utc)},{lat},{ns},{lon},{ew},1,{satellites:02d},{hdop:.1f},"
            f"{altitude_m + 0.0:.2f},M,0.0,M,,")
    return sentence(body)


def hehdt(heading_deg: float) -> str:
    """True heading from a gyro/INS (``$HEHDT``), deg in [0, 360), 2 decimals."""
    return sentence(f"HEHDT,{_angle(heading_deg)},T")

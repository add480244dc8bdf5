"""NMEA 0183 sentences and NMEA 4.10 TAG blocks (docs/reference.md section 4)."""

from __future__ import annotations

import datetime as dt
from functools import reduce

from groundfloor.units import KNOTS_PER_MPS


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
          hdop: float = 0.9, geoid_separation_m: float = 0.0) -> str:
    """GNSS fix data (``$GPGGA``): GPS fix (quality 1), antenna altitude above mean sea level.

    Parameters
    ----------
    utc : datetime.datetime
        Time of the fix, UTC.
    lat_deg, lon_deg : float
        WGS84 position, deg.
    altitude_m : float
        Antenna altitude above mean sea level (the geoid), m (2 decimals).
    satellites : int
        Satellites in use.
    hdop : float
        Horizontal dilution of precision.
    geoid_separation_m : float
        Height of the geoid above the WGS84 ellipsoid, m (1 decimal, as receivers print it): the
        ellipsoidal height is ``altitude_m + geoid_separation_m``.
    """
    lat, ns = _lat(lat_deg)
    lon, ew = _lon(lon_deg)
    body = (f"GPGGA,{_hhmmss(utc)},{lat},{ns},{lon},{ew},1,{satellites:02d},{hdop:.1f},"
            f"{altitude_m + 0.0:.2f},M,{round(geoid_separation_m, 1) + 0.0:.1f},M,,")
    return sentence(body)


def hehdt(heading_deg: float) -> str:
    """True heading from a gyro/INS (``$HEHDT``), deg in [0, 360), 2 decimals."""
    return sentence(f"HEHDT,{_angle(heading_deg)},T")


def gpvtg(sog_mps: float, cog_deg: float) -> str:
    """Course and speed over ground (``$GPVTG``), NMEA 0183 v3+ layout with the mode indicator.

    ``$GPVTG,<cog>,T,,M,<sog kn>,N,<sog km/h>,K,A*hh``: the magnetic course is left empty (no
    magnetic variation is modelled), mode ``A`` (autonomous), as :func:`gprmc`.

    Parameters
    ----------
    sog_mps : float
        Speed over ground, m/s; written in knots and in km/h (2 decimals each, both rounded from
        ``sog_mps``).
    cog_deg : float
        Course over ground, deg true, written in [0, 360) with 2 decimals.

    Returns
    -------
    str
        The sentence with its checksum, without a line end.
    """
    return sentence(f"GPVTG,{_angle(cog_deg)},T,,M,{sog_mps * KNOTS_PER_MPS:.2f},N,{sog_mps * 3.6:.2f},K,A")


def gpzda(utc: dt.datetime) -> str:
    """UTC time and date (``$GPZDA``): ``hhmmss.ss,dd,mm,yyyy,00,00`` (local zone = UTC).

    Parameters
    ----------
    utc : datetime.datetime
        The epoch, UTC (hundredths of a second truncated, as in :func:`gprmc`).

    Returns
    -------
    str
        The sentence with its checksum, without a line end.
    """
    return sentence(f"GPZDA,{_hhmmss(utc)},{utc.day:02d},{utc.month:02d},{utc.year:04d},00,00")


#: Sentences of one own-ship NMEA epoch, in the order they are written (:func:`nav_epoch`).
NAV_EPOCH_SENTENCES = ("GPRMC", "GPGGA", "GPVTG", "GPZDA", "HEHDT")


def nav_epoch(utc: dt.datetime, lat_deg: float, lon_deg: float, altitude_m: float, sog_mps: float, cog_deg: float,
              heading_deg: float, geoid_separation_m: float = 0.0) -> list[str]:
    """The own ship's sentences of one NMEA epoch, in the order of :data:`NAV_EPOCH_SENTENCES`.

    The GNSS receiver's burst comes first, as real receivers send it: ``$GPRMC`` (which starts the
    epoch for gpsd and chart plotters), ``$GPGGA``, ``$GPVTG``, then ``$GPZDA`` closing it; the
    gyro/INS's ``$HEHDT``, a separate talker on the multiplexed bus, follows.

    Parameters
    ----------
    utc : datetime.datetime
        The epoch, UTC.
    lat_deg, lon_deg : float
        WGS84 position, deg.
    altitude_m : float
        Antenna altitude above mean sea level, m.
    sog_mps : float
        Speed over ground, m/s.
    cog_deg, heading_deg : float
        Course over ground and true heading, deg.
    geoid_separation_m : float
        Geoid height above the WGS84 ellipsoid, m (GGA).

    Returns
    -------
    list of str
        Five sentences with checksums, without TAG blocks or line ends.
    """
    return [gprmc(utc, lat_deg, lon_deg, sog_mps, cog_deg),
            gpgga(utc, lat_deg, lon_deg, altitude_m, geoid_separation_m=geoid_separation_m),
            gpvtg(sog_mps, cog_deg), gpzda(utc), hehdt(heading_deg)]

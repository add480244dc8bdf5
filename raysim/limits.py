"""What raysim renders and what it refuses up front: sizes, times, speeds and scene size.

Each limit comes from a format, a number type or the cost of rendering (docs/scenario.md,
"Limits and what is refused"). The checks return a one-line reason (or raise
:class:`raysim.errors.InputError`), so bad input is refused before anything is rendered
or written.
"""

from __future__ import annotations

import datetime as dt

import numpy as np

from raysim.errors import InputError

_UTC = dt.timezone.utc

#: Smallest size of anything physical a scenario gives in metres (lengths, beams, radii, heights,
#: antenna heights, visibility, LiDAR range). Below a centimetre an object is smaller than the
#: HDL-32E's range noise (8 mm) and a thousand times below the radar's range cell: such a value is
#: a slip (millimetres given as metres, a missing exponent), and at 1e-30 m the meshes' float32
#: vertices collapse to one point.
MIN_SIZE_M = 0.01

#: Finest radar ray spacing (``sensors.radar.resolve_m``), m: the rays per spoke grow as
#: 1 / resolve_m^2 (44 at the default 6 m, 4,056 at 0.5 m, 92,796 at 0.1 m: 190 million rays a
#: revolution, hours per revolution and gigabytes of ray buffers).
MIN_RADAR_RESOLVE_M = 0.5

def _at_least(minimum: float, why: str):
    def check(value: float) -> str | None:
        return f"must be at least {minimum:g} m, got {value:g}: {why}" if value < minimum else None

    return check


#: Schema check of a size (:data:`MIN_SIZE_M`).
SIZE_CHECK = _at_least(MIN_SIZE_M, "below a centimetre nothing is seen (the LiDAR's range noise is 8 mm); "
                                   "millimetres given as metres?")
#: Schema check of ``sensors.radar.resolve_m`` (:data:`MIN_RADAR_RESOLVE_M`).
RESOLVE_CHECK = _at_least(MIN_RADAR_RESOLVE_M, "rays per spoke grow as 1 / resolve_m^2 (4,056 at 0.5 m, "
                                               "92,796 at 0.1 m): hours per revolution")

#: Positions further than this from the origin are rejected: the local frame
#: (transverse Mercator about the origin, flat sea) is meant for a local scene.
MAX_DISTANCE_FROM_ORIGIN_M = 50_000.0

#: Most objects in a scene, the own ship included. Each object is posed for every ray batch and
#: adds a truth line every 0.1 s (266 bytes): 1,000 objects for the default 300 s write 0.8 GB of
#: truth.jsonl; the thesis's scenario has 17.
MAX_OBJECTS = 1_000

#: Most triangles in a scene (every object's mesh counted once per object). A generated iceberg has
#: 5,120, a buoy 336, a generated hull 130, so only mesh files come near it.
MAX_TRIANGLES = 10_000_000

#: Memory per triangle of a scene, bytes, for the estimate in messages: the mesh arrays (float64
#: vertices, int64 faces) and the ray engine's float32 copy and BVH (about 100 bytes).
BYTES_PER_TRIANGLE = 160

#: Render time per object per simulated second, s, for the estimate in messages (measured on
#: two cores with the default sensors: 5,000 buoys took 23 s for 3 s of scenario).
RENDER_S_PER_OBJECT_SECOND = 0.002

#: Truth lines per object per simulated second (truth.jsonl at 10 Hz) and bytes per line (a mean of 372 on
#: harbour_approach, with the centre fields).
TRUTH_BYTES_PER_OBJECT_SECOND = 10 * 372

#: Fastest a trajectory may move between consecutive samples, m/s: the fastest surface craft
#: (racing powerboats, fast patrol boats) do 40-50 m/s; a planing USV 20-25 m/s.
MAX_SPEED_MPS = 60.0

#: Position jitter allowed on top of :data:`MAX_SPEED_MPS` x dt between two samples, m
#: (GNSS noise in a recorded track sampled at 10-100 Hz).
SPEED_JITTER_M = 1.0

#: First instant any output can stamp: the PCAP's and the bag's times are unsigned seconds
#: (and nanoseconds) since 1970-01-01.
EARLIEST_START = dt.datetime(1970, 1, 1, tzinfo=_UTC)

#: Last instant the ROS 2 bag can stamp: builtin_interfaces/Time holds seconds since 1970 in a
#: signed 32-bit integer (2**31 - 1 s). The bag is always written, so a run must end by then.
LATEST_END = EARLIEST_START + dt.timedelta(seconds=2**31 - 1)

#: Last instant the PCAP can stamp: its record headers hold unsigned 32-bit seconds (2**32 - 1 s).
PCAP_LATEST_END = EARLIEST_START + dt.timedelta(seconds=2**32 - 1)

#: Mean Earth radius (IUGG), m, for distances between trajectory samples.
EARTH_RADIUS_M = 6_371_008.8


def _iso(t: dt.datetime) -> str:
    return t.astimezone(_UTC).strftime("%Y-%m-%dT%H:%M:%SZ")


def time_span_problem(start: dt.datetime, duration_s: float, duration_from: str = "duration_s") -> str | None:
    """Why a run from ``start`` for ``duration_s`` cannot be stamped in the outputs, or None.

    Parameters
    ----------
    start : datetime.datetime
        Aware UTC start.
    duration_s : float
        Length of the run, s.
    duration_from : str
        Where the duration comes from, for the message (``duration_s`` or ``--duration``).
    """
    start_unix_s = start.timestamp()  # exact for any aware datetime, whatever its year
    if start < EARLIEST_START:
        return (f"{_iso(start)} is before {_iso(EARLIEST_START)}: the PCAP's and the ROS 2 bag's time stamps "
                "are unsigned seconds since 1970")
    end_unix_s = start_unix_s + duration_s
    if end_unix_s > LATEST_END.timestamp():
        pcap = "" if end_unix_s <= PCAP_LATEST_END.timestamp() else (
            f" (and the PCAP's unsigned 32-bit seconds end at {_iso(PCAP_LATEST_END)})")
        return (f"the run ({duration_from} {duration_s:g} s from {_iso(start)}) ends after {_iso(LATEST_END)}, "
                f"the last second the ROS 2 bag's signed 32-bit seconds hold{pcap}")
    return None


def object_count_problem(n_objects: int, duration_s: float) -> str | None:
    """Why a scene of ``n_objects`` (own ship included) is refused, with the cost estimate; or None."""
    if n_objects <= MAX_OBJECTS:
        return None
    truth_gb = n_objects * duration_s * TRUTH_BYTES_PER_OBJECT_SECOND / 1e9
    minutes = n_objects * duration_s * RENDER_S_PER_OBJECT_SECOND / 60.0
    took = f"{minutes:.0f} min" if minutes < 90 else f"{minutes / 60:.1f} h"
    return (f"{n_objects:,} objects (own ship, obstacles and ships); at most {MAX_OBJECTS:,}: for {duration_s:g} s "
            f"they would write about {truth_gb:.3g} GB of truth.jsonl and take about {took} to render on two cores")


def check_scene_triangles(triangles_per_object: list[tuple[str, int]], file: str) -> None:
    """Refuse a scene of more than :data:`MAX_TRIANGLES` triangles, naming its largest object.

    Parameters
    ----------
    triangles_per_object : list of (str, int)
        Each object's key path in the scenario and its triangle count.
    file : str
        The scenario file, for the message.

    Raises
    ------
    InputError
        With the total, the memory estimate and the object with the most triangles.
    """
    total = sum(n for _, n in triangles_per_object)
    if total <= MAX_TRIANGLES:
        return
    where, most = max(triangles_per_object, key=lambda item: item[1])
    memory_gb = total * BYTES_PER_TRIANGLE / 1e9
    raise InputError(file, where, f"the scene has {total:,} triangles ({most:,} here); at most {MAX_TRIANGLES:,} "
                                  f"(about {memory_gb:.3g} GB of meshes and ray-engine structures): simplify the mesh")


def fastest_step(t_s: np.ndarray, lat_deg: np.ndarray, lon_deg: np.ndarray) -> tuple[int, float, float] | None:
    """The first step between consecutive samples faster than :data:`MAX_SPEED_MPS`, or None.

    Returns
    -------
    (int, float, float) or None
        Index of the later sample, the distance (m) and the time step (s).
    """
    lat, lon = np.radians(lat_deg), np.radians(lon_deg)
    hav = (np.sin(np.diff(lat) / 2.0) ** 2
           + np.cos(lat[:-1]) * np.cos(lat[1:]) * np.sin(np.diff(lon) / 2.0) ** 2)
    distance_m = 2.0 * EARTH_RADIUS_M * np.arcsin(np.sqrt(np.clip(hav, 0.0, 1.0)))
    dt_s = np.diff(t_s)
    bad = distance_m > MAX_SPEED_MPS * dt_s + SPEED_JITTER_M
    if not bad.any():
        return None
    k = int(np.argmax(bad))
    return k + 1, float(distance_m[k]), float(dt_s[k])


def speed_text(distance_m: float, dt_s: float) -> str:
    """``moves 20,015 km in 10 s (2.0e+06 m/s)`` for a message."""
    far = f"{distance_m / 1000:,.0f} km" if distance_m >= 10_000 else f"{distance_m:,.1f} m"
    return f"moves {far} in {dt_s:g} s ({distance_m / dt_s:.3g} m/s)"

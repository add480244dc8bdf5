"""``land.geojson``: the recording's chart of land (:data:`groundfloor.recording.LAND`), checked.

A recording whose scenario has land carries it as a GeoJSON FeatureCollection (RFC 7946, WGS84
longitude/latitude) of Polygon and MultiPolygon features (properties ``id``, ``name``,
``height_m``, ``material``; docs/formats.md). The TDM uses only the geometry, as a real one uses
an ENC's land areas as its land mask (:mod:`tdm.land`).

No file: no land. A file that is there but broken is an **error** (one line naming the file and the
place, such as ``features[3].geometry.coordinates[0][2]``), never a counted warning: the writer
writes it whole and at once (not line by line as a logger), and a TDM that read on without its
chart would silently report targets on land. Checked: readable UTF-8 JSON (at most
:data:`MAX_LAND_BYTES`); a FeatureCollection with a ``features`` array; each feature a Feature
whose ``properties`` are an object or null and whose geometry is a Polygon or MultiPolygon; each
ring an array of at least 4 ``[lon, lat]`` positions (a third number, an altitude, ignored), the
first equal to the last, every coordinate finite with lon in [-180, 180] and lat in [-90, 90] deg;
each polygon valid (OGC: rings that do not cross, holes inside their shell; :func:`shapely.is_valid`).
An empty ``features`` array is a recording without land.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import shapely
from shapely.geometry import MultiPolygon, Polygon
from shapely.validation import explain_validity

from groundfloor.recording import LAND
from tdm.errors import RecordingError
from tdm.recording import values
from tdm.recording.files import decode_utf8, is_present, read_bytes

__all__ = ["MAX_LAND_BYTES", "ChartLand", "read_land"]

#: Largest land.geojson read, bytes (parsed whole; raysim reads land files of up to 200 MB,
#: OpenStreetMap's coast of a 50 km scene is a few MB).
MAX_LAND_BYTES = 200_000_000
#: Smallest number of positions of a closed ring (RFC 7946 section 3.1.6).
MIN_RING_POSITIONS = 4


@dataclass(frozen=True)
class ChartLand:
    """The recording's land: its polygons in WGS84 (x = longitude, y = latitude, degrees).

    Attributes
    ----------
    polygons : tuple of shapely.geometry.Polygon
        Valid polygons, holes allowed, in file order (a MultiPolygon gives one per polygon).
    path : Path
        The file they were read from.
    """

    polygons: tuple[Polygon, ...]
    path: Path

    def geometry(self) -> MultiPolygon:
        """All polygons as one MultiPolygon (lon, lat degrees)."""
        return MultiPolygon(list(self.polygons))


def read_land(recording: Path) -> ChartLand | None:
    """The recording's land (module docstring), or None when it has no ``land.geojson``.

    Raises
    ------
    RecordingError
        The file is there but unreadable or broken (module docstring).
    """
    path = Path(recording) / LAND
    if not is_present(path):
        return None
    text = decode_utf8(read_bytes(path, max_bytes=MAX_LAND_BYTES), path)
    if not text.strip():
        raise RecordingError(str(path), "(file)", "empty: not a GeoJSON FeatureCollection")
    try:
        root = json.loads(text)
    except json.JSONDecodeError as exc:
        raise RecordingError(str(path), f"line {exc.lineno}", f"not valid JSON: {exc.msg}") from None
    except RecursionError:
        raise RecordingError(str(path), "(file)", "not valid JSON: nested too deeply") from None
    return ChartLand(tuple(_feature_collection(root, path)), path)


def _feature_collection(root: object, path: Path) -> list[Polygon]:
    if not isinstance(root, dict):
        raise RecordingError(str(path), "(top level)",
                             f"must be a GeoJSON FeatureCollection object, not {values.describe(root)}")
    if root.get("type") != "FeatureCollection":
        raise RecordingError(str(path), "type", f"must be a GeoJSON FeatureCollection, not {root.get('type')!r}")
    features = root.get("features")
    if not isinstance(features, list):
        raise RecordingError(str(path), "features", f"must be an array of Features, not {values.describe(features)}")
    return [p for i, f in enumerate(features) for p in _feature(f, path, f"features[{i}]")]


def _feature(feature: object, path: Path, where: str) -> list[Polygon]:
    if not isinstance(feature, dict) or feature.get("type") != "Feature":
        raise RecordingError(str(path), f"{where}.type", "not a GeoJSON Feature (its \"type\" must be \"Feature\")")
    if not isinstance(feature.get("properties", {}), (dict, type(None))):
        raise RecordingError(str(path), f"{where}.properties", "must be an object or null")
    geometry = feature.get("geometry")
    where = f"{where}.geometry"
    if not isinstance(geometry, dict) or geometry.get("type") not in ("Polygon", "MultiPolygon"):
        kind = geometry.get("type") if isinstance(geometry, dict) else values.describe(geometry)
        raise RecordingError(str(path), f"{where}.type", f"land must be a Polygon or MultiPolygon, not {kind!r}")
    coordinates = geometry.get("coordinates")
    where = f"{where}.coordinates"
    if not isinstance(coordinates, list):
        raise RecordingError(str(path), where, f"must be an array, not {values.describe(coordinates)}")
    if geometry["type"] == "Polygon":
        return [_polygon(coordinates, path, where)]
    return [_polygon(rings, path, f"{where}[{i}]") for i, rings in enumerate(coordinates)]


def _polygon(rings: object, path: Path, where: str) -> Polygon:
    """A valid polygon from its rings (the shell first, then holes)."""
    if not isinstance(rings, list) or not rings:
        raise RecordingError(str(path), where, "a polygon must be a non-empty array of rings")
    shell, *holes = [_ring(ring, path, f"{where}[{i}]") for i, ring in enumerate(rings)]
    polygon = Polygon(shell, holes)
    if not shapely.is_valid(polygon):
        raise RecordingError(str(path), where, f"invalid polygon: {explain_validity(polygon)}")
    return polygon


def _ring(ring: object, path: Path, where: str) -> list[tuple[float, float]]:
    """The (lon, lat) positions of a closed ring of at least 4 positions."""
    if not isinstance(ring, list):
        raise RecordingError(str(path), where, f"a ring must be an array of positions, not {values.describe(ring)}")
    points = [_position(p, path, f"{where}[{i}]") for i, p in enumerate(ring)]
    if len(points) < MIN_RING_POSITIONS:
        raise RecordingError(str(path), where,
                             f"a ring needs at least {MIN_RING_POSITIONS} positions, not {len(points)}")
    if points[0] != points[-1]:
        raise RecordingError(str(path), where, "ring not closed: its first and last positions differ")
    return points


def _position(position: object, path: Path, where: str) -> tuple[float, float]:
    """One [lon, lat] position: finite numbers in range."""
    if not (isinstance(position, list) and len(position) >= 2
            and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in position)):
        raise RecordingError(str(path), where,
                             f"a position must be [lon, lat] numbers, not {values.describe(position)}")
    try:
        lon, lat = float(position[0]), float(position[1])
    except OverflowError:  # a JSON integer beyond any float
        lon, lat = math.inf, math.inf
    if not (math.isfinite(lon) and math.isfinite(lat)):
        raise RecordingError(str(path), where, f"non-finite coordinate [{lon}, {lat}]")
    if not (-180.0 <= lon <= 180.0 and -90.0 <= lat <= 90.0):
        raise RecordingError(str(path), where, f"[{lon:g}, {lat:g}] is outside lon [-180, 180] / lat [-90, 90] deg")
    return lon, lat

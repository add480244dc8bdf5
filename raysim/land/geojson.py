"""Reading land polygons from GeoJSON (RFC 7946) files.

A land file is a FeatureCollection, a Feature or a bare Polygon/MultiPolygon geometry in WGS84
longitude/latitude (RFC 7946 section 4), holes allowed. Each polygon (one per polygon of a
MultiPolygon) becomes a :class:`LandPolygon`; a feature's properties ``height_m``, ``material`` and
``slope_deg`` override the land entry's defaults. Every problem raises
:class:`raysim.errors.InputError` with the file, the place in it (``features[3].geometry.coordinates[0]``)
and one line saying what is wrong; nothing is printed. docs/land.md states the rules.
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import shapely
from shapely.geometry import LinearRing, Polygon
from shapely.validation import explain_validity

from raysim.errors import InputError
from raysim.input_files import MAX_LAND_FILE_BYTES, read_text_file
from raysim.land.mesh import LAND_MATERIALS

__all__ = ["MAX_LAND_FILE_BYTES", "MAX_LAND_HEIGHT_M", "LandPolygon", "read_land_file"]

#: Highest land accepted, m above the sea (higher than any mountain; catches feet or millimetres).
MAX_LAND_HEIGHT_M = 9_000.0

_POLYGON_TYPES = ("Polygon", "MultiPolygon")
_OTHER_GEOMETRIES = ("Point", "MultiPoint", "LineString", "MultiLineString", "GeometryCollection")


@dataclass(frozen=True)
class LandPolygon:
    """One land polygon of a GeoJSON file, with its height and material.

    Attributes
    ----------
    polygon : shapely.geometry.Polygon
        Valid polygon in WGS84 (x = longitude, y = latitude, degrees), holes allowed.
    height_m : float
        Top height above the sea, m (>= 0).
    material : str
        Material name, one of :data:`raysim.land.mesh.LAND_MATERIALS`.
    slope_deg : float or None
        Slope of the shore, degrees in (0, 90]; None for vertical faces.
    where : str
        Its place in the file, for messages (``features[3].geometry.coordinates[0]``).
    """

    polygon: Polygon
    height_m: float
    material: str
    slope_deg: float | None
    where: str


def _at(prefix: str, where: str) -> str:
    """``where`` inside the file, after the caller's prefix (``land[0]`` + ``features[3]``)."""
    if not prefix:
        return where
    return f"{prefix}.{where}" if where else prefix


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def read_land_file(
    path: str | os.PathLike,
    default_height_m: float = 10.0,
    default_material: str = "rock",
    where_prefix: str = "",
) -> list[LandPolygon]:
    """Read the land polygons of a GeoJSON file.

    Parameters
    ----------
    path : str or os.PathLike
        GeoJSON file (RFC 7946, WGS84 lon/lat), at most :data:`MAX_LAND_FILE_BYTES`.
    default_height_m : float, optional
        Height of polygons whose feature has no ``height_m`` property, m.
    default_material : str, optional
        Material of polygons whose feature has no ``material`` property.
    where_prefix : str, optional
        Put before every place in messages and :attr:`LandPolygon.where`, joined with ``.``
        (empty: places in the file as they are, ``features[3].geometry``).

    Returns
    -------
    list of LandPolygon
        In file order; a MultiPolygon gives one per polygon.

    Raises
    ------
    InputError
        ``(path, where, what)``: unreadable or too large, not JSON, not GeoJSON, a geometry other than
        Polygon/MultiPolygon, a ring not closed or of fewer than 4 positions, an invalid (e.g.
        self-intersecting) polygon, a coordinate outside lon [-180, 180] / lat [-90, 90] or not finite,
        a bad ``height_m``, ``material`` or ``slope_deg``, no polygons at all.
    ValueError
        ``default_height_m`` or ``default_material`` is bad (the scenario's schema checks them first).
    """
    if not (_is_number(default_height_m) and 0.0 <= default_height_m <= MAX_LAND_HEIGHT_M):
        raise ValueError(f"default height must be in [0, {MAX_LAND_HEIGHT_M:g}] m, got {default_height_m!r}")
    if default_material not in LAND_MATERIALS:
        raise ValueError(f"unknown land material {default_material!r}; valid: {', '.join(LAND_MATERIALS)}")
    file = str(path)
    text = read_text_file(Path(path), file, _at(where_prefix, "(file)"), MAX_LAND_FILE_BYTES, "GeoJSON file")
    try:
        root = json.loads(text)
    except json.JSONDecodeError as exc:
        where = _at(where_prefix, f"line {exc.lineno}")
        raise InputError(file, where, f"not JSON: {exc.msg} (column {exc.colno})") from None
    except RecursionError:
        raise InputError(file, _at(where_prefix, "(file)"), "not JSON that can be read: nested too deeply") from None
    reader = _Reader(file, where_prefix, float(default_height_m), default_material)
    polygons = reader.root(root)
    if not polygons:
        raise InputError(file, _at(where_prefix, "(file)"), "holds no land polygons")
    return polygons


class _Reader:
    """Walks a parsed GeoJSON document, collecting :class:`LandPolygon` or raising :class:`InputError`."""

    def __init__(self, file: str, prefix: str, height_m: float, material: str) -> None:
        self.file = file
        self.prefix = prefix
        self.defaults = {"height_m": height_m, "material": material, "slope_deg": None}

    def fail(self, where: str, what: str) -> InputError:
        return InputError(self.file, _at(self.prefix, where), what)

    def root(self, root: Any) -> list[LandPolygon]:
        """Polygons of a FeatureCollection, a Feature or a bare geometry."""
        if not isinstance(root, dict) or not isinstance(root.get("type"), str):
            raise self.fail("type", "not GeoJSON: the top level must be an object with a \"type\" "
                            "(FeatureCollection, Feature, Polygon or MultiPolygon)")
        self._check_crs(root)
        kind = root["type"]
        if kind == "FeatureCollection":
            features = root.get("features")
            if not isinstance(features, list):
                raise self.fail("features", "a FeatureCollection needs a \"features\" array")
            return [p for i, f in enumerate(features) for p in self.feature(f, f"features[{i}]")]
        if kind == "Feature":
            return self.feature(root, "")
        return self.geometry(root, "", self.defaults)

    def _check_crs(self, root: dict) -> None:
        """Refuse an old-style (GeoJSON 2008) ``crs`` member naming anything but WGS84 lon/lat."""
        crs = root.get("crs")
        if crs is None:
            return
        name = str(crs.get("properties", {}).get("name", "")) if isinstance(crs, dict) else ""
        if "CRS84" not in name and not name.endswith(("EPSG::4326", "EPSG:4326")):
            raise self.fail("crs", f"coordinates must be WGS84 lon/lat (RFC 7946), not {name or crs!r}; "
                            "convert with ogr2ogr -t_srs EPSG:4326")

    def feature(self, feature: Any, where: str) -> list[LandPolygon]:
        """Polygons of one Feature, with its properties over the defaults."""
        if not isinstance(feature, dict) or feature.get("type") != "Feature":
            raise self.fail(_at(where, "type"), "not a GeoJSON Feature (its \"type\" must be \"Feature\")")
        properties = feature.get("properties") or {}
        if not isinstance(properties, dict):
            raise self.fail(_at(where, "properties"), "a Feature's properties must be an object or null")
        values = self.properties(properties, _at(where, "properties"))
        geometry = feature.get("geometry")
        if geometry is None:
            raise self.fail(_at(where, "geometry"), "a land Feature needs a Polygon or MultiPolygon geometry, "
                            "not null")
        return self.geometry(geometry, _at(where, "geometry"), values)

    def properties(self, properties: dict, where: str) -> dict[str, Any]:
        """The defaults overridden by a feature's ``height_m``, ``material`` and ``slope_deg``."""
        values = dict(self.defaults)
        height = properties.get("height_m")
        if height is not None:
            if not _is_number(height) or not math.isfinite(height):
                raise self.fail(_at(where, "height_m"), f"height must be a finite number of metres, got {height!r}")
            if not 0.0 <= height <= MAX_LAND_HEIGHT_M:
                raise self.fail(_at(where, "height_m"),
                                f"height must be in [0, {MAX_LAND_HEIGHT_M:g}] m above the sea, got {height!r}")
            values["height_m"] = float(height)
        material = properties.get("material")
        if material is not None:
            if material not in LAND_MATERIALS:
                raise self.fail(_at(where, "material"),
                                f"unknown land material {material!r}; valid: {' | '.join(LAND_MATERIALS)}")
            values["material"] = material
        slope = properties.get("slope_deg")
        if slope is not None:
            if not _is_number(slope) or not (math.isfinite(slope) and 0.0 < slope <= 90.0):
                raise self.fail(_at(where, "slope_deg"),
                                f"slope must be a number of degrees in (0, 90] (90: vertical), got {slope!r}")
            values["slope_deg"] = float(slope)
        return values

    def geometry(self, geometry: Any, where: str, values: dict[str, Any]) -> list[LandPolygon]:
        """Polygons of a Polygon or MultiPolygon geometry."""
        if not isinstance(geometry, dict) or not isinstance(geometry.get("type"), str):
            raise self.fail(_at(where, "type"), "not a GeoJSON geometry (an object with a \"type\")")
        kind = geometry["type"]
        if kind not in _POLYGON_TYPES:
            known = "a" if kind in _OTHER_GEOMETRIES else "an unknown"
            raise self.fail(_at(where, "type"), f"{known} geometry {kind!r}; land must be Polygon or MultiPolygon")
        coordinates = geometry.get("coordinates")
        where_c = _at(where, "coordinates")
        if not isinstance(coordinates, list):
            raise self.fail(where_c, f"a {kind} needs a \"coordinates\" array")
        if kind == "Polygon":
            return [self.polygon(coordinates, where_c, values)]
        return [self.polygon(p, f"{where_c}[{i}]", values) for i, p in enumerate(coordinates)]

    def polygon(self, rings: Any, where: str, values: dict[str, Any]) -> LandPolygon:
        """One valid polygon from its rings (the first the shoreline, the others holes)."""
        if not isinstance(rings, list) or not rings:
            raise self.fail(where, "a polygon needs an array of rings (the shoreline first, then holes)")
        shell, *holes = [self.ring(r, f"{where}[{i}]") for i, r in enumerate(rings)]
        polygon = Polygon(shell, holes)
        if not polygon.is_valid:
            raise self.fail(where, f"invalid polygon: {explain_validity(polygon)} (rings must not cross each "
                            "other, holes must lie inside the shoreline)")
        return LandPolygon(polygon, values["height_m"], values["material"], values["slope_deg"],
                           _at(self.prefix, where))

    def ring(self, ring: Any, where: str) -> list[tuple[float, float]]:
        """The (lon, lat) positions of a closed, simple ring."""
        if not isinstance(ring, list):
            raise self.fail(where, "a ring must be an array of [lon, lat] positions")
        points = [self.position(p, f"{where}[{i}]") for i, p in enumerate(ring)]
        if len(points) < 4:
            raise self.fail(where, f"a ring needs at least 4 positions (first = last), got {len(points)}")
        if points[0] != points[-1]:
            raise self.fail(where, f"ring not closed: the first position {list(points[0])} differs from the last "
                            f"{list(points[-1])}")
        linear = LinearRing(points)
        if not linear.is_simple or shapely.area(Polygon(linear)) == 0.0:
            problem = explain_validity(Polygon(linear))
            raise self.fail(where, f"self-intersecting or degenerate ring: {problem}")
        return points

    def position(self, position: Any, where: str) -> tuple[float, float]:
        """A (lon, lat) position in range; a third number (altitude) is ignored."""
        if not (isinstance(position, list) and len(position) >= 2 and all(_is_number(v) for v in position)):
            raise self.fail(where, f"a position must be [lon, lat] numbers, got {position!r}")
        lon, lat = float(position[0]), float(position[1])
        if not (math.isfinite(lon) and math.isfinite(lat)):
            raise self.fail(where, f"non-finite coordinate [{lon}, {lat}]")
        if not (-180.0 <= lon <= 180.0 and -90.0 <= lat <= 90.0):
            raise self.fail(where, f"[{lon:g}, {lat:g}] is outside lon [-180, 180] / lat [-90, 90]: GeoJSON is "
                            "WGS84 lon, lat in degrees (projected files: ogr2ogr -t_srs EPSG:4326)")
        return lon, lat

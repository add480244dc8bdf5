"""The recording's ``land.geojson``: the world's land as the chart a TDM masks with (groundfloor.recording.LAND).

One Feature per land polygon, WGS84 lon/lat as read from the scenario's GeoJSON files, with the land
object's ``id`` (manifest.json), ``name``, ``height_m`` and ``material``: a recording carries its own
chart, so a TDM needs neither raysim nor the scenario's files.
"""

from __future__ import annotations

import json
from pathlib import Path

from shapely.geometry import mapping

from raysim.land.geojson import read_land_file
from raysim.recording.staging import atomic_path


def land_features(scenario, land_ids: dict[str, int]) -> dict:
    """The FeatureCollection of a scenario's land (empty when it has none).

    Parameters
    ----------
    scenario : raysim.scenario.Scenario
    land_ids : dict
        Land entry name -> its object id in the world.
    """
    features = []
    for entry in scenario.land:
        for polygon in read_land_file(entry.file, entry.height_m, entry.material):
            features.append({
                "type": "Feature",
                "properties": {"id": land_ids[entry.name], "name": entry.name, "height_m": polygon.height_m,
                               "material": polygon.material},
                "geometry": mapping(polygon.polygon),
            })
    return {"type": "FeatureCollection", "features": features}


def write_land_geojson(scenario, land_ids: dict[str, int], path: Path) -> int:
    """Write ``land.geojson`` atomically; returns the number of features."""
    collection = land_features(scenario, land_ids)
    with atomic_path(Path(path)) as tmp:
        tmp.write_text(json.dumps(collection, separators=(",", ":")) + "\n", encoding="utf-8")
    return len(collection["features"])


__all__ = ["land_features", "write_land_geojson"]

"""Make scenarios/land/busy_port_harbour.geojson from NYC's Borough Boundaries (clipped to shoreline).

Source: New York City Department of City Planning, "Borough Boundaries (Clipped to Shoreline)",
release 16A, published on NYC Open Data (https://data.cityofnewyork.us/, dataset "Borough Boundaries";
free to use under the NYC Open Data Terms of Use). The same release is the ``nybb_16a.zip`` file that
geopandas 0.14 ships in ``geopandas/datasets``. The shapefile is in NAD83 / New York Long Island
State Plane (US feet); this script takes Brooklyn's polygon, clips it to the box round Erie Basin
(Red Hook, Brooklyn) and writes it in WGS84 lon/lat (RFC 7946).

Usage (optional tools, not needed to run raysim)::

    pip install pyshp            # shapely and pyproj are raysim dependencies already
    python scripts/busy_port_land.py nybb_16a/nybb.shp scenarios/land/busy_port_harbour.geojson

The same with GDAL::

    ogr2ogr -f GeoJSON -t_srs EPSG:4326 -where "BoroName = 'Brooklyn'" \\
        -clipdst -74.0235 40.6610 -74.0040 40.6765 out.geojson nybb_16a/nybb.shp
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pyproj
import shapely
from shapely.geometry import box, mapping, shape

#: The scene's box: lon min, lat min, lon max, lat max (Erie Basin and Atlantic Basin's south side).
BOX = (-74.0235, 40.6610, -74.0040, 40.6765)
#: Quays, piers and the breakwater: concrete and rubble faced, about 3 m above high water (not surveyed).
PROPERTIES = {"name": "red_hook", "height_m": 3.0, "material": "concrete"}


def main(shp: Path, out: Path) -> None:
    import shapefile  # pyshp, optional

    reader = shapefile.Reader(str(shp))
    wkt = Path(shp).with_suffix(".prj").read_text()
    to_lonlat = pyproj.Transformer.from_crs(pyproj.CRS.from_wkt(wkt), "EPSG:4326", always_xy=True)
    names = [f[0] for f in reader.fields[1:]]
    for rec in reader.iterShapeRecords():
        if dict(zip(names, rec.record))["BoroName"] != "Brooklyn":
            continue
        geom = shapely.transform(shape(rec.shape.__geo_interface__),
                                 lambda xy: shapely.get_coordinates(shapely.points(*to_lonlat.transform(xy[:, 0], xy[:, 1]))))
        clipped = shapely.set_precision(geom.intersection(box(*BOX)), 1e-7)
        feature = {"type": "Feature", "properties": PROPERTIES, "geometry": mapping(clipped)}
        out.write_text(json.dumps({"type": "FeatureCollection", "features": [feature]}, indent=1) + "\n")
        return
    raise SystemExit("no Brooklyn polygon in " + str(shp))


if __name__ == "__main__":
    main(Path(sys.argv[1]), Path(sys.argv[2]))

"""Land in the pictures (issue 20): map.png fills it, the LiDAR bird's-eye view outlines the shoreline."""

from __future__ import annotations

import datetime as dt
import json
from types import SimpleNamespace

import numpy as np
from PIL import Image

from groundfloor.frames import LocalFrame
from raysim.recording.bev import SHORE_COLOUR, write_bev
from raysim.recording.land_picture import LAND_COLOURS
from raysim.recording.map_picture import MARGIN_PX, SEA, SIZE_PX, TOP_PX, write_map

LAT0, LON0 = 59.43, 10.49
START = dt.datetime(2017, 6, 1, 12, tzinfo=dt.timezone.utc)


def ring(corners_xy_m) -> list[list[float]]:
    """A closed GeoJSON ring (lon, lat) from local corners (x east, y north, m)."""
    frame = LocalFrame(LAT0, LON0)
    lat, lon = frame.to_geodetic(*np.array(corners_xy_m, dtype=float).T)
    return [[float(a), float(b)] for a, b in zip(lon, lat)] + [[float(lon[0]), float(lat[0])]]


def square(x0: float, y0: float, x1: float, y1: float) -> list[tuple[float, float]]:
    return [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]


def recording(tmp_path, land_rings=None, material: str = "rock"):
    """A recording with an own ship going north from (-400, -400) to (-400, 400) m past a buoy at (400, 400) m,
    the origin and (optionally) land."""
    tmp_path.mkdir(parents=True, exist_ok=True)
    (tmp_path / "scenario.yaml").write_text(f"name: t\norigin:\n  lat: {LAT0}\n  lon: {LON0}\n", encoding="utf-8")
    lines = []
    for k, t in enumerate(np.arange(0.0, 9.0)):
        own = {"t": t, "id": 0, "name": "odin", "kind": "ownship", "x": -400.0, "y": -400.0 + 100.0 * k,
               "heading_deg": 0.0, "length_m": 10.9, "beam_m": 3.5}
        buoy = {"t": t, "id": 1, "name": "buoy", "kind": "buoy", "x": 400.0, "y": 400.0, "heading_deg": 0.0,
                "length_m": 1.0, "beam_m": 1.0}
        lines += [json.dumps(own), json.dumps(buoy)]
    (tmp_path / "truth.jsonl").write_text("\n".join(lines) + "\n", encoding="utf-8")
    if land_rings is not None:
        feature = {"type": "Feature", "properties": {"id": 1, "name": "island", "height_m": 20.0, "material": material},
                   "geometry": {"type": "Polygon", "coordinates": land_rings}}
        (tmp_path / "land.geojson").write_text(json.dumps({"type": "FeatureCollection", "features": [feature]}),
                                               encoding="utf-8")
    return tmp_path


def land_mask(path, colour) -> np.ndarray:
    return np.all(np.asarray(Image.open(path).convert("RGB")) == colour, axis=2)


def test_the_map_fills_the_island_in_its_colour_with_its_lagoon_as_sea_and_nothing_else(tmp_path):
    # island 100..300 m east and north, a lagoon 175..225 m; the objects span -450..450 m (50 m margin)
    rec = recording(tmp_path, [ring(square(100, 100, 300, 300)), ring(square(175, 175, 225, 225))])
    write_map(rec, START)
    mask = land_mask(rec / "map.png", LAND_COLOURS["rock"])
    scale = min((SIZE_PX - 2 * MARGIN_PX) / 900.0, (SIZE_PX - TOP_PX - MARGIN_PX) / 900.0)  # px per metre
    middle_row = TOP_PX + (SIZE_PX - TOP_PX - MARGIN_PX) / 2

    def px(x_m, y_m):
        return int(round(SIZE_PX / 2 + x_m * scale)), int(round(middle_row - y_m * scale))  # column, row

    (c0, r1), (c1, r0) = px(100, 100), px(300, 300)
    mask[:TOP_PX] = False  # the key's land swatch
    rows, cols = np.nonzero(mask)
    assert abs(cols.min() - c0) <= 2 and abs(cols.max() - c1) <= 2
    assert abs(rows.min() - r0) <= 2 and abs(rows.max() - r1) <= 2
    (lc0, lr1), (lc1, lr0) = px(175, 175), px(225, 225)
    lagoon = np.zeros_like(mask)
    lagoon[lr0 + 1:lr1, lc0 + 1:lc1] = True
    island = np.zeros_like(mask)
    island[r0:r1 + 1, c0:c1 + 1] = True
    assert mask[island & ~lagoon].mean() > 0.95  # filled (the shoreline's pixels are drawn over it)
    assert not mask[lagoon].any()
    picture = np.asarray(Image.open(rec / "map.png").convert("RGB"))
    assert (picture[lr0 + 3:lr1 - 2, lc0 + 3:lc1 - 2] == SEA).all()


def test_a_map_without_land_has_no_land_colours(tmp_path):
    rec = recording(tmp_path)
    write_map(rec, START)
    for colour in LAND_COLOURS.values():
        assert not land_mask(rec / "map.png", colour).any()


def test_the_map_colours_land_by_material(tmp_path):
    rec = recording(tmp_path, [ring(square(100, 100, 300, 300))], material="concrete")
    write_map(rec, START)
    assert land_mask(rec / "map.png", LAND_COLOURS["concrete"])[TOP_PX:].sum() > 10_000
    assert not land_mask(rec / "map.png", LAND_COLOURS["rock"])[TOP_PX:].any()


def test_the_birds_eye_view_outlines_the_shoreline_about_the_sensor(tmp_path):
    # the own ship at (-400, -400) heading north at t = 0; land 20..40 m east, -10..10 m north of it:
    # forward (north) is up, 4 px per metre, so its west face is the column 400 + 4 x 20 = 480
    rec = recording(tmp_path, [ring(square(-380, -410, -360, -390))])
    sweeps = rec / "lidar" / "sweeps"
    sweeps.mkdir(parents=True)
    np.savez(sweeps / "000000.npz", x=np.zeros(1, np.float32), y=np.zeros(1, np.float32),
             intensity=np.zeros(1, np.uint8), time=np.zeros(1))
    lidar = SimpleNamespace(rotation_hz=10.0, mount=SimpleNamespace(x_m=0.0, y_m=0.0, z_m=3.0, yaw_deg=0.0))
    scenario = SimpleNamespace(sensors=SimpleNamespace(lidar=lidar), start_time=START,
                               origin=SimpleNamespace(lat=LAT0, lon=LON0), land=("island",))
    assert write_bev(rec, scenario) == 1
    shore = land_mask(rec / "lidar" / "bev" / "000000.png", SHORE_COLOUR)
    shore[:40] = shore[700:] = False  # the time stamp's and the key's (antialiased) grey text
    rows_px, cols_px = np.nonzero(shore)
    assert abs(cols_px.min() - 480) <= 1 and abs(cols_px.max() - 560) <= 1
    assert abs(rows_px.min() - 360) <= 1 and abs(rows_px.max() - 440) <= 1
    assert shore[362:439, 482:559].sum() == 0  # an outline, not a fill


def test_the_map_frames_land_near_the_tracks_and_not_land_far_from_them(tmp_path):
    # the objects' box with its 50 m margin is -450..450 m; land within 150 m of it is framed
    near = recording(tmp_path / "near", [ring(square(500, 0, 560, 60))])
    far = recording(tmp_path / "far", [ring(square(1500, 0, 1560, 60))])
    for rec in (near, far):
        write_map(rec, START)
    in_map = land_mask(near / "map.png", LAND_COLOURS["rock"])
    in_map = in_map[TOP_PX:SIZE_PX - MARGIN_PX, MARGIN_PX:SIZE_PX - MARGIN_PX]
    scale = (SIZE_PX - 2 * MARGIN_PX) / 1010.0  # px per metre: the box grown to x = 560 m is 1010 m wide
    assert in_map.sum() > 0.8 * 60 * 60 * scale ** 2  # the whole island (its shoreline's pixels are drawn over it)
    assert not land_mask(far / "map.png", LAND_COLOURS["rock"])[TOP_PX:].any()

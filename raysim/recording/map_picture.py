"""``map.png``: the whole run from above, in the local frame (north up).

Own-ship track (blue), other ships' tracks (orange, with their names), fixed objects as discs of
their beam (bergs white, buoys yellow, other structures grey), tracks sampled every 1 s, a
scale bar and the own ship's start and end. Land (the recording's ``land.geojson``) is filled in
its material's colour under the tracks, with its shoreline; the map frames the tracks and the land
within :data:`LAND_REACH_M` of them. The top left says what it is and when (UTC start - end,
duration), a key at the top right names every marker. Drawn from ``truth.jsonl``, read line by line.
"""

from __future__ import annotations

import datetime as dt
import math
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw, ImageFont

from raysim.recording.jsonl import every, row_centre_xy, truth_epochs
from raysim.recording.land_picture import (LAND_COLOURS, LandOutline, clip_polygons, clip_shoreline, land_extent,
                                          read_land)
from raysim.recording.staging import atomic_path

__all__ = ["write_map"]

SIZE_PX = 1000
MARGIN_PX = 40
TOP_PX = 120  # band for the title, the time span and the key: nothing of the map is drawn under them
COLOURS = {"ownship": (60, 140, 255), "ship": (255, 140, 40), "iceberg": (235, 245, 255), "buoy": (255, 215, 0),
           "mesh": (150, 150, 150)}
SEA = (15, 40, 70)
TEXT = (220, 220, 220)
KEY_FILL = (8, 26, 48)
COAST = (200, 200, 180)  # the shoreline drawn round the land's fill
LAND_REACH_M = 150.0  # the map frames the tracks and the land within this distance of their box
FONT_PX = 13  # Pillow's bundled font (the same glyphs everywhere: the pictures stay byte-identical)


def _read_tracks(truth: Path, every_s: float = 1.0) -> dict:
    tracks: dict[int, dict] = {}
    for _, rows in truth_epochs(truth, every(every_s)):
        for row in rows:
            track = tracks.setdefault(row["id"], {"name": row["name"], "kind": row["kind"], "beam_m": row["beam_m"],
                                                  "xy": [], "t": []})
            track["xy"].append(row_centre_xy(row))
            track["t"].append(row["t"])
    for track in tracks.values():
        track["xy"] = np.array(track["xy"])
    return tracks


def _time_span(start_time: dt.datetime | None, t0_s: float, t1_s: float) -> str:
    """``2017-06-01 12:00:00 - 12:05:00 UTC (300 s)``; ``t = 0 - 300 s`` without a start time."""
    if start_time is None:
        return f"t = {t0_s:g} - {t1_s:g} s ({t1_s - t0_s:g} s)"
    start = start_time.astimezone(dt.timezone.utc) + dt.timedelta(seconds=t0_s)
    end = start + dt.timedelta(seconds=t1_s - t0_s)
    end_format = "%H:%M:%S" if end.date() == start.date() else "%Y-%m-%d %H:%M:%S"
    return f"{start:%Y-%m-%d %H:%M:%S} - {end.strftime(end_format)} UTC ({t1_s - t0_s:g} s)"


def _key(draw: ImageDraw.ImageDraw, font, materials: tuple[str, ...] = ()) -> None:
    """The key of the markers, top right: tracks with start and end circles, the fixed objects, the land."""
    rows = [("track", COLOURS["ownship"], "own ship's track (hollow: start, filled: end)"),
            ("track", COLOURS["ship"], "other ships' tracks, named at the end"),
            ("disc", COLOURS["iceberg"], "iceberg, a disc of its beam (drifting: a track)"),
            ("disc", COLOURS["buoy"], "buoy"),
            ("disc", COLOURS["mesh"], "other fixed object")]
    if materials:  # one row: a swatch per material
        swatches = [LAND_COLOURS.get(m, LAND_COLOURS["rock"]) for m in materials]
        rows.append(("land", swatches, "land: " + ", ".join(materials)))
    width, line = 330, 18
    left, top = SIZE_PX - width - 10, 10
    draw.rectangle([left, top, SIZE_PX - 10, top + 8 + line * len(rows)], fill=KEY_FILL, outline=(90, 110, 140))
    for k, (shape, colour, text) in enumerate(rows):
        y = top + 4 + k * line + line / 2
        if shape == "track":
            draw.line([(left + 12, y), (left + 36, y)], fill=colour, width=2)
            draw.ellipse([left + 6, y - 4, left + 14, y + 4], outline=colour)
            draw.ellipse([left + 34, y - 4, left + 42, y + 4], fill=colour)
        elif shape == "land":
            step = 32 / len(colour)
            for j, fill in enumerate(colour):
                draw.rectangle([left + 8 + j * step, y - 5, left + 8 + (j + 1) * step, y + 5], fill=fill)
            draw.rectangle([left + 8, y - 5, left + 40, y + 5], outline=COAST)
        else:
            draw.ellipse([left + 19, y - 5, left + 29, y + 5], fill=colour)
        draw.text((left + 50, y - 8), text, fill=TEXT, font=font)


def _draw_land(draw: ImageDraw.ImageDraw, land: list[LandOutline], px,
               area_m: tuple[float, float, float, float]) -> None:
    """Fill the land clipped to the map's area (``area_m``: x0, y0, x1, y1 in metres), holes as sea; the shoreline."""
    for outline in land:
        fill = LAND_COLOURS.get(outline.material, LAND_COLOURS["rock"])
        for part in clip_polygons(outline.polygon, *area_m):
            draw.polygon(px(np.asarray(part.exterior.coords)), fill=fill)
            for hole in part.interiors:
                draw.polygon(px(np.asarray(hole.coords)), fill=SEA)
    for outline in land:
        for line in clip_shoreline(outline.polygon, *area_m):
            draw.line(px(line), fill=COAST, width=1)


def write_map(recording: Path, start_time: dt.datetime | None = None) -> None:
    """Draw ``recording/map.png`` (1000 x 1000 pixels) from ``recording/truth.jsonl``.

    Parameters
    ----------
    recording : Path
        Recording directory.
    start_time : datetime.datetime, optional
        UTC of t = 0, for the picture's time span (without it the span is given in t).
    """
    recording = Path(recording)
    tracks = _read_tracks(recording / "truth.jsonl")
    xy = np.concatenate([t["xy"] for t in tracks.values()])
    land = read_land(recording)
    lo, hi = land_extent(land, xy.min(axis=0) - 50.0, xy.max(axis=0) + 50.0, LAND_REACH_M)
    width_px, height_px = SIZE_PX - 2 * MARGIN_PX, SIZE_PX - TOP_PX - MARGIN_PX  # the map's area below the band
    scale = min(width_px / float(hi[0] - lo[0]), height_px / float(hi[1] - lo[1]))  # px per metre
    centre = (lo + hi) / 2.0
    middle_y = TOP_PX + height_px / 2

    def px(p):
        p = np.atleast_2d(p)
        return [(SIZE_PX / 2 + (x - centre[0]) * scale, middle_y - (y - centre[1]) * scale) for x, y in p]

    image = Image.new("RGB", (SIZE_PX, SIZE_PX), SEA)
    draw = ImageDraw.Draw(image)
    font = ImageFont.load_default(size=FONT_PX)
    half_w_m, half_h_m = width_px / 2 / scale, height_px / 2 / scale
    _draw_land(draw, land, px, (centre[0] - half_w_m, centre[1] - half_h_m, centre[0] + half_w_m, centre[1] + half_h_m))
    for track in sorted(tracks.values(), key=lambda t: t["kind"] == "ownship"):  # own ship on top
        colour = COLOURS.get(track["kind"], (150, 150, 150))
        points = px(track["xy"])
        moving = np.ptp(track["xy"], axis=0).max() > 1.0
        if moving:
            draw.line(points, fill=colour, width=3 if track["kind"] == "ownship" else 2)
            draw.ellipse([points[0][0] - 4, points[0][1] - 4, points[0][0] + 4, points[0][1] + 4], outline=colour)
            draw.ellipse([points[-1][0] - 4, points[-1][1] - 4, points[-1][0] + 4, points[-1][1] + 4], fill=colour)
            draw.text((points[-1][0] + 6, points[-1][1] - 8), track["name"], fill=colour, font=font)
        else:
            r = max(2.0, track["beam_m"] / 2.0 * scale)
            x, y = points[0]
            draw.ellipse([x - r, y - r, x + r, y + r], fill=colour)
    # scale bar: a round number of metres near a fifth of the picture
    target = width_px / scale / 5.0
    bar = 10 ** math.floor(math.log10(target))
    bar *= 5 if target / bar >= 5 else 2 if target / bar >= 2 else 1
    y0 = SIZE_PX - MARGIN_PX / 2
    draw.line([(MARGIN_PX, y0), (MARGIN_PX + bar * scale, y0)], fill=(255, 255, 255), width=3)
    draw.text((MARGIN_PX, y0 - 18), f"{bar:g} m", fill=(255, 255, 255), font=font)
    times = [t for track in tracks.values() for t in (track["t"][0], track["t"][-1])]
    draw.text((10, 10), "The whole run from above, north up (truth)", fill=TEXT, font=font)
    draw.text((10, 28), _time_span(start_time, min(times), max(times)), fill=TEXT, font=font)
    _key(draw, font, tuple(dict.fromkeys(o.material for o in land)))
    with atomic_path(recording / "map.png") as tmp:
        image.save(tmp, format="PNG")

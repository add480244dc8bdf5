"""``lidar/bev/NNNNNN.png``: bird's-eye pictures of LiDAR sweeps with the truth outlines.

One picture per second of scenario (every ``rotation_hz``-th sweep, named after it), 800 x 800
pixels for +-100 m around the sensor (the HDL-32E's range), sensor frame with x (forward) up:
points coloured by intensity (dark blue 0 to yellow 255), each object's truth box (length x beam at
its truth pose at the sweep's first point, in the own ship's level frame) outlined in red, the
chart's shoreline (the recording's ``land.geojson``) in grey: land's own points are drawn like any
other, and on a sloping shore they lie inland of the line. The picture says what it shows: the
sweep's time (UTC and t) top left, a 20 m scale bar bottom left, a key (the intensity colour ramp,
the truth box, the shoreline when there is land) bottom right.
"""

from __future__ import annotations

import datetime as dt
import math
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw, ImageFont

from groundfloor.frames import LocalFrame
from raysim.recording.jsonl import row_centre_xy, truth_epochs
from raysim.recording.land_picture import LandOutline, clip_shoreline, read_land
from raysim.recording.npz import read_npz
from raysim.recording.staging import atomic_path

__all__ = ["write_bev"]

SIZE_PX = 800
HALF_RANGE_M = 100.0
SCALE_BAR_M = 20.0
BOX_COLOUR = (255, 40, 40)
SHORE_COLOUR = (150, 150, 150)
TEXT = (210, 210, 210)
KEY_FILL = (24, 24, 24)  # not black: a point under the key still shows as drawn
FONT_PX = 13  # Pillow's bundled font (the same glyphs everywhere: the pictures stay byte-identical)


def _colour(intensity: np.ndarray) -> np.ndarray:
    """(N, 3) uint8: dark blue (0) through green to yellow (255)."""
    v = np.clip(intensity.astype(np.float32) / 255.0, 0.0, 1.0) ** 0.5
    return np.stack([255 * v, 80 + 175 * v, 200 * (1 - v) + 30], axis=1).astype(np.uint8)


def _annotate(draw: ImageDraw.ImageDraw, time_s: float, start_time: dt.datetime, land: bool = False) -> None:
    """Time (top left), a :data:`SCALE_BAR_M` scale bar (bottom left), the key (bottom right).

    The key names the shoreline's line when ``land``.
    """
    font = ImageFont.load_default(size=FONT_PX)
    utc = start_time.astimezone(dt.timezone.utc) + dt.timedelta(seconds=time_s)
    stamp = utc.strftime("%Y-%m-%d %H:%M:%S.") + f"{utc.microsecond // 100_000} UTC"
    draw.text((6, 6), f"{stamp}, t = {time_s:.1f} s (sweep start)", fill=TEXT, font=font)
    draw.text((6, 22), f"LiDAR from above, +-{HALF_RANGE_M:g} m, forward up", fill=TEXT, font=font)
    scale = SIZE_PX / (2 * HALF_RANGE_M)
    x0, y0 = 12, SIZE_PX - 14
    x1 = x0 + SCALE_BAR_M * scale
    draw.line([(x0, y0), (x1, y0)], fill=TEXT, width=3)
    draw.line([(x0, y0 - 5), (x0, y0 + 3)], fill=TEXT, width=1)
    draw.line([(x1, y0 - 5), (x1, y0 + 3)], fill=TEXT, width=1)
    draw.text((x0, y0 - 20), f"{SCALE_BAR_M:g} m", fill=TEXT, font=font)
    # key: the intensity ramp and the truth box
    left, top, ramp_px = SIZE_PX - 196, SIZE_PX - (84 if land else 66), 128
    draw.rectangle([left - 6, top - 6, SIZE_PX - 6, SIZE_PX - 6], fill=KEY_FILL, outline=(90, 90, 90))
    ramp = _colour(np.arange(256)[np.linspace(0, 255, ramp_px).round().astype(int)])
    for k, colour in enumerate(ramp):
        draw.line([(left + k, top), (left + k, top + 9)], fill=tuple(int(c) for c in colour))
    draw.text((left + ramp_px + 6, top - 2), "intensity", fill=TEXT, font=font)
    draw.text((left, top + 11), "0", fill=TEXT, font=font)
    draw.text((left + ramp_px - draw.textlength("255", font=font), top + 11), "255", fill=TEXT, font=font)
    draw.rectangle([left, top + 33, left + 18, top + 43], outline=BOX_COLOUR)
    draw.text((left + 26, top + 30), "truth box (length x beam)", fill=TEXT, font=font)
    if land:
        draw.line([(left, top + 56), (left + 18, top + 56)], fill=SHORE_COLOUR, width=1)
        draw.text((left + 26, top + 48), "shoreline (chart)", fill=TEXT, font=font)


def _sensor_pixels(own: dict, mount, scale: float):
    """A function from world (x, y) arrays, metres, to picture (column, row) arrays for the sensor at ``own``'s pose."""
    psi = math.radians(90.0 - own["heading_deg"]) + math.radians(mount.yaw_deg)  # sensor x in the world
    c, s = math.cos(psi), math.sin(psi)
    ox = own["x"] + mount.x_m * c - mount.y_m * s
    oy = own["y"] + mount.x_m * s + mount.y_m * c

    def to_px(wx, wy):
        sx = (wx - ox) * c + (wy - oy) * s
        sy = -(wx - ox) * s + (wy - oy) * c
        return SIZE_PX / 2 - sy * scale, SIZE_PX / 2 - sx * scale

    return to_px


def _draw_boxes(draw: ImageDraw.ImageDraw, rows: list[dict], to_px) -> None:
    """Every object's truth box (length x beam about its centre, at its truth heading) but the own ship's."""
    for r in rows:
        if r["kind"] == "ownship":
            continue
        a = math.radians(90.0 - r["heading_deg"])
        cx, cy = row_centre_xy(r)
        corners = []
        for u, v in ((1, 1), (1, -1), (-1, -1), (-1, 1)):
            wx = cx + u * r["length_m"] / 2 * math.cos(a) - v * r["beam_m"] / 2 * math.sin(a)
            wy = cy + u * r["length_m"] / 2 * math.sin(a) + v * r["beam_m"] / 2 * math.cos(a)
            corners.append(to_px(wx, wy))
        draw.polygon(corners, outline=BOX_COLOUR)


def _draw_shoreline(draw: ImageDraw.ImageDraw, land: list[LandOutline], own: dict, to_px) -> None:
    """The shoreline within reach of the picture (a square of 1.5 x its diagonal about the own ship)."""
    reach_m = 1.5 * math.sqrt(2.0) * HALF_RANGE_M
    x, y = own["x"], own["y"]
    for outline in land:
        for line in clip_shoreline(outline.polygon, x - reach_m, y - reach_m, x + reach_m, y + reach_m):
            cols, rows = to_px(line[:, 0], line[:, 1])
            draw.line(list(zip(cols.tolist(), rows.tolist())), fill=SHORE_COLOUR, width=1)


def write_bev(recording: Path, scenario) -> int:
    """Draw the bird's-eye pictures of ``recording``; returns how many."""
    recording = Path(recording)
    sweeps = sorted((recording / "lidar" / "sweeps").glob("*.npz"))
    every = max(1, int(round(scenario.sensors.lidar.rotation_hz)))
    chosen = sweeps[::every]
    if not chosen:
        return 0
    starts = {}
    for path in chosen:
        times = read_npz(path)["time"]
        starts[path] = round(float(times.min()) * 10.0) / 10.0 if times.size else 0.0
    wanted = set(starts.values())
    truth = dict(truth_epochs(recording / "truth.jsonl", wanted.__contains__))
    mount = scenario.sensors.lidar.mount
    folder = recording / "lidar" / "bev"
    folder.mkdir(parents=True, exist_ok=True)
    scale = SIZE_PX / (2 * HALF_RANGE_M)
    land = read_land(recording, LocalFrame(scenario.origin.lat, scenario.origin.lon)) if scenario.land else []
    for path in chosen:
        sweep = read_npz(path)
        x, y, intensity = sweep["x"], sweep["y"], sweep["intensity"]
        image = np.zeros((SIZE_PX, SIZE_PX, 3), dtype=np.uint8)
        col = np.floor(SIZE_PX / 2 - y * scale).astype(np.int64)  # y (left) to the left
        row = np.floor(SIZE_PX / 2 - x * scale).astype(np.int64)  # x (forward) up
        ok = (col >= 0) & (col < SIZE_PX) & (row >= 0) & (row < SIZE_PX)
        order = np.argsort(intensity[ok], kind="stable")  # brightest drawn last
        image[row[ok][order], col[ok][order]] = _colour(intensity[ok][order])
        picture = Image.fromarray(image)
        draw = ImageDraw.Draw(picture)
        own = next((r for r in truth.get(starts[path], []) if r["kind"] == "ownship"), None)
        if own is not None:
            to_px = _sensor_pixels(own, mount, scale)
            _draw_shoreline(draw, land, own, to_px)
            _draw_boxes(draw, truth.get(starts[path], []), to_px)
        _annotate(draw, starts[path], scenario.start_time, bool(land))
        with atomic_path(folder / f"{path.stem}.png") as tmp:
            picture.save(tmp, format="PNG")
    return len(chosen)

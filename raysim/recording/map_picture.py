"""``map.png``: the whole run from above, in the local frame (north up).

Own-ship track (blue), other ships' tracks (orange, with their names), fixed objects as discs of
their beam (bergs white, buoys yellow, other structures grey), a 1 s tick spacing on tracks, a
scale bar and the own ship's start and end. Drawn from ``truth.jsonl``, read line by line.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw

from raysim.recording.jsonl import every, truth_epochs
from raysim.recording.staging import atomic_path

__all__ = ["write_map"]

SIZE_PX = 1000
MARGIN_PX = 40
COLOURS = {"ownship": (60, 140, 255), "ship": (255, 140, 40), "iceberg": (235, 245, 255), "buoy": (255, 215, 0),
           "mesh": (150, 150, 150)}


def _read_tracks(truth: Path, every_s: float = 1.0) -> dict:
    tracks: dict[int, dict] = {}
    for _, rows in truth_epochs(truth, every(every_s)):
        for row in rows:
            track = tracks.setdefault(row["id"], {"name": row["name"], "kind": row["kind"], "beam_m": row["beam_m"],
                                                  "xy": []})
            track["xy"].append((row["x"], row["y"]))
    for track in tracks.values():
        track["xy"] = np.array(track["xy"])
    return tracks


def write_map(recording: Path) -> None:
    """Draw ``recording/map.png`` from ``recording/truth.jsonl``."""
    recording = Path(recording)
    tracks = _read_tracks(recording / "truth.jsonl")
    xy = np.concatenate([t["xy"] for t in tracks.values()])
    lo, hi = xy.min(axis=0) - 50.0, xy.max(axis=0) + 50.0
    span = float(max(hi - lo))
    scale = (SIZE_PX - 2 * MARGIN_PX) / span  # px per metre
    centre = (lo + hi) / 2.0

    def px(p):
        p = np.atleast_2d(p)
        return [(SIZE_PX / 2 + (x - centre[0]) * scale, SIZE_PX / 2 - (y - centre[1]) * scale) for x, y in p]

    image = Image.new("RGB", (SIZE_PX, SIZE_PX), (15, 40, 70))
    draw = ImageDraw.Draw(image)
    for track in sorted(tracks.values(), key=lambda t: t["kind"] == "ownship"):  # own ship on top
        colour = COLOURS.get(track["kind"], (150, 150, 150))
        points = px(track["xy"])
        moving = np.ptp(track["xy"], axis=0).max() > 1.0
        if moving:
            draw.line(points, fill=colour, width=3 if track["kind"] == "ownship" else 2)
            draw.ellipse([points[0][0] - 4, points[0][1] - 4, points[0][0] + 4, points[0][1] + 4], outline=colour)
            draw.ellipse([points[-1][0] - 4, points[-1][1] - 4, points[-1][0] + 4, points[-1][1] + 4], fill=colour)
            draw.text((points[-1][0] + 6, points[-1][1] - 6), track["name"], fill=colour)
        else:
            r = max(2.0, track["beam_m"] / 2.0 * scale)
            x, y = points[0]
            draw.ellipse([x - r, y - r, x + r, y + r], fill=colour)
    # scale bar: a round number of metres near a fifth of the picture
    target = span / 5.0
    bar = 10 ** math.floor(math.log10(target))
    bar *= 5 if target / bar >= 5 else 2 if target / bar >= 2 else 1
    y0 = SIZE_PX - MARGIN_PX / 2
    draw.line([(MARGIN_PX, y0), (MARGIN_PX + bar * scale, y0)], fill=(255, 255, 255), width=3)
    draw.text((MARGIN_PX, y0 - 16), f"{bar:g} m", fill=(255, 255, 255))
    draw.text((10, 10), "N up; own ship blue, ships orange, bergs white, buoys yellow", fill=(220, 220, 220))
    with atomic_path(recording / "map.png") as tmp:
        image.save(tmp, format="PNG")

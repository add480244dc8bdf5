"""Plan position indicator (PPI) pictures of radar sweeps, as a navigator's display shows them.

North-up: each spoke is drawn at its true bearing (the own ship's heading at that spoke plus
the antenna azimuth), the own ship at the centre, range rings at quarters of the range scale,
a heading line, video levels 0..15 as phosphor green on black.
"""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw

from raysim.recording.staging import atomic_path

SIZE_PX = 800


#: phosphor green: video level 0..15 -> RGB
PALETTE = np.array([[40 * v, 40 + 215 * v, 20 + 60 * v] for v in np.arange(16) / 15.0]).astype(np.uint8)
BEARING_BINS = 7200  # 0.05 deg: finer than the finest spoke spacing drawn (8192 spokes: 0.044 deg ~ one bin)


@lru_cache(maxsize=4)
def _pixel_geometry(size_px: int, samples: int, range_scale_m: float):
    """Per pixel (flattened): bearing bin, sample index, inside the range scale (cached per display)."""
    half = size_px / 2.0
    y, x = np.mgrid[0:size_px, 0:size_px]
    dx, dy = x - half + 0.5, half - y - 0.5
    radius = np.hypot(dx, dy) / half * range_scale_m
    bearing = np.degrees(np.arctan2(dx, dy)) % 360.0
    bins = (np.floor(bearing / 360.0 * BEARING_BINS).astype(np.int64) % BEARING_BINS).ravel()
    range_m = np.arange(samples) * (range_scale_m / (samples - 1))
    sample = np.clip(np.searchsorted(range_m, radius), 0, samples - 1).ravel()
    inside = (radius <= range_scale_m).ravel()
    return bins, sample, inside


def ppi_image(echo: np.ndarray, azimuth_deg: np.ndarray, heading_deg: np.ndarray, range_m: np.ndarray,
              size_px: int = SIZE_PX) -> Image.Image:
    """North-up PPI of one sweep.

    Parameters
    ----------
    echo : (S, N) uint8
        Video levels 0..15.
    azimuth_deg, heading_deg : (S,) float
        Antenna azimuth from the bow and own-ship heading of each spoke, degrees.
    range_m : (N,) float
        Range of each sample (first at the antenna, last at the range scale, evenly spaced).
    """
    spokes, samples = echo.shape
    half = size_px / 2.0
    bins, sample, inside = _pixel_geometry(size_px, samples, float(range_m[-1]))
    # the spoke whose true bearing is nearest (at or after) each bearing bin's centre
    true = (np.asarray(heading_deg, dtype=float) + azimuth_deg) % 360.0
    order = np.argsort(true, kind="stable")
    centres = (np.arange(BEARING_BINS) + 0.5) * (360.0 / BEARING_BINS)
    spoke_of_bin = order[np.searchsorted(true[order], centres) % spokes]
    level = np.where(inside, echo[spoke_of_bin[bins], sample], 0)
    rgb = PALETTE[level]
    rgb[~inside] = 0
    image = Image.fromarray(rgb.reshape(size_px, size_px, 3))
    draw = ImageDraw.Draw(image)
    for quarter in (1, 2, 3, 4):
        r = half * quarter / 4
        draw.ellipse([half - r, half - r, half + r, half + r], outline=(70, 110, 70))
        draw.text((half + 4, half - r + 2), f"{range_m[-1] * quarter / 4 / 1852:.2f} NM", fill=(120, 170, 120))
    h = np.radians(heading_deg[0])
    draw.line([half, half, half + half * np.sin(h), half - half * np.cos(h)], fill=(200, 200, 200))
    draw.text((6, 6), "N up", fill=(160, 200, 160))
    return image


def write_ppi(path: Path, sweep: dict[str, np.ndarray]) -> None:
    """Write the PPI picture of a sweep (the NPZ arrays) as PNG, atomically."""
    image = ppi_image(sweep["echo"], sweep["azimuth_deg"], sweep["heading_deg"], sweep["range_m"])
    with atomic_path(Path(path)) as tmp:
        image.save(tmp, format="PNG", optimize=False, compress_level=3)

"""Plan position indicator (PPI) pictures of radar sweeps, as a navigator's display shows them.

North-up: each spoke is drawn at its true bearing (the own ship's heading at that spoke plus
the antenna azimuth), the own ship at the centre, range rings at quarters of the range scale,
a heading line, video levels 0..15 as phosphor green on black. The corners outside the
display say what a navigator reads off the set: heading, time of the revolution, range scale
and ring spacing, receiver settings (gain, sea and rain control).
"""

from __future__ import annotations

import datetime as dt
import threading
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw, ImageFont

from groundfloor.units import METRES_PER_NM
from raysim.recording.staging import atomic_path

SIZE_PX = 800


#: phosphor green: video level 0..15 -> RGB
PALETTE = np.array([[40 * v, 40 + 215 * v, 20 + 60 * v] for v in np.arange(16) / 15.0]).astype(np.uint8)
BEARING_BINS = 7200  # 0.05 deg: finer than the finest spoke spacing drawn (8192 spokes: 0.044 deg ~ one bin)
FONT_PX = 13  # Pillow's bundled font (the same glyphs everywhere: the pictures stay byte-identical)
TEXT = (170, 215, 170)
RING = (70, 110, 70)
RING_LABEL = (120, 170, 120)
HEADING_LINE = (200, 200, 200)
LINE_PX = 16
#: the picture is a palette PNG: 16 video levels, black outside the display, then the annotation colours
#: (a quarter of the bytes of RGB to encode; every viewer and ROS image decoder reads palette PNGs)
OUTSIDE, TEXT_INK, RING_INK, RING_LABEL_INK, HEADING_INK = range(16, 21)
IMAGE_PALETTE = np.concatenate([PALETTE, np.array([(0, 0, 0), TEXT, RING, RING_LABEL, HEADING_LINE], np.uint8)])


@dataclass(frozen=True)
class PpiLabels:
    """What the corners of a PPI say beside the picture's own arrays (heading, time, range).

    Attributes
    ----------
    start_time : datetime.datetime or None
        UTC of the scenario's t = 0 (the sweep's times count from it).
    gain_db : float or None
        Receiver gain re. the default setting, dB.
    sea_clutter_control_db : float or None
        Sea control (STC) at 100 m, dB; 0 = off.
    rain_clutter_control_m : float or None
        Rain control (FTC) time constant, m; 0 = off.
    """

    start_time: dt.datetime | None = None
    gain_db: float | None = None
    sea_clutter_control_db: float | None = None
    rain_clutter_control_m: float | None = None

    @classmethod
    def from_scenario(cls, scenario) -> "PpiLabels":
        """The labels of a scenario's ``start_time`` and ``sensors.radar`` receiver settings."""
        cfg = scenario.sensors.radar
        return cls(scenario.start_time, cfg.gain_db, cfg.sea_clutter_control_db, cfg.rain_clutter_control_m)

    def receiver_lines(self) -> list[str]:
        """``gain +0 dB``, ``sea (STC) 20 dB``, ``rain (FTC) off``: the settings that are known."""
        lines = []
        if self.gain_db is not None:
            lines.append(f"gain {self.gain_db:+g} dB")
        sea, rain = self.sea_clutter_control_db, self.rain_clutter_control_m
        if sea is not None:
            lines.append(f"sea (STC) {sea:g} dB" if sea else "sea (STC) off")
        if rain is not None:
            lines.append(f"rain (FTC) {rain:g} m" if rain else "rain (FTC) off")
        return lines


def _nm(metres: float) -> str:
    """Nautical miles, as few digits as exact to 1/1000 NM: ``1.5``, ``0.375``, ``0.25``."""
    return f"{round(metres / METRES_PER_NM, 3):g}"


_FONTS = threading.local()
#: Index no picture uses: the unpainted pixels of an overlay's canvas (:func:`_overlay`).
BLANK_INK = 255


def _font() -> ImageFont.FreeTypeFont | ImageFont.ImageFont:
    """Pillow's bundled font at FONT_PX, loaded once per thread (a FreeType face is not shared across threads)."""
    font = getattr(_FONTS, "font", None)
    if font is None:
        font = _FONTS.font = ImageFont.load_default(size=FONT_PX)
    return font


def _corner_text(draw: ImageDraw.ImageDraw, size_px: int, corner: str, lines: list[str], skip: int = 0) -> None:
    """Write ``lines`` into ``corner`` (``"tl"``, ``"tr"``, ``"bl"``, ``"br"``), outside the display circle.

    The first ``skip`` lines are left out (their places kept): a top corner's first lines drawn elsewhere.
    """
    font = _font()
    top = corner[0] == "t"
    for k, line in enumerate(lines):
        if k < skip:
            continue
        y = 6 + k * LINE_PX if top else size_px - 6 - (len(lines) - k) * LINE_PX
        x = 6 if corner[1] == "l" else size_px - 6 - draw.textlength(line, font=font)
        draw.text((x, y), line, fill=TEXT_INK, font=font)


def _changing_corners(heading_deg: float, time_s: float | None, labels: PpiLabels) -> dict[str, list[str]]:
    """Corner texts that change every revolution: heading (top left) and time (top right)."""
    corners = {"tl": ["N up", f"HDG {heading_deg % 360.0:05.1f}\N{DEGREE SIGN}"]}
    if time_s is not None:
        when = [f"t = {time_s:.1f} s (first spoke)"]
        if labels.start_time is not None:
            utc = labels.start_time.astimezone(dt.timezone.utc) + dt.timedelta(seconds=time_s)
            when.insert(0, utc.strftime("%Y-%m-%d %H:%M:%S.") + f"{utc.microsecond // 100_000} UTC")
        corners["tr"] = when
    return corners


def _fixed_corners(range_m: np.ndarray, labels: PpiLabels) -> dict[str, list[str]]:
    """Corner texts fixed for a display: range scale and rings (bottom left), receiver settings (bottom right)."""
    scale_m = float(range_m[-1])
    return {"bl": [f"range {_nm(scale_m)} NM ({scale_m:g} m)", f"rings {_nm(scale_m / 4)} NM"],
            "br": labels.receiver_lines()}


def _annotate(draw: ImageDraw.ImageDraw, size_px: int, range_m: np.ndarray, heading_deg: float,
              time_s: float | None, labels: PpiLabels | None) -> None:
    """Corner texts: heading (top left), time (top right), range (bottom left), receiver (bottom right)."""
    labels = labels or PpiLabels()
    for corner, lines in {**_changing_corners(heading_deg, time_s, labels), **_fixed_corners(range_m, labels)}.items():
        _corner_text(draw, size_px, corner, lines)


def _pixel_geometry(size_px: int, samples: int, range_scale_m: float):
    """The pixels inside the range scale (flat indices) with their bearing bin and sample index (kept per display in
    the order :func:`_pixel_geometry_by_bin` puts them in, not in this one)."""
    half = size_px / 2.0
    y, x = np.mgrid[0:size_px, 0:size_px]
    dx, dy = x - half + 0.5, half - y - 0.5
    radius = (np.hypot(dx, dy) / half * range_scale_m).ravel()
    bearing = (np.degrees(np.arctan2(dx, dy)) % 360.0).ravel()
    inside = np.flatnonzero(radius <= range_scale_m)
    bins = np.floor(bearing[inside] / 360.0 * BEARING_BINS).astype(np.int64) % BEARING_BINS
    range_m = np.arange(samples) * (range_scale_m / (samples - 1))
    sample = np.clip(np.searchsorted(range_m, radius[inside]), 0, samples - 1)
    return inside, bins, sample


@lru_cache(maxsize=4)
def _pixel_geometry_by_bin(size_px: int, samples: int, range_scale_m: float):
    """:func:`_pixel_geometry` ordered by bearing bin, then sample: (P,) flat pixel indices, bins, samples.

    In this order a picture reads the sweep nearly in memory order (spoke by spoke, out along each) and scatters into
    the picture, which fits in cache: a third less time than reading in picture order.
    """
    inside, bins, sample = _pixel_geometry(size_px, samples, range_scale_m)
    order = np.argsort(bins * samples + sample, kind="stable")
    return inside[order], bins[order], sample[order]


def _overlay(size_px: int, paint) -> tuple[np.ndarray, np.ndarray]:
    """What ``paint(draw)`` draws on a palette picture: (Q,) flat indices of the painted pixels and (Q,) uint8 inks.

    Pillow draws shapes and text on a palette picture by setting pixels to the ink (no blending, text unsmoothed),
    so pasting these pixels gives the bytes drawing on the picture itself gives, in the same order of drawing.
    """
    canvas = Image.new("P", (size_px, size_px), BLANK_INK)
    paint(ImageDraw.Draw(canvas))
    ink = np.asarray(canvas).ravel()
    painted = np.flatnonzero(ink != BLANK_INK)
    return painted, ink[painted]


@lru_cache(maxsize=8)
def _rings(size_px: int, ring_labels: tuple[str, ...]) -> tuple[np.ndarray, np.ndarray]:
    """The range rings and their labels (one per quarter of the scale) as an :func:`_overlay` (cached per display)."""
    half = size_px / 2.0

    def paint(draw: ImageDraw.ImageDraw) -> None:
        for quarter, label in zip((1, 2, 3, 4), ring_labels):
            r = half * quarter / 4
            draw.ellipse([half - r, half - r, half + r, half + r], outline=RING_INK)
            draw.text((half + 4, half - r + 2), label, fill=RING_LABEL_INK)

    return _overlay(size_px, paint)


@lru_cache(maxsize=8)
def _fixed_text(size_px: int, top_left: str, bottom_left: tuple[str, ...],
                bottom_right: tuple[str, ...]) -> tuple[Image.Image, ...]:
    """The fixed corner texts (the top left's first line, the bottom corners) as a mask "1" picture and its bounding
    box, to paste TEXT_INK through (cached per display)."""
    painted, _ = _overlay(size_px, lambda draw: (_corner_text(draw, size_px, "tl", [top_left]),
                                                 _corner_text(draw, size_px, "bl", list(bottom_left)),
                                                 _corner_text(draw, size_px, "br", list(bottom_right))))
    mask = np.zeros(size_px * size_px, bool)
    mask[painted] = True
    picture = Image.fromarray(mask.reshape(size_px, size_px)).convert("1")
    box = picture.getbbox()
    return () if box is None else (picture.crop(box), box)


def ppi_image(echo: np.ndarray, azimuth_deg: np.ndarray, heading_deg: np.ndarray, range_m: np.ndarray,
              size_px: int = SIZE_PX, time_s: np.ndarray | None = None, labels: PpiLabels | None = None) -> Image.Image:
    """North-up PPI of one sweep, ``size_px`` x ``size_px`` pixels, with its corner texts.

    Drawn in this order: the video, the range rings and their labels, the heading line, the corner texts. What is
    fixed for a display (rings, labels, "N up", range and receiver texts) is drawn once and pasted (:func:`_overlay`): the
    same bytes as :func:`ppi_image_reference`, which draws everything every time.

    Parameters
    ----------
    echo : (S, N) uint8
        Video levels 0..15.
    azimuth_deg, heading_deg : (S,) float
        Antenna azimuth from the bow and own-ship heading of each spoke, degrees.
    range_m : (N,) float
        Range of each sample (first at the antenna, last at the range scale, evenly spaced).
    size_px : int
        Width and height of the picture, pixels.
    time_s : (S,) float, optional
        Time of each spoke, s since the scenario start (the first is written in a corner).
    labels : PpiLabels, optional
        UTC start and receiver settings for the corners (left out when not given).
    """
    spokes, samples = echo.shape
    half = size_px / 2.0
    labels = labels or PpiLabels()
    pixels, bins, sample = _pixel_geometry_by_bin(size_px, samples, float(range_m[-1]))
    index = (_spoke_of_bin(azimuth_deg, heading_deg, spokes) * samples).take(bins)
    index += sample
    level = np.full(size_px * size_px, OUTSIDE, np.uint8)
    level[pixels] = np.ascontiguousarray(echo, dtype=np.uint8).ravel().take(index)
    ring_pixels, ring_ink = _rings(size_px, tuple(f"{_nm(range_m[-1] * quarter / 4)} NM" for quarter in (1, 2, 3, 4)))
    level[ring_pixels] = ring_ink
    image = Image.fromarray(level.reshape(size_px, size_px))  # "L"; putpalette makes it "P"
    image.putpalette(_PALETTE_LIST)
    draw = ImageDraw.Draw(image)
    h = np.radians(heading_deg[0])
    draw.line([half, half, half + half * np.sin(h), half - half * np.cos(h)], fill=HEADING_INK)
    changing = _changing_corners(float(heading_deg[0]), None if time_s is None else float(time_s[0]), labels)
    for corner, lines in changing.items():  # the top left's first line ("N up") is the same every time: pasted
        _corner_text(draw, size_px, corner, lines, skip=1 if corner == "tl" else 0)
    fixed = _fixed_corners(range_m, labels)
    pasted = _fixed_text(size_px, changing["tl"][0], tuple(fixed["bl"]), tuple(fixed["br"]))
    if pasted:
        image.paste(TEXT_INK, pasted[1], pasted[0])
    return image


_PALETTE_LIST = IMAGE_PALETTE.ravel().tolist()


def _spoke_of_bin(azimuth_deg: np.ndarray, heading_deg: np.ndarray, spokes: int) -> np.ndarray:
    """(BEARING_BINS,) int64: the spoke whose true bearing is nearest (at or after) each bearing bin's centre."""
    true = (np.asarray(heading_deg, dtype=float) + azimuth_deg) % 360.0
    order = np.argsort(true, kind="stable")
    centres = (np.arange(BEARING_BINS) + 0.5) * (360.0 / BEARING_BINS)
    return order[np.searchsorted(true[order], centres) % spokes]


def ppi_image_reference(echo: np.ndarray, azimuth_deg: np.ndarray, heading_deg: np.ndarray, range_m: np.ndarray,
                        size_px: int = SIZE_PX, time_s: np.ndarray | None = None,
                        labels: PpiLabels | None = None) -> Image.Image:
    """:func:`ppi_image` drawn the plain way, everything every time (kept as the reference its tests compare to)."""
    spokes, samples = echo.shape
    half = size_px / 2.0
    flat_inside, bins, sample = _pixel_geometry(size_px, samples, float(range_m[-1]))
    spoke_of_bin = _spoke_of_bin(azimuth_deg, heading_deg, spokes)
    level = np.full(size_px * size_px, OUTSIDE, np.uint8)
    level[flat_inside] = np.ascontiguousarray(echo, dtype=np.uint8).ravel().take(spoke_of_bin[bins] * samples + sample)
    image = Image.fromarray(level.reshape(size_px, size_px))
    image.putpalette(IMAGE_PALETTE.ravel().tolist())
    draw = ImageDraw.Draw(image)
    for quarter in (1, 2, 3, 4):
        r = half * quarter / 4
        draw.ellipse([half - r, half - r, half + r, half + r], outline=RING_INK)
        draw.text((half + 4, half - r + 2), f"{_nm(range_m[-1] * quarter / 4)} NM", fill=RING_LABEL_INK)
    h = np.radians(heading_deg[0])
    draw.line([half, half, half + half * np.sin(h), half - half * np.cos(h)], fill=HEADING_INK)
    _annotate(draw, size_px, range_m, float(heading_deg[0]), None if time_s is None else float(time_s[0]), labels)
    return image


def write_ppi(path: Path, sweep: dict[str, np.ndarray], labels: PpiLabels | None = None) -> None:
    """Write the PPI picture of a sweep (the NPZ arrays, ``time`` optional) as PNG, atomically.

    ``labels`` (:meth:`PpiLabels.from_scenario`) adds the UTC time and the receiver settings.
    """
    image = ppi_image(sweep["echo"], sweep["azimuth_deg"], sweep["heading_deg"], sweep["range_m"],
                      time_s=sweep.get("time"), labels=labels)
    with atomic_path(Path(path)) as tmp:
        image.save(tmp, format="PNG", optimize=False, compress_level=3)

"""The radar's PPI picture (raysim.recording.ppi): the cached-overlay picture equals the one drawn the plain way."""
import datetime as dt

import numpy as np
import pytest

from raysim.recording import ppi

UTC = dt.timezone.utc
LABELS = [None, ppi.PpiLabels(), ppi.PpiLabels(dt.datetime(2026, 1, 2, 3, 4, 5, tzinfo=UTC), 3.0, 20.0, 0.0),
          ppi.PpiLabels(None, -5.0, 0.0, 150.0)]


def _sweep(rng: np.random.Generator, spokes: int, samples: int, scale_m: float, dtype=np.float32):
    """Random video with runs (echoes), antenna azimuths, a yawing heading and ranges to ``scale_m``."""
    echo = rng.integers(0, 16, (spokes, samples)).astype(np.uint8)
    echo[:, samples // 3: samples // 2] = rng.integers(0, 16, spokes)[:, None]
    azimuth = np.arange(spokes) * (360.0 / spokes)
    heading = rng.uniform(0.0, 360.0) + np.cumsum(rng.normal(0.0, 0.02, spokes))
    range_m = (np.arange(samples) * (scale_m / (samples - 1))).astype(dtype)
    return echo, azimuth, heading, range_m


@pytest.mark.parametrize("case", range(8))
def test_ppi_image_equals_the_plain_drawing(case):
    rng = np.random.default_rng(case)
    spokes, samples, scale_m = [(2048, 1024, 1852.0), (512, 256, 463.0), (1000, 700, 5556.0), (64, 32, 100.0)][case % 4]
    echo, azimuth, heading, range_m = _sweep(rng, spokes, samples, scale_m, [np.float32, np.float64][case % 2])
    size_px = [800, 600, 1200, 800][case % 4]
    time_s = None if case == 5 else np.full(spokes, rng.uniform(0.0, 5000.0))
    labels = LABELS[case % len(LABELS)]
    fast = ppi.ppi_image(echo, azimuth, heading, range_m, size_px=size_px, time_s=time_s, labels=labels)
    plain = ppi.ppi_image_reference(echo, azimuth, heading, range_m, size_px=size_px, time_s=time_s, labels=labels)
    assert fast.mode == plain.mode == "P"
    assert fast.getpalette() == plain.getpalette()
    assert np.array_equal(np.asarray(fast), np.asarray(plain))


@pytest.mark.parametrize("heading_deg", [0.0, 45.0, 135.0, 225.0, 315.0])
def test_ppi_overlays_keep_the_order_of_drawing_where_they_overlap(heading_deg):
    """A small picture: the corner texts run into the display, over the rings and the heading line."""
    rng = np.random.default_rng(7)
    echo, azimuth, _, range_m = _sweep(rng, 360, 100, 1852.0)
    heading = np.full(360, heading_deg)
    labels = LABELS[2]
    fast = ppi.ppi_image(echo, azimuth, heading, range_m, size_px=120, time_s=np.zeros(360), labels=labels)
    plain = ppi.ppi_image_reference(echo, azimuth, heading, range_m, size_px=120, time_s=np.zeros(360), labels=labels)
    picture = np.asarray(plain)
    rows, cols = np.nonzero(picture == ppi.TEXT_INK)
    assert np.any(np.hypot(rows + 0.5 - 60.0, cols + 0.5 - 60.0) < 50.0)  # text over the display, not only beside it
    assert np.count_nonzero(picture == ppi.HEADING_INK) > 0
    assert np.array_equal(np.asarray(fast), picture)


def test_ppi_reads_every_pixel_from_its_nearest_spoke_and_sample():
    """One bright cell per spoke at a known range: the pixel at that bearing and range shows it."""
    spokes, samples = 360, 200
    echo = np.zeros((spokes, samples), np.uint8)
    echo[90, 100] = 15  # 90 deg true with a heading of 0: east, half the range scale
    range_m = np.arange(samples) * (1000.0 / (samples - 1))
    picture = np.asarray(ppi.ppi_image(echo, np.arange(spokes) * 1.0, np.zeros(spokes), range_m, size_px=400))
    rows, cols = np.nonzero(picture == 15)
    assert rows.size > 0
    assert np.all(np.abs(rows - 199.5) <= 2) and np.all(np.abs(cols - 299.5) <= 2)

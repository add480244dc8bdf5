"""tdm.frontend.radar_extended: the interior of an echo longer than the range CFAR's window is detected through
the clutter map, so that an extended object is one plot at its middle, and rain around it does not join it."""

from __future__ import annotations

import numpy as np
import pytest

from tdm.frames import Mount
from tdm.frontend.radar import RadarFrontEndConfig, radar_detections
from tdm.frontend.radar_cfar import video_power
from tdm.frontend.radar_clutter import beam_integrated_power
from tdm.frontend.radar_extended import clutter_map_cells
from tests.tdm.test_frontend_radar import RANGE_M, SPOKES, static_track, sweep_with

#: A hull 109 m long along the beam (60 samples of 1.81 m), 500 spokes (88 deg) right of the bow, from sample 300.
HULL_SPOKE, HULL_FIRST, HULL_SAMPLES = 500, 300, 60
#: The front end with the clutter-map cells (on by default, RadarFrontEndConfig.clutter_map_detection) and without.
ON, OFF = RadarFrontEndConfig(clutter_map_detection=True), RadarFrontEndConfig(clutter_map_detection=False)


def _hull_sweep() -> dict[str, np.ndarray]:
    """A line of point echoes saturating the video (level 15) along range: a long ship end-on, or a long face."""
    return sweep_with(points=[(HULL_SPOKE, s, 15) for s in range(HULL_FIRST, HULL_FIRST + HULL_SAMPLES)])


def _ranges(det) -> np.ndarray:
    return np.hypot(det.position_m[:, 0], det.position_m[:, 1])


def test_a_long_saturated_echo_is_one_plot_at_its_middle_with_the_clutter_map_cells_and_not_without():
    sweep = _hull_sweep()
    middle_m = 0.5 * (RANGE_M[HULL_FIRST] + RANGE_M[HULL_FIRST + HULL_SAMPLES - 1])
    whole = radar_detections(sweep, static_track(), Mount(z_m=4.0), ON)
    assert len(whole) == 1
    assert _ranges(whole)[0] == pytest.approx(middle_m, abs=3.0)
    assert whole.length_m[0] == pytest.approx(RANGE_M[HULL_SAMPLES], abs=10.0)
    edges = radar_detections(sweep, static_track(), Mount(z_m=4.0), OFF)
    # the range CFAR alone masks the echo's interior: no plot lies within a quarter of the hull of its middle (here none
    # is kept at all: the edges it passes are under the size and beam-fill tests)
    assert np.all(np.abs(_ranges(edges) - middle_m) > 0.25 * RANGE_M[HULL_SAMPLES])


def test_clutter_map_cells_lie_on_the_echo_and_outside_the_blanking():
    sweep = _hull_sweep()
    config = RadarFrontEndConfig()
    integrated, g = beam_integrated_power(video_power(sweep["echo"], config), config)
    flat = clutter_map_cells(sweep["echo"], RANGE_M, integrated, g, config)
    spoke, sample = np.divmod(flat, sweep["echo"].shape[1])
    assert flat.size > HULL_SAMPLES and (sweep["echo"].reshape(-1)[flat] > 0).all()
    assert np.abs(spoke - HULL_SPOKE).max() < SPOKES * 8.0 / 360.0  # within the beam's smear
    assert sample.min() >= HULL_FIRST - 10 and sample.max() < HULL_FIRST + HULL_SAMPLES + 10
    blanked = RadarFrontEndConfig(blanking_m=float(RANGE_M[HULL_FIRST + HULL_SAMPLES + 20]))
    assert clutter_map_cells(sweep["echo"], RANGE_M, integrated, g, blanked).size == 0


def test_in_rain_the_clutter_map_cells_are_the_echo_over_the_rain_not_the_rain():
    # uniform rain 9 dB over level 1's start (level 4) over the whole annulus about the hull, in every spoke
    sweep = _hull_sweep()
    rain = sweep["echo"][:, 150:500]
    np.maximum(rain, 4, out=rain)
    config = RadarFrontEndConfig()
    integrated, g = beam_integrated_power(video_power(sweep["echo"], config), config)
    flat = clutter_map_cells(sweep["echo"], RANGE_M, integrated, g, config)
    assert flat.size > HULL_SAMPLES
    # every cell taken stands 10 dB (clutter_margin_db) over the rain in the beam-integrated power: none is rain alone
    spoke, _ = np.divmod(flat, sweep["echo"].shape[1])
    assert np.abs(spoke - HULL_SPOKE).max() < SPOKES * 8.0 / 360.0
    det = radar_detections(sweep, static_track(), Mount(z_m=4.0), ON)
    middle_m = 0.5 * (RANGE_M[HULL_FIRST] + RANGE_M[HULL_FIRST + HULL_SAMPLES - 1])
    assert len(det) == 1 and _ranges(det)[0] == pytest.approx(middle_m, abs=3.0)


def test_a_plot_counts_its_resolution_cells_in_beamwidths_by_range_resolutions():
    # a point echo covers a few resolution cells (the beam's and the point-spread's smear down to its weakest cell,
    # 3 dB a level): 1-3 at level 4, at most 8.5 saturated (level 15), where the radar tracker's weak limit starts to
    # rise (TdmConfig.radar_tracker); the 109 m hull along the beam about 109 / 2.5 = 44 range resolutions by up to
    # three beams (saturated, its echo smears over nearly three beamwidths down to its weakest cell)
    def detect(sweep):
        return radar_detections(sweep, static_track(), Mount(z_m=4.0), ON)

    weak, saturated = (detect(sweep_with(points=[(HULL_SPOKE, 400, level)])) for level in (4, 15))
    hull = detect(_hull_sweep())
    per_cell = (360.0 / SPOKES / ON.beam_az_deg) * (float(RANGE_M[1] - RANGE_M[0]) / ON.range_resolution_m)
    for det in (weak, saturated, hull):
        assert det.resolution_cells == pytest.approx(det.n_cells * per_cell, rel=1e-4)
    assert 1.0 <= weak.resolution_cells[0] <= 3.0
    assert 3.0 < saturated.resolution_cells[0] <= 8.5
    assert 44.0 <= hull.resolution_cells[0] <= 3.0 * 44.0

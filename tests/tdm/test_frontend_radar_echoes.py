"""Radar plots that are fragments of one echo (tdm.frontend.radar_echoes) and what a radar track on one reports."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tdm.frames import Mount
from tdm.frontend.radar import RadarFrontEndConfig, radar_detections
from tdm.frontend.radar_echoes import fragment_spread_m
from tdm.fusion_config import FusionConfig
from tdm.fusion_face import sensor_report
from tdm.tracker import Track
from tests.tdm.test_frontend_radar import RANGE_M, SPOKES, static_track, sweep_with

SPACING_M = 1.0
SPOKE_DEG = 0.5


def _plots(*boxes):
    """Cells of plots, each a box (first spoke, spokes, first sample, samples), about bearing 0; their arguments
    for fragment_spread_m."""
    d_az, sample, label, bearing = [], [], [], []
    for k, (s0, ns, m0, nm) in enumerate(boxes):
        spokes = np.arange(s0, s0 + ns) * SPOKE_DEG
        centre = spokes.mean()
        grid_s, grid_m = np.meshgrid(spokes, np.arange(m0, m0 + nm), indexing="ij")
        d_az.append((grid_s - centre).ravel())
        sample.append(grid_m.ravel())
        label.append(np.full(grid_s.size, k))
        bearing.append(centre)
    n = len(boxes)
    return (np.concatenate(d_az), np.concatenate(sample), np.concatenate(label), n, np.array(bearing),
            np.full(n, 500.0), SPACING_M, SPOKE_DEG)


def test_plots_along_one_spoke_within_the_gap_are_one_echo():
    # two 10 m plots on the same 10 spokes, 5 m apart along range: an echo 25 m long, 15 m beyond each;
    # a third 60 spokes (30 deg) away stands alone
    args = _plots((0, 10, 100, 10), (0, 10, 115, 10), (60, 10, 100, 10))
    spread = fragment_spread_m(*args, gap_m=10.0)
    assert spread == pytest.approx([15.0, 15.0, 0.0])


def test_plots_further_apart_than_the_gap_are_resolved_targets():
    args = _plots((0, 10, 100, 10), (0, 10, 125, 10))  # 15 m apart
    assert fragment_spread_m(*args, gap_m=10.0) == pytest.approx([0.0, 0.0])
    assert fragment_spread_m(*args, gap_m=20.0) == pytest.approx([25.0, 25.0])


def test_a_piece_far_weaker_than_its_echo_does_not_stretch_it_and_land_is_no_fragment():
    # a strong 10 m plot with a weak 10 m piece 5 m behind it (its range skirt, 30 dB down) and a third 5 m further
    args = _plots((0, 10, 100, 10), (0, 10, 115, 10), (0, 10, 130, 10))
    peak = np.array([1e5, 1e2, 1e5])  # linear power: the middle piece 30 dB under the others
    spread = fragment_spread_m(*args, gap_m=10.0, peak_power=peak)
    assert spread == pytest.approx([30.0, 30.0, 30.0])  # the strong two span 40 m; the weak piece lies inside that
    alone = fragment_spread_m(*_plots((0, 10, 100, 10), (0, 10, 115, 10)), gap_m=10.0, peak_power=peak[:2])
    assert alone == pytest.approx([0.0, 0.0])  # a skirt does not make its echo longer
    # the third plot on the chart's land: not a piece of the others' echo (nor they of its)
    spread = fragment_spread_m(*args, gap_m=10.0, joinable=np.array([True, True, False]))
    assert spread == pytest.approx([15.0, 15.0, 0.0])


def test_the_echo_reaches_across_the_beam_as_far_as_its_widest_fragment():
    # a 20-spoke (10 deg) plot and a 4-spoke one behind it on its middle spokes: the small one's echo is 8 deg wider
    args = _plots((0, 20, 100, 10), (8, 4, 112, 5))
    spread = fragment_spread_m(*args, gap_m=10.0)
    assert spread[1] == pytest.approx(max(17.0 - 5.0, 500.0 * math.radians(8.0)))
    assert spread[0] == pytest.approx(7.0)  # 17 m of echo in range against its own 10 m


def test_only_core_cells_measure_how_far_an_echo_reaches():
    # a sidelobe arc: the first plot's cells spread over 60 spokes at its range, but only its 10 middle spokes are core
    d_az, sample, label, n, bearing, rng, spacing, spoke = _plots((0, 60, 100, 3), (25, 10, 106, 10))
    core = (label == 1) | (np.abs(d_az) <= 2.5)
    with_arc = fragment_spread_m(d_az, sample, label, n, bearing, rng, spacing, spoke, 10.0)
    cored = fragment_spread_m(d_az, sample, label, n, bearing, rng, spacing, spoke, 10.0, core)
    assert with_arc[1] == pytest.approx(500.0 * math.radians(30.0 - 5.0))  # the arc's 30 deg at 500 m, less its own 5
    assert cored[1] == pytest.approx(max(116.0 - 100.0 - 10.0, 0.0), abs=1e-9)
    assert cored[0] == pytest.approx(16.0 - 3.0)


def test_the_front_end_gives_each_fragment_its_echo_and_a_lone_plot_none():
    config = RadarFrontEndConfig()
    # an echo of two parts along one set of spokes, level 0 between them for 4 samples; a lone echo elsewhere
    sweep = sweep_with([(500, 30, 300, 8, 12), (500, 30, 312, 8, 12), (1200, 30, 300, 8, 12)])
    det = radar_detections(sweep, static_track(), Mount(z_m=4.0), config)
    assert len(det) == 3
    order = np.argsort(det.range_m + 1e4 * (np.degrees(np.arctan2(det.position_m[:, 0], det.position_m[:, 1])) < 0))
    parts, lone = order[:2], order[2]
    spacing = float(RANGE_M[1] - RANGE_M[0])
    assert det.echo_spread_m[parts] == pytest.approx([12.0 * spacing] * 2, abs=1.5 * spacing)
    assert det.echo_spread_m[lone] == 0.0
    apart = radar_detections(sweep, static_track(), Mount(z_m=4.0), RadarFrontEndConfig(echo_gap_m=None))
    assert np.all(apart.echo_spread_m == 0.0)


def _radar_track(spread_m: float) -> Track:
    x = np.array([0.0, 500.0, 0.0, 0.0, 0.0, 100.0])
    return Track(1, "radar", x, np.diag([4.0, 4.0, 1.0, 1.0, 1e-4, 1e4]), 0.0, 0.0, 0.0, confirmed=True,
                 echo_spread_m=spread_m)


def test_a_radar_track_on_a_fragment_reports_its_echo_spread():
    config = FusionConfig()
    _, alone = sensor_report("radar", _radar_track(float("nan")), 0.0, np.zeros(2), config)
    _, fragment = sensor_report("radar", _radar_track(48.0), 0.0, np.zeros(2), config)
    np.testing.assert_allclose(fragment[:2, :2] - alone[:2, :2], 48.0 ** 2 / 12.0 * np.eye(2))
    _, none = sensor_report("radar", _radar_track(0.0), 0.0, np.zeros(2), config)
    np.testing.assert_allclose(none[:2, :2], alone[:2, :2])
    _, off = sensor_report("radar", _radar_track(48.0), 0.0, np.zeros(2),
                           FusionConfig(radar_track_fragment_covariance=False))
    np.testing.assert_allclose(off[:2, :2], alone[:2, :2])


def test_a_fused_target_takes_its_radar_fragments_spread_through_the_fusions_weights_only_when_asked():
    from tdm.fusion_consider import reported_covariance

    class Target:  # the members and descriptor reported_covariance reads
        members = {"radar": 1}
        descriptor = "unknown"

    track = _radar_track(48.0)
    x, p = track.x, track.p
    on = FusionConfig(consider_nav_bias=False, consider_radar_face=False, consider_radar_fragment=True)
    off = FusionConfig(consider_nav_bias=False, consider_radar_face=False)  # the default: not in the fused covariance
    live = {("radar", 1): track}
    with_spread = reported_covariance(Target(), x, p, x[None], p[None], live, np.zeros(2), set(), on)
    without = reported_covariance(Target(), x, p, x[None], p[None], live, np.zeros(2), set(), off)
    np.testing.assert_allclose(with_spread[:2, :2] - without[:2, :2], 48.0 ** 2 / 12.0 * np.eye(2))

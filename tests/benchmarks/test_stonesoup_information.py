"""What the Stone Soup comparison gives Stone Soup (benchmarks/stonesoup_trackers.py), on tiny synthetic cases.

Fast (not ``bench``): the AIS 4-D measurement carries SOG/COG into the state with our AIS
tracker's variances; the strength gate keeps weak radar plots from starting tracks while they
still update them; the closed-form transition model equals Stone Soup's combined one; a chunk
never holds two scans.
"""

from __future__ import annotations

import datetime as dt
import math

import numpy as np
import pytest

pytest.importorskip("stonesoup")

from benchmarks.stonesoup_trackers import (Context, NearlyConstantVelocity2D, Setting,  # noqa: E402
                                           StrengthGatedInitiator, _initiator, ais_detection, ais_velocity_cov,
                                           chunks, context_from, scan_detections, stamp)
from groundfloor.units import KNOT_MPS  # noqa: E402
from tdm.detections import AisReport, Detections  # noqa: E402
from tdm.pipeline import TdmConfig  # noqa: E402

CONFIG = TdmConfig()


def _ctx() -> Context:
    return context_from(CONFIG, {"lidar": 0.1, "radar": 2.5}, {"lidar": 1e-5, "radar": 1e-6}, 30.0)


def _report(sog_mps: float, cog_deg: float, t_s: float = 1.0) -> AisReport:
    return AisReport(time_s=t_s, mmsi=257000001, position_m=np.array([100.0, 200.0]), cog_deg=cog_deg,
                     sog_mps=sog_mps, heading_deg=math.nan, rot_deg_per_min=math.nan, msg_type=1)


def _radar_scan(strength_db: list[float], beam_fill: list[float], t_s: float = 1.0,
                east_m: float = 500.0) -> Detections:
    n = len(strength_db)
    dets = Detections.empty("radar", t_s)
    dets.time_s = np.full(n, t_s)
    dets.position_m = np.column_stack([np.full(n, east_m) + 100.0 * np.arange(n), np.zeros(n)])
    dets.position_cov_m2 = np.tile(np.eye(2) * 4.0, (n, 1, 1))
    dets.strength_db = np.array(strength_db, float)
    dets.beam_fill = np.array(beam_fill, float)
    return dets


def test_ais_report_is_a_4d_measurement_with_our_variances():
    """SOG 5 m/s towards 090: velocity (5, 0); variances SOG along, SOG^2 var(COG) across; position ours."""
    ctx = _ctx()
    det = ais_detection(_report(5.0, 90.0), ctx)
    assert det.measurement_model.mapping == (0, 1, 2, 3)
    np.testing.assert_allclose(np.asarray(det.state_vector, float).ravel(), [100.0, 5.0, 200.0, 0.0], atol=1e-9)
    cov = np.asarray(det.measurement_model.covar(), float)
    ais = CONFIG.ais_tracker
    assert cov[0, 0] == cov[2, 2] == ais.position_var_m2
    assert cov[1, 1] == pytest.approx(ais.sog_var_kn2 * KNOT_MPS ** 2)
    assert cov[3, 3] == pytest.approx(25.0 * ais.cog_var_deg2 * math.radians(1.0) ** 2)
    # north-east course: the Jacobian's covariance is symmetric and its trace is var_sog + sog^2 var_cog
    c = ais_velocity_cov(5.0, 45.0, 0.2, 0.01)
    assert c[0, 1] == pytest.approx(c[1, 0]) and np.trace(c) == pytest.approx(0.2 + 25.0 * 0.01)


def test_slow_ais_report_is_position_only():
    """Below our AIS tracker's COG speed the report measures the position only (as ours)."""
    det = ais_detection(_report(0.1, 90.0), _ctx())
    assert det.measurement_model.mapping == (0, 2)


def test_ais_velocity_reaches_the_state():
    """A track started from one AIS report has the report's velocity and the measurement's covariance."""
    ctx = _ctx()
    det = ais_detection(_report(5.0, 0.0), ctx)
    seed = StrengthGatedInitiator(prior_state=_prior(), measurement_model=None)
    (track,) = seed.initiate({det}, det.timestamp)
    np.testing.assert_allclose(np.asarray(track.state_vector, float).ravel(), [100.0, 0.0, 200.0, 5.0], atol=1e-9)
    assert track.covar[3, 3] == pytest.approx(CONFIG.ais_tracker.sog_var_kn2 * KNOT_MPS ** 2)


def _prior():
    from stonesoup.types.state import GaussianState

    return GaussianState(np.zeros((4, 1)), np.diag([0.0, 16.0, 0.0, 16.0]))


def test_weak_plot_cannot_start_a_track_a_strong_one_can():
    """Gate 13 dB, beam fill 0.5: only the 20 dB plot that fills the beam seeds; LiDAR always may."""
    seed = StrengthGatedInitiator(prior_state=_prior(), measurement_model=None, min_strength_db=13.0,
                                  min_beam_fill=0.5)
    weak, strong, spike = scan_detections(_radar_scan([10.0, 20.0, 20.0], [1.0, 1.0, 0.3]))
    assert seed.initiate({weak}, weak.timestamp) == set()
    assert seed.initiate({spike}, spike.timestamp) == set()
    assert len(seed.initiate({strong}, strong.timestamp)) == 1
    lidar = Detections.empty("lidar", 1.0)
    lidar.time_s, lidar.position_m, lidar.position_cov_m2 = np.array([1.0]), np.zeros((1, 2)), np.eye(2)[None]
    (cluster,) = scan_detections(lidar)
    assert len(seed.initiate({cluster}, cluster.timestamp)) == 1
    ungated = StrengthGatedInitiator(prior_state=_prior(), measurement_model=None)
    assert len(ungated.initiate({weak}, weak.timestamp)) == 1


def test_weak_plot_updates_a_track_a_strong_plot_started():
    """min_points 2: a strong plot starts a holding track, a weak plot a sweep later confirms it; weak alone never."""
    from stonesoup.models.transition.linear import ConstantVelocity
    from stonesoup.predictor.kalman import ExtendedKalmanPredictor
    from stonesoup.updater.kalman import ExtendedKalmanUpdater

    ctx = _ctx()
    setting = Setting(min_points=2, hold_periods=2.0, min_strength_db=13.0)
    predictor = ExtendedKalmanPredictor(NearlyConstantVelocity2D([ConstantVelocity(0.1)] * 2))
    updater = ExtendedKalmanUpdater(measurement_model=None)

    def run(strengths: tuple[float, float]) -> set:
        init = _initiator(setting, ctx, ("radar",), predictor, updater)
        tracks = set()
        for k, s in enumerate(strengths):
            (det,) = scan_detections(_radar_scan([s], [1.0], t_s=1.0 + 2.5 * k))
            tracks |= init.initiate({det}, det.timestamp)
        return tracks

    assert len(run((20.0, 10.0))) == 1
    assert run((10.0, 10.0)) == set()


def test_closed_form_transition_equals_stonesoup_combined_model():
    """F and Q of :class:`NearlyConstantVelocity2D` are those of two ``ConstantVelocity`` stacked."""
    from stonesoup.models.transition.linear import CombinedLinearGaussianTransitionModel, ConstantVelocity

    ours = NearlyConstantVelocity2D([ConstantVelocity(0.3)] * 2)
    theirs = CombinedLinearGaussianTransitionModel([ConstantVelocity(0.3)] * 2)
    step = dt.timedelta(seconds=1.7)
    np.testing.assert_allclose(ours.matrix(time_interval=step), theirs.matrix(time_interval=step))
    np.testing.assert_allclose(ours.covar(time_interval=step), theirs.covar(time_interval=step))


def test_a_chunk_never_holds_two_scans():
    """One object seen in two LiDAR scans 0.1 s apart: two chunks; a radar sweep's plots 0.1 s apart: one."""
    def lidar_scan(t_s: float) -> Detections:
        d = Detections.empty("lidar", t_s)
        d.time_s, d.position_m, d.position_cov_m2 = np.array([t_s]), np.zeros((1, 2)), np.eye(2)[None]
        return d

    radar = _radar_scan([20.0, 20.0], [1.0, 1.0], t_s=3.0)
    radar.time_s = np.array([3.0, 3.1])
    events = [(0.1, "lidar", lidar_scan(0.05)), (0.2, "lidar", lidar_scan(0.15)), (3.2, "radar", radar)]
    fed = chunks(events, ("lidar", "radar"), _ctx())
    assert [(sensor, len(dets)) for _, sensor, dets in fed] == [("lidar", 1), ("lidar", 1), ("radar", 2)]
    assert [t for t, _, _ in fed] == [0.05, 0.15, 3.1]
    assert fed[0][2][0].timestamp == stamp(0.05)

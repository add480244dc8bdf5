"""Stone Soup trackers for the comparison (benchmarks/stonesoup_compare.py): detections, components, runs.

What Stone Soup is given (the information our trackers use):

- **Positions** of LiDAR clusters and radar plots: a ``LinearGaussian`` on (east, north) of the
  state ``[east, v_east, north, v_north]`` whose covariance is the detection's own
  ``position_cov_m2`` (no floor added: our floors are our own tuning).
- **AIS kinematics**: a report with a speed over ground above our AIS tracker's
  :data:`tdm.ais_tracker.AIS_COG_MIN_SOG_MPS` and a course over ground is a 4-D measurement of the
  whole state (``LinearGaussian`` on dims 0-3): position with our AIS tracker's
  ``position_var_m2`` per axis, velocity ``SOG (sin COG, cos COG)`` with the covariance of our
  ``sog_var_kn2`` and ``cog_var_deg2`` carried through that map (first order,
  :func:`ais_velocity_cov`). Slower reports, or reports without COG, are positions only (our AIS
  tracker then uses no COG either, but still the SOG: a little information Stone Soup does not
  get). All variances are read from :class:`tdm.pipeline.TdmConfig`. Our AIS tracker also holds a Class
  A ship that reports itself at anchor or moored at speed 0 (:mod:`tdm.ais_tracker`); Stone Soup is not given
  the status, but none of the comparison's scenarios (busy_open_sea, crossing_silent_ship, rough_sea_rain) has
  such a ship, so neither tracker uses it there.
- **Plot strengths**: chosen as *seeding*: a radar plot may start a (holding) track only when its
  ``strength_db`` is at least ``min_strength_db`` and its ``beam_fill`` at least our radar
  tracker's ``min_beam_fill`` (:class:`StrengthGatedInitiator`), while every plot may update
  tracks. This is the nearest Stone Soup component analogue of our weighting (weak plots count
  half a hit, plots narrower than the beam are weak); ``min_strength_db`` is on the tuning grid
  (None: no gate, every plot seeds). LiDAR clusters and AIS reports carry no strength and
  always may seed.

Time: every detection keeps its own time. The detections of the tracker's sensors are sorted by
time and fed in chunks of one scan spanning at most :data:`CHUNK_S` (0.1 s LiDAR, 0.25 s radar:
a radar sweep lasts a revolution, 2.5 s at 24 rpm; fed whole, a JPDA mixture would join states
seconds apart, and a centralised tracker would predict backwards). Chunks end at their last
detection's time, so no prediction goes back in time. Stone Soup thus sees each radar plot at
most a chunk after it is measured, where ours takes a sweep when it ends: a small latency
advantage to Stone Soup.
"""

from __future__ import annotations

import datetime as dt
import math
import time
from dataclasses import dataclass, field

import numpy as np

from stonesoup.base import Property
from stonesoup.dataassociator.neighbour import GNNWith2DAssignment
from stonesoup.dataassociator.probability import JPDA, JPDAwithLBP
from stonesoup.deleter.time import UpdateTimeDeleter
from stonesoup.hypothesiser.distance import DistanceHypothesiser
from stonesoup.hypothesiser.probability import PDAHypothesiser
from stonesoup.initiator.simple import MultiMeasurementInitiator, SimpleMeasurementInitiator
from stonesoup.measures import Mahalanobis
from stonesoup.models.measurement.linear import LinearGaussian
from stonesoup.models.transition.linear import CombinedLinearGaussianTransitionModel, ConstantVelocity
from stonesoup.predictor.kalman import ExtendedKalmanPredictor
from stonesoup.tracker.simple import MultiTargetMixtureTracker, MultiTargetTracker
from stonesoup.types.array import CovarianceMatrix
from stonesoup.types.detection import Detection
from stonesoup.types.state import GaussianState
from stonesoup.updater.kalman import ExtendedKalmanUpdater

from groundfloor.units import KNOT_MPS
from tdm.detections import AisReport, Detections
from tdm.pipeline import TdmConfig
from tdm.ais_tracker import AIS_COG_MIN_SOG_MPS

#: Longest time span of one chunk of detections fed to a tracker, per sensor, s: one LiDAR revolution
#: at 10 Hz; a tenth of a radar revolution at 24 rpm (a target is in one chunk of a sweep); AIS
#: reports one by one.
CHUNK_S = {"lidar": 0.1, "radar": 0.25, "ais": 0.0}
#: Stone Soup trackers: name -> sensors whose detections it takes.
TRACKER_SENSORS = {"lidar": ("lidar",), "radar": ("radar",), "central": ("lidar", "radar"),
                   "central_ais": ("lidar", "radar", "ais")}
EPOCH = dt.datetime(2000, 1, 1)


def stamp(t_s: float) -> dt.datetime:
    """A Stone Soup timestamp ``t_s`` seconds after a fixed epoch."""
    return EPOCH + dt.timedelta(seconds=float(t_s))


@dataclass(frozen=True)
class Setting:
    """One point of the tuning grid for one Stone Soup tracker.

    Attributes
    ----------
    algorithm : str
        ``gnn`` (``GNNWith2DAssignment`` + ``MultiTargetTracker``) or ``jpda`` (``JPDA`` with
        ``PDAHypothesiser`` + ``MultiTargetMixtureTracker``; centralised trackers ``JPDAwithLBP``,
        the same marginals approximated by loopy belief propagation).
    q_m2_s3 : float
        Process-noise intensity of ``ConstantVelocity`` per axis, m^2/s^3.
    min_points : int
        Updates a holding track needs to be released as a track (``MultiMeasurementInitiator``).
    hold_periods : float
        A holding track not updated for this many revolutions of the tracker's slowest position
        sensor is deleted (``UpdateTimeDeleter`` inside the initiator).
    delete_s : float
        A track not updated for this long is deleted (``UpdateTimeDeleter``), s.
    min_strength_db : float or None
        Radar plots weaker than this may not start a track, dB (None: no gate).
    clutter_scale : float
        JPDA: the clutter densities are the estimates of :class:`Context` times this.
    prob_detect : float
        JPDA: detection probability of a target in a chunk of its sensor.
    """

    algorithm: str = "gnn"
    q_m2_s3: float = 0.1
    min_points: int = 3
    hold_periods: float = 2.0
    delete_s: float = 8.0
    min_strength_db: float | None = None
    clutter_scale: float = 1.0
    prob_detect: float = 0.9


@dataclass(frozen=True)
class Context:
    """Fixed inputs of every Stone Soup tracker, read from our configuration and the tuning recording.

    Attributes
    ----------
    missed_distance : float
        Mahalanobis gate of the GNN hypothesisers: sqrt of the chi-square(2) quantile of our
        ``gate_probability`` (-2 ln(1 - P), closed form for 2 degrees of freedom).
    gate_probability : float
        JPDA ``prob_gate`` (ours).
    prior_speed_sigma_mps : dict
        Per sensor, velocity standard deviation per axis of a new track, m/s (our ``init_speed_sigma_mps``).
    period_s : dict
        Per position sensor, one revolution, s.
    min_beam_fill : float or None
        Our radar tracker's ``min_beam_fill`` (the seeding gate with the strength).
    ais_position_var_m2, ais_sog_var_mps2, ais_cog_var_rad2 : float
        Our AIS tracker's variances (``AisTrackerConfig``), in m^2, (m/s)^2 and rad^2.
    clutter_density_per_m2 : dict
        Per position sensor, estimated clutter density, 1/m^2 (estimated on the tuning recording).
    ais_clutter_density : float
        AIS: clutter density in the 4-D measurement space, 1/(m^2 (m/s)^2).
    """

    missed_distance: float
    gate_probability: float
    prior_speed_sigma_mps: dict
    period_s: dict
    min_beam_fill: float | None
    ais_position_var_m2: float
    ais_sog_var_mps2: float
    ais_cog_var_rad2: float
    clutter_density_per_m2: dict = field(default_factory=dict)
    ais_clutter_density: float = 1e-12


def context_from(config: TdmConfig, period_s: dict, clutter_density_per_m2: dict, ais_velocity_box_mps: float) \
        -> Context:
    """The :class:`Context` of our configuration.

    Parameters
    ----------
    config : TdmConfig
        Our run configuration (trackers' gates, prior speed sigmas, AIS variances).
    period_s : dict
        ``lidar`` and ``radar`` revolution, s.
    clutter_density_per_m2 : dict
        ``lidar`` and ``radar`` clutter density estimates, 1/m^2.
    ais_velocity_box_mps : float
        Side of the velocity square over which AIS clutter would spread, m/s (AIS clutter
        density = the radar's over its area).
    """
    radar = config.radar_tracker
    ais = config.ais_tracker
    return Context(missed_distance=math.sqrt(-2.0 * math.log(1.0 - radar.gate_probability)),
                   gate_probability=radar.gate_probability,
                   prior_speed_sigma_mps={"lidar": config.lidar_tracker.init_speed_sigma_mps,
                                          "radar": radar.init_speed_sigma_mps},
                   period_s=dict(period_s), min_beam_fill=radar.min_beam_fill,
                   ais_position_var_m2=ais.position_var_m2, ais_sog_var_mps2=ais.sog_var_kn2 * KNOT_MPS ** 2,
                   ais_cog_var_rad2=ais.cog_var_deg2 * math.radians(1.0) ** 2,
                   clutter_density_per_m2=dict(clutter_density_per_m2),
                   ais_clutter_density=clutter_density_per_m2["radar"] / ais_velocity_box_mps ** 2)


# ---- detections ---------------------------------------------------------------------------------

def ais_velocity_cov(sog_mps: float, cog_deg: float, sog_var_mps2: float, cog_var_rad2: float) -> np.ndarray:
    """Covariance (2, 2) of (v_east, v_north) = SOG (sin COG, cos COG), to first order, (m/s)^2.

    Parameters
    ----------
    sog_mps : float
        Speed over ground, m/s.
    cog_deg : float
        Course over ground, compass degrees.
    sog_var_mps2 : float
        SOG variance, (m/s)^2.
    cog_var_rad2 : float
        COG variance, rad^2.
    """
    c = math.radians(cog_deg)
    jac = np.array([[math.sin(c), sog_mps * math.cos(c)], [math.cos(c), -sog_mps * math.sin(c)]])
    return jac @ np.diag([sog_var_mps2, cog_var_rad2]) @ jac.T


def ais_detection(report: AisReport, ctx: Context):
    """One AIS report as a Stone Soup ``Detection``: 4-D (position, velocity) when SOG and COG are usable."""
    var_p = ctx.ais_position_var_m2
    moving = math.isfinite(report.sog_mps) and report.sog_mps > AIS_COG_MIN_SOG_MPS and math.isfinite(report.cog_deg)
    meta = {"sensor": "ais", "mmsi": int(report.mmsi)}
    if not moving:
        model = LinearGaussian(ndim_state=4, mapping=(0, 2), noise_covar=np.eye(2) * var_p)
        return Detection(np.asarray(report.position_m, float).reshape(2, 1), timestamp=stamp(report.time_s),
                         measurement_model=model, metadata=meta)
    c = math.radians(report.cog_deg)
    v = report.sog_mps * np.array([math.sin(c), math.cos(c)])
    cov = np.zeros((4, 4))
    cov[0, 0] = cov[2, 2] = var_p
    cov[np.ix_((1, 3), (1, 3))] = ais_velocity_cov(report.sog_mps, report.cog_deg, ctx.ais_sog_var_mps2,
                                                  ctx.ais_cog_var_rad2)
    z = np.array([report.position_m[0], v[0], report.position_m[1], v[1]], float).reshape(4, 1)
    return Detection(z, timestamp=stamp(report.time_s), measurement_model=LinearGaussian(
        ndim_state=4, mapping=(0, 1, 2, 3), noise_covar=cov), metadata=meta)


def scan_detections(dets: Detections) -> list:
    """One LiDAR or radar scan as Stone Soup ``Detection`` s (own time, own covariance, strength in metadata)."""
    covs = 0.5 * (dets.position_cov_m2 + np.swapaxes(dets.position_cov_m2, 1, 2))
    out = []
    for j in range(len(dets)):
        meta = {"sensor": dets.sensor}
        if dets.strength_db is not None:
            meta["strength_db"] = float(dets.strength_db[j])
        if dets.beam_fill is not None:
            meta["beam_fill"] = float(dets.beam_fill[j])
        out.append(Detection(dets.position_m[j].reshape(2, 1), timestamp=stamp(dets.time_s[j]),
                             measurement_model=LinearGaussian(ndim_state=4, mapping=(0, 2), noise_covar=covs[j]),
                             metadata=meta))
    return out


def chunks(events: list, sensors: tuple, ctx: Context) -> list[tuple[float, str, list]]:
    """The detections of ``sensors`` in time order, in chunks of one scan spanning at most its sensor's :data:`CHUNK_S`.

    A chunk holds detections of one scan only (two detections of one object from consecutive
    scans never meet in a chunk), consecutive in time.

    Returns
    -------
    list of (t_s, sensor, detections)
        ``t_s``: the chunk's last detection time, s.
    """
    items = []
    for scan, (_, sensor, payload) in enumerate(events):
        if sensor not in sensors:
            continue
        if isinstance(payload, AisReport):
            items.append((float(payload.time_s), sensor, scan, ais_detection(payload, ctx)))
        else:
            items.extend((float(t), sensor, scan, d) for t, d in zip(payload.time_s, scan_detections(payload)))
    items.sort(key=lambda it: it[0])
    out: list[tuple[float, str, list]] = []
    start_s, start_scan = -math.inf, -1
    for t_s, sensor, scan, det in items:
        if out and scan == start_scan and t_s - start_s <= CHUNK_S[sensor]:
            out[-1] = (t_s, sensor, out[-1][2] + [det])
        else:
            start_s, start_scan = t_s, scan
            out.append((t_s, sensor, [det]))
    return out


# ---- components ---------------------------------------------------------------------------------

class NearlyConstantVelocity2D(CombinedLinearGaussianTransitionModel):
    """``CombinedLinearGaussianTransitionModel([ConstantVelocity(q), ConstantVelocity(q)])`` in closed form.

    The same matrices (F and Q of Stone Soup's ``ConstantVelocity`` per axis, block-diagonal),
    written out rather than assembled with ``scipy.linalg.block_diag`` at every call, which was a
    third of a tracker's run time. Both axes must have the same ``noise_diff_coeff``.
    """

    def matrix(self, time_interval: dt.timedelta, **kwargs) -> np.ndarray:
        """Transition matrix F for ``time_interval`` (state [east, v_east, north, v_north])."""
        d = time_interval.total_seconds()
        return np.array([[1.0, d, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, d], [0.0, 0.0, 0.0, 1.0]])

    def covar(self, time_interval: dt.timedelta, **kwargs) -> CovarianceMatrix:
        """Process noise Q for ``time_interval``: q [[d^3/3, d^2/2], [d^2/2, d]] per axis, m^2, m^2/s, m^2/s^2."""
        d = time_interval.total_seconds()
        q = float(self.model_list[0].noise_diff_coeff)
        block = q * np.array([[d ** 3 / 3.0, d ** 2 / 2.0], [d ** 2 / 2.0, d]])
        out = np.zeros((4, 4))
        out[:2, :2] = out[2:, 2:] = block
        return CovarianceMatrix(out)


class StrengthGatedInitiator(SimpleMeasurementInitiator):
    """``SimpleMeasurementInitiator`` that starts tracks only from detections strong enough.

    A detection whose metadata has ``strength_db`` under ``min_strength_db``, or ``beam_fill``
    under ``min_beam_fill``, starts no track; detections without these keys (LiDAR, AIS) always may.
    Used as the ``initiator`` of a ``MultiMeasurementInitiator``: its holding tracks are still
    updated by every detection, weak ones included.
    """

    min_strength_db: float | None = Property(default=None, doc="Weakest plot that may start a track, dB (None: any)")
    min_beam_fill: float | None = Property(default=None, doc="Smallest beam fill of a plot that may start a track")

    def may_seed(self, detection) -> bool:
        """Whether ``detection`` may start a track."""
        meta = detection.metadata
        if self.min_strength_db is not None and meta.get("strength_db", math.inf) < self.min_strength_db:
            return False
        return not (self.min_beam_fill is not None and meta.get("beam_fill", math.inf) < self.min_beam_fill)

    def initiate(self, detections, timestamp, **kwargs):
        """Tracks from the detections that may seed (see :meth:`may_seed`)."""
        return super().initiate({d for d in detections if self.may_seed(d)}, timestamp, **kwargs)


class SensorPDAHypothesiser(PDAHypothesiser):
    """``PDAHypothesiser`` whose clutter density and detection probability are those of the chunk's sensor.

    Every chunk holds one sensor's detections (:func:`chunks`); the sensor is read from the first
    detection's metadata.
    """

    densities: dict = Property(default=None, doc="sensor -> clutter density, 1/(measurement-space volume)")
    probs: dict = Property(default=None, doc="sensor -> detection probability")

    def hypothesise(self, track, detections, timestamp, **kwargs):
        """PDA hypotheses with the chunk's sensor's clutter density and detection probability."""
        first = next(iter(detections), None)
        if first is not None:
            sensor = first.metadata.get("sensor")
            self.clutter_spatial_density = self.densities[sensor]
            self.prob_detect = self.probs[sensor]
        return super().hypothesise(track, detections, timestamp, **kwargs)


def _initiator(setting: Setting, ctx: Context, sensors: tuple, predictor, updater) -> MultiMeasurementInitiator:
    """``MultiMeasurementInitiator`` (GNN on its holding tracks) seeded by a :class:`StrengthGatedInitiator`."""
    speed_sigma = ctx.prior_speed_sigma_mps["radar" if "radar" in sensors else "lidar"]
    prior = GaussianState(np.zeros((4, 1)), np.diag([0.0, speed_sigma ** 2, 0.0, speed_sigma ** 2]))
    seed = StrengthGatedInitiator(prior_state=prior, measurement_model=None,
                                  min_strength_db=setting.min_strength_db,
                                  min_beam_fill=None if setting.min_strength_db is None else ctx.min_beam_fill)
    hold_s = setting.hold_periods * max(ctx.period_s[s] for s in sensors if s in ctx.period_s)
    hold_assoc = GNNWith2DAssignment(DistanceHypothesiser(predictor, updater, measure=Mahalanobis(),
                                                          missed_distance=ctx.missed_distance))
    return MultiMeasurementInitiator(prior_state=prior, deleter=UpdateTimeDeleter(dt.timedelta(seconds=hold_s)),
                                     data_associator=hold_assoc, updater=updater, min_points=setting.min_points,
                                     initiator=seed)


def build_tracker(setting: Setting, ctx: Context, sensors: tuple, detector):
    """A Stone Soup tracker of ``sensors`` over ``detector`` (iterable of (datetime, set of Detection)).

    Returns
    -------
    tracker : MultiTargetTracker or MultiTargetMixtureTracker
    predictor : ExtendedKalmanPredictor
        To predict its tracks to the output epochs.
    """
    transition = NearlyConstantVelocity2D([ConstantVelocity(setting.q_m2_s3), ConstantVelocity(setting.q_m2_s3)])
    predictor = ExtendedKalmanPredictor(transition)
    updater = ExtendedKalmanUpdater(measurement_model=None)  # each detection brings its own
    initiator = _initiator(setting, ctx, sensors, predictor, updater)
    deleter = UpdateTimeDeleter(dt.timedelta(seconds=setting.delete_s))
    if setting.algorithm == "gnn":
        associator = GNNWith2DAssignment(DistanceHypothesiser(predictor, updater, measure=Mahalanobis(),
                                                              missed_distance=ctx.missed_distance))
        return MultiTargetTracker(initiator=initiator, deleter=deleter, detector=detector,
                                  data_associator=associator, updater=updater), predictor
    densities = {s: ctx.clutter_density_per_m2[s] * setting.clutter_scale for s in ("lidar", "radar")}
    densities["ais"] = ctx.ais_clutter_density * setting.clutter_scale
    probs = {"lidar": setting.prob_detect, "radar": setting.prob_detect, "ais": setting.prob_detect}
    hypothesiser = SensorPDAHypothesiser(predictor, updater, clutter_spatial_density=densities["radar"],
                                         prob_detect=setting.prob_detect, prob_gate=ctx.gate_probability,
                                         densities=densities, probs=probs)
    # centralised: JPDA's exact enumeration of joint hypotheses over every track near a big ship's several
    # LiDAR clusters did not finish one 120 s run in 12 min; loopy belief propagation approximates the marginals
    associator = JPDAwithLBP(hypothesiser) if len(sensors) > 1 else JPDA(hypothesiser)
    return MultiTargetMixtureTracker(initiator=initiator, deleter=deleter, detector=detector,
                                     data_associator=associator, updater=updater), predictor


# ---- runs ---------------------------------------------------------------------------------------

def track_record(t_s: float, track_id: int, name: str, x: np.ndarray, p: np.ndarray, frame) -> dict:
    """One ``sensor_tracks.jsonl`` line (docs/formats.md) from a state ``[e, ve, n, vn]`` (m, m/s) and covariance."""
    east, ve, north, vn = (float(v) for v in x)
    lat, lon = frame.to_geodetic(east, north)
    cov = p[np.ix_((0, 2), (0, 2))]
    return {"t": round(float(t_s), 6), "target_id": int(track_id), "object_descriptor": "unknown",
            "longitude": round(float(lon), 8), "latitude": round(float(lat), 8),
            "cog_deg": round(float(np.mod(np.degrees(np.arctan2(ve, vn)), 360.0)), 3),
            "sog_mps": round(float(np.hypot(ve, vn)), 4), "cross_section_m2": 0.0, "sources": [name],
            "position_cov_m2": [[round(float(cov[0, 0]), 4), round(float(cov[0, 1]), 4)],
                                [round(float(cov[1, 0]), 4), round(float(cov[1, 1]), 4)]],
            "mmsi": None, "sensor": name}


def run_tracker(fed: list, name: str, setting: Setting, ctx: Context, epochs: np.ndarray, frame) \
        -> tuple[list[dict], float]:
    """Run one Stone Soup tracker over its chunks; its tracks predicted to every output epoch.

    Parameters
    ----------
    fed : list of (t_s, sensor, detections)
        :func:`chunks` of the tracker's sensors.
    name : str
        A key of :data:`TRACKER_SENSORS` (the ``sensor`` of the records).
    setting : Setting
    ctx : Context
    epochs : (E,) float
        Output times, s.
    frame : EnuFrame
        The recording's frame (for lat/lon).

    Returns
    -------
    records : list of dict
        ``sensor_tracks.jsonl`` lines in time order.
    wall_s : float
        Tracking time, s.
    """
    records: list[dict] = []
    ids: dict = {}
    k = 0
    box: list = []

    def emit_until(t_s: float) -> None:
        nonlocal k
        tracker, predictor = box
        while k < epochs.size and epochs[k] < t_s:
            for track in tracker.tracks:
                pred = predictor.predict(track.state, timestamp=stamp(epochs[k]))
                tid = ids.setdefault(track.id, len(ids) + 1)
                records.append(track_record(float(epochs[k]), tid, name, np.asarray(pred.state_vector, float).ravel(),
                                            np.asarray(pred.covar, float), frame))
            k += 1

    def detector():
        for t_s, _, dets in fed:
            emit_until(t_s)
            yield stamp(t_s), set(dets)
        emit_until(math.inf)

    box[:] = build_tracker(setting, ctx, TRACKER_SENSORS[name], detector())
    start = time.perf_counter()
    for _ in box[0]:
        pass
    return records, time.perf_counter() - start

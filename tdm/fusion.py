"""Track-to-track association and fusion of the per-sensor tracks (docs/reference.md section 5).

- **Association.** A fused target holds at most one track per sensor. A track stays with its
  target while it lives and stays within the track-to-track gate; a new (or released) track
  joins the nearest target that has no track of its sensor, by GNN on the track-to-track
  statistic ``d^2 = dx^T (P_i + P_j)^-1 dx`` on position (gate chi-square 2 dof), else it
  starts a new target. An AIS track is matched to targets the same way, so a ship keeps its
  id when its AIS arrives after the radar saw it. Target ids are never reused for another object: a
  target that ended comes back under its id only where it was (``revive_s``), and a track that was folded
  with its target into another (same object, below) and leaves it again takes its own target's id back.
- **Extended objects.** A large ship gives several radar plots (bow, bridge, stern) and an
  iceberg several LiDAR clusters, hence several tracks of one sensor. A track that joins no
  target but lies near the footprint of a target (within ``absorb_lengths`` (0.75) of its length,
  known from AIS static data or from its tracks' measured extents, plus three standard
  deviations: the radar beam smears a ship's ends by tens of metres at range; for a radar track, plus half
  the beam's cross-range resolution at its range) is absorbed:
  it belongs to that target, is not reported and does not enter the fusion; it leaves only on a plot outside the
  footprint, not by coasting out of it (``release_absorbed_on_plot``). An AIS track is never
  absorbed (it is a ship's identity): inside the footprint of a target without AIS (by the ship's own
  length when known, plus three standard deviations of both positions) whose velocity is not known to
  differ from the ship's it joins that target; otherwise it starts its own. An AIS ship's absorbed LiDAR
  track becomes its member once it moves with the ship and lies on the hull (``promote_after_s``): the
  LiDAR alone is then often the best position sensor, and an absorbed track is not fused.
- **Simple Fusion** (thesis eq. 3.2): ``x = (sum_i P_i^-1)^-1 sum_i P_i^-1 x_i`` over the tracks of the target at
  the output time, a LiDAR or radar track's ``P_i`` without its position-velocity cross-covariance
  (``fuse_position_apart``). It ignores the cross-covariance of the per-sensor tracks, so its covariance is too
  small (REFERENCE: NEES about 5.8 against 4); ``tdm evaluate`` reports the NEES.
- **Where on the hull** (``weigh_hull``): a ship's radar track lies on whatever part of the hull the
  radar paints, so for a target whose AIS gives the ship's length, its radar track enters the output
  fusion with the covariance of a point uniform over the hull added (:func:`tdm.hull.hull_covariance`):
  the fusion leans on the AIS, and its covariance holds the radar's offset. Its LiDAR track lies at the
  middle of the part it sees: uniform over the hull less that part (``hull_sensors``).
- **Behind the face** (``radar_hidden_depth_*``; :mod:`tdm.fusion_face`): a still target's radar track without AIS
  is put half its plots' core width (or 0.6 of its length where the core width is ill-conditioned) behind its face;
  the radar track of any other target without AIS stays on its face, and that offset is reported in the target's
  covariance (``consider_radar_face``).
- **Covariance intersection** (``fusion: ci``), the consistent alternative, with the fast
  weights ``w_i = (1/tr P_i) / sum_j (1/tr P_j)`` (Niehsen 2002):
  ``P^-1 = sum_i w_i P_i^-1``, ``x = P sum_i w_i P_i^-1 x_i``.
- **Classes** (:mod:`tdm.fusion_classes`): ``vessel``, ``iceberg``, ``fixed obstacle`` or ``unknown``, from the
  target's AIS, its fused speed over time, its footprint and its LiDAR height.
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from tdm import ekf
from tdm.association import chi2_gate, gnn, mahalanobis2
from tdm.fusion_classes import STILL_SPEED_FRACTION, VESSEL_SIGMAS, Classifier
from tdm.fusion_config import FusionConfig
from tdm.fusion_geometry import FOOTPRINT_SIGMAS, MERGE_SIGMAS, MERGE_SPEED_MPS  # noqa: F401
from tdm.fusion_geometry import clearly_apart as _clearly_apart
from tdm.fusion_geometry import finite_or_inf, inside, within_reach
from tdm.fusion_geometry import major_variance as _major_variance
from tdm.fusion_geometry import moves_apart as _moves_apart
from tdm.fusion_consider import reported_covariance
from tdm.fusion_face import STILL_DESCRIPTORS, behind_the_face
from tdm.fusion_rules import apart_members, fuse, velocity_frame, without_stray_velocities
from tdm.fusion_target import FusedEstimate, FusedTarget
from tdm.fusion_weights import member_hull_covariance, with_extent, with_face_turn, with_fragments, with_hull
from tdm.tracker import Track, predicted_at


#: Degrees of freedom of the track-to-track gate: east and north position.
POSITION_DOF = 2
#: Degrees of freedom of the AIS velocity gate (FusionConfig.ais_velocity_gate_probability): east and north velocity.
VELOCITY_DOF = 2
#: A member leaves its target when its statistic exceeds this many gates, or its distance this many
#: ``max_distance_m``: looser than joining, so that a track does not flicker in and out.
RELEASE_GATES = 4
RELEASE_DISTANCES = 2
#: The order in which the free tracks of each sensor look for a target: AIS (the identity) first.
SENSOR_ORDER = ("ais", "lidar", "radar")


class Fuser:
    """Keeps fused targets over time and produces their fused estimates."""

    def __init__(self, config: FusionConfig):
        self.config = config
        self.targets: list[FusedTarget] = []
        self.lengths_by_mmsi: dict[int, float] = {}
        self.beams_by_mmsi: dict[int, float] = {}
        self._ended: list[FusedTarget] = []
        self._folded: dict[tuple[str, int], FusedTarget] = {}  # track -> the target it held before a merge
        self._inside_at_s: dict[tuple[str, int], float] = {}  # absorbed track -> its last plot's time while inside
        self._ids = itertools.count(1)
        self._gate = chi2_gate(config.gate_probability, POSITION_DOF)
        self._velocity_gate = None if config.ais_velocity_gate_probability is None else \
            chi2_gate(config.ais_velocity_gate_probability, VELOCITY_DOF)
        self._classifier = Classifier(config)
        self._memo: dict | None = None  # the fused estimates and weighed members of one step (_estimate, _members)
        self.weighed: dict = {}  # (sensor, track id) -> (x (6,), p (6, 6)) as the last step's output fusion weighed it

    def step(self, t_s: float, tracks_by_sensor: dict[str, list[Track]],
             own_position_m: np.ndarray | None = None,
             own_velocity_mps: np.ndarray | None = None) -> list[FusedEstimate]:
        """Associate the confirmed tracks at ``t_s`` and return every target's fused estimate.

        ``own_position_m`` (2,), the own ship's east and north at ``t_s`` (m), lets still targets' radar tracks
        be put behind their painted face (``radar_hidden_depth_fraction``) and the other radar tracks' face offset be
        reported along the line of sight (``consider_radar_face``), and the heading bias's share of the own ship's
        navigation bias (``consider_nav_bias``); None or not finite: as they are, no face offset, and the position
        bias alone. ``own_velocity_mps`` (2,), its velocity (m/s), lets the velocity of the tracks of a sensor that
        sees a side be weighed with that side's turning (``face_turn_scale``); None: not.
        """
        self._memo = {}
        if own_position_m is not None:
            own_position_m = np.asarray(own_position_m, dtype=float)[:2]
            own_position_m = own_position_m if np.all(np.isfinite(own_position_m)) else None
        if own_velocity_mps is not None:
            own_velocity_mps = np.asarray(own_velocity_mps, dtype=float)[:2]
            own_velocity_mps = own_velocity_mps if np.all(np.isfinite(own_velocity_mps)) else None
        try:
            return self._step(t_s, tracks_by_sensor, own_position_m, own_velocity_mps)
        finally:
            self._memo = None

    def _step(self, t_s: float, tracks_by_sensor: dict[str, list[Track]],
              own_position_m: np.ndarray | None, own_velocity_mps: np.ndarray | None) -> list[FusedEstimate]:
        """:meth:`step`, with the fused estimates of the step kept (:meth:`_estimate`)."""
        cfg = self.config
        live = {(s, tr.track_id): tr for s, trs in tracks_by_sensor.items() for tr in trs}
        states = dict(zip(live, predicted_at(list(live.values()), t_s)))  # at once; kept for the output
        self._folded = {k: t for k, t in self._folded.items() if k in live}
        self._inside_at_s = {k: t for k, t in self._inside_at_s.items() if k in live}
        moved = set()
        if own_position_m is not None and cfg.radar_hidden_depth_fraction > 0.0:
            moved = behind_the_face(self.targets, states, live, own_position_m, cfg)
        # keep members that still exist and stay close to the rest of their target
        claimed: set[tuple[str, int]] = set()
        for target in self.targets:
            target.members = {s: i for s, i in target.members.items() if (s, i) in live}
            if len(target.members) > 1:
                self._split_inconsistent(target, states)
            claimed.update(target.members.items())
        for target in self.targets:
            if not target.members and target.last_x is not None:
                self._ended.append(target)
        self._ended = [t for t in self._ended if t_s - t.last_t_s <= (
            cfg.revive_still_s if self._ended_still(t) else cfg.revive_s)]
        self.targets = [t for t in self.targets if t.members]
        for target in self.targets:
            x, _ = self._estimate(target, states)
            half = self._half_length(target, live)
            target.absorbed = {k for k in target.absorbed if k in live and k not in claimed
                               and self._stays_absorbed(k, live[k], states[k], x, half)}
            self._promote(target, states, live, t_s)
            claimed.update(target.absorbed)
            claimed.update(target.members.items())
        # new or released tracks: join a target without a track of their sensor, else start one
        for sensor in sorted(tracks_by_sensor,
                             key=lambda s: SENSOR_ORDER.index(s) if s in SENSOR_ORDER else len(SENSOR_ORDER)):
            free = [tr for tr in tracks_by_sensor[sensor] if (sensor, tr.track_id) not in claimed]
            if not free:
                continue
            candidates = [t for t in self.targets if sensor not in t.members]
            pairs = []
            if candidates:
                cx, cp = zip(*(self._estimate(t, states) for t in candidates))
                cx, cp = np.array(cx), np.array(cp)
                fx = np.array([states[(sensor, tr.track_id)][0] for tr in free])
                fp = np.array([states[(sensor, tr.track_id)][1] for tr in free])
                d = cx[:, None, :2] - fx[None, :, :2]
                cost = mahalanobis2(d, cp[:, None, :2, :2] + fp[None, :, :2, :2])
                cost[np.hypot(d[..., 0], d[..., 1]) > cfg.max_distance_m] = np.inf
                pairs = gnn(cost, self._gate)
            joined = set()
            for ti, fi in pairs:
                candidates[ti].members[sensor] = free[fi].track_id
                joined.add(fi)
            for fi, tr in enumerate(free):
                if fi not in joined:
                    self._place(sensor, tr, states, live, t_s, own_position_m)
        self._merge_overlapping(states, live, own_position_m)
        out = []
        weigh = with_extent(states, live) if cfg.weigh_extent else states
        if cfg.weigh_hull:
            weigh = with_hull(weigh, live, self.targets, self.lengths_by_mmsi, self.beams_by_mmsi, VESSEL_SIGMAS,
                              cfg.hull_sensors)
        if cfg.fragment_sensors:
            weigh = with_fragments(weigh, self.targets, cfg.fragment_sensors)
        if cfg.face_turn_scale > 0.0 and own_position_m is not None and own_velocity_mps is not None:
            weigh = with_face_turn(weigh, live, own_position_m, own_velocity_mps, cfg.face_turn_scale,
                                   cfg.face_turn_sensors)
        self.weighed = weigh
        for target in self.targets:
            x, p = self._estimate(target, weigh)
            reported_p = reported_covariance(target, x, p, *self._members(target, weigh), live, own_position_m,
                                             moved, cfg)
            target.last_x, target.last_p, target.last_t_s = x, p, t_s
            target.radius_m = self._half_length(target, live)
            ais_track = live.get(("ais", target.members.get("ais", -1)))
            target.mmsi = ais_track.mmsi if ais_track is not None else target.mmsi
            heights = [live[(s, i)].height_m for s, i in target.members.items() if s == "lidar"]
            self._classifier.classify(target, x, p, t_s, heights[0] if heights else float("nan"))
            out.append(FusedEstimate(target, x, reported_p, sorted(target.members)))
        return out

    def _place(self, sensor: str, tr: Track, states: dict, live: dict, t_s: float,
               own_position_m: np.ndarray | None) -> None:
        """A track that joined no target: absorbed by a target that holds it (:meth:`_holds`); an AIS track instead
        joins such a target without AIS whose velocity is not known to differ, as the ship's identity never hides in
        a target; otherwise a new target, or a recently ended one revived."""
        key = (sensor, tr.track_id)
        unresolved_m = self._unresolved_m(sensor, states[key][0], own_position_m)
        ship_m = self._ship_half_length(tr.mmsi) if sensor == "ais" else math.nan
        host = next((t for t in self.targets if (sensor != "ais" or "ais" not in t.members)
                     and self._holds(t, sensor, states[key], live, states, unresolved_m, ship_m, own_position_m)),
                    None)
        if host is not None and sensor == "ais":
            if _moves_apart(self._estimate(host, states), states[key], older_has_ais=False):
                host = None  # another ship close by: a target of its own
            else:
                host.members[sensor] = tr.track_id
        elif host is not None:
            host.absorbed.add(key)
            self._inside_at_s[key] = tr.updated_s
        if host is None:
            self.targets.append(self._unfold(key) or self._revive(states[key], t_s)
                                or FusedTarget(next(self._ids), created_s=t_s))
            self.targets[-1].members = {sensor: tr.track_id}

    def _stays_absorbed(self, key: tuple[str, int], tr: Track, state: tuple, centre: np.ndarray,
                        half_length_m: float) -> bool:
        """Whether absorbed track ``key`` stays with its target (``centre`` (6,), radius ``half_length_m``, m): while
        its ``state`` lies inside the footprint, and (``release_absorbed_on_plot``) while it has had no plot since it
        last did: a coasting track moves on its own velocity, not on evidence that it is another object. Inside, the
        time of its last plot is recorded (``_inside_at_s``)."""
        if self._inside(state, centre, half_length_m):
            self._inside_at_s[key] = tr.updated_s
            return True
        return self.config.release_absorbed_on_plot and tr.updated_s <= self._inside_at_s.get(key, -math.inf)

    def _unfold(self, key: tuple[str, int]) -> FusedTarget | None:
        """The target that track ``key`` held before it was folded into another (:meth:`_merge_overlapping`), when
        the track leaves that other one and starts a target again: the track is the same, so is its id (unless
        another of its tracks took the id back first)."""
        target = self._folded.pop(key, None)
        if target is None or any(t.target_id == target.target_id for t in self.targets):
            return None
        if target in self._ended:  # taken back by another of its tracks since, and ended again
            self._ended.remove(target)
        target.absorbed = set()
        return target

    def _holds(self, target: FusedTarget, sensor: str, state: tuple, live: dict, states: dict, unresolved_m: float,
               ship_m: float, own_position_m: np.ndarray | None) -> bool:
        """Whether ``target`` holds a new track of ``sensor`` at ``state`` (:meth:`_place`): within its footprint
        (for radar, widened by half the beam's resolution at the track's range, ``unresolved_m``:
        :meth:`_beyond_size`); for an AIS track of a ship of known half length ``ship_m``, within that, or half the
        radar's resolution at the target's range if larger (as :meth:`_merge_radius` would merge them), with both
        positions' uncertainty (:meth:`_against`)."""
        estimate = self._estimate(target, states)
        centre = estimate[0]
        if math.isfinite(ship_m):
            radar = "radar" if "radar" in target.members else ""
            radius_m = max(ship_m, self._unresolved_m(radar, centre, own_position_m))
        else:
            radius_m = self._beyond_size(self._half_length(target, live), unresolved_m)
        return self._inside(self._against(sensor, state, estimate), centre, radius_m)

    def _promote(self, target: FusedTarget, states: dict, live: dict, t_s: float) -> None:
        """An AIS ship's target without a track of a ``join_free_slot`` sensor takes an absorbed track of that sensor
        as its member once the track is ``promote_after_s`` old and lies on the hull (:meth:`_on_the_hull`)."""
        if "ais" not in target.members:
            return
        for key in sorted(target.absorbed):
            sensor = key[0]
            if sensor in self.config.join_free_slot and sensor not in target.members \
                    and t_s - live[key].created_s >= self.config.promote_after_s \
                    and self._on_the_hull(sensor, live[key], states, live, target):
                target.members[sensor] = key[1]
                target.absorbed.discard(key)

    def _on_the_hull(self, sensor: str, tr: Track, states: dict, live: dict, host: FusedTarget) -> bool:
        """Whether a track may be on an AIS ship's hull: its velocity not known to differ from the ship's, and its
        position within the fusion's gate of the AIS track's with the hull's variance added
        (:func:`tdm.fusion_weights.with_hull`)."""
        ais_key, key = ("ais", host.members["ais"]), (sensor, tr.track_id)
        if _moves_apart(states[ais_key], states[key], older_has_ais=True):
            return False
        hull = member_hull_covariance(sensor, tr, live[ais_key], states[ais_key], self.lengths_by_mmsi,
                                      self.beams_by_mmsi, VESSEL_SIGMAS)
        if hull is None:
            return False  # the ship's length is not known
        d = states[key][0][:2] - states[ais_key][0][:2]
        s = states[key][1][:2, :2] + hull + states[ais_key][1][:2, :2]
        return float(mahalanobis2(d[None, :], s[None])[0]) <= self._gate

    @staticmethod
    def _against(sensor: str, state: tuple, target_estimate: tuple) -> tuple:
        """An AIS track's state with the target's position covariance added (their difference's uncertainty: a
        target a second old is as uncertain as its first plot); another sensor's track as it is."""
        if sensor != "ais":
            return state
        x, p = state
        p = p.copy()
        p[:2, :2] = p[:2, :2] + target_estimate[1][:2, :2]
        return x, p

    def _beyond_size(self, half_length_m: float, unresolved_m: float) -> float:
        """A new track's absorbing radius about a target: the target's radius and the beam's half resolution summed
        (``radar_smear_beyond_size``: the echo of an object spans its size smeared by the beam) or the larger."""
        if self.config.radar_smear_beyond_size:
            return half_length_m + unresolved_m
        return max(half_length_m, unresolved_m)

    def _unresolved_m(self, sensor: str, x: np.ndarray, own_position_m: np.ndarray | None) -> float:
        """Half the radar's cross-range resolution at the track's range, m (``radar_beam_deg``); 0 otherwise."""
        beam_deg = self.config.radar_beam_deg
        if sensor != "radar" or beam_deg is None or own_position_m is None:
            return 0.0
        distance = math.hypot(float(x[0]) - float(own_position_m[0]), float(x[1]) - float(own_position_m[1]))
        return 0.5 * distance * math.radians(beam_deg)

    def _members(self, target: FusedTarget, states) -> tuple[np.ndarray, np.ndarray]:
        """The target's members' states (K, 6) and covariances (K, 6, 6) as the fusion weighs them: from
        ``states``, with a velocity its AIS member rules out left out (``ais_velocity_gate_probability``;
        :func:`tdm.fusion_rules.without_stray_velocities`). Within a :meth:`step` kept as :meth:`_estimate` keeps
        its fusion (the fusion and the reported covariance read them both)."""
        memo = self._memo
        key = ("members", id(states), tuple(target.members.items()))
        if memo is not None and key in memo:
            return memo[key]
        xs = np.array([states[(s, i)][0] for s, i in target.members.items()])
        ps = np.array([states[(s, i)][1] for s, i in target.members.items()])
        if self._velocity_gate is not None and "ais" in target.members and len(xs) > 1:
            ps = without_stray_velocities(xs, ps, list(target.members).index("ais"), self._velocity_gate)
        if memo is not None:
            memo[key] = (xs, ps)
        return xs, ps

    def _estimate(self, target: FusedTarget, states) -> tuple[np.ndarray, np.ndarray]:
        """The target's fused state (6,) and covariance (6, 6) from its members' ``states`` (:meth:`_members`).

        Within a :meth:`step` (``states`` fixed once the members are checked) a target with the same members
        is fused once: the arrays are shared, not to be changed in place.
        """
        memo = self._memo
        key = (id(states), tuple(target.members.items()))
        if memo is not None and key in memo:
            return memo[key]
        cfg = self.config
        out = fuse(*self._members(target, states), cfg.rule, velocity_frame(cfg.fuse_velocity, target.members),
                   apart_members(target.members, cfg.fuse_position_apart))
        if memo is not None:
            memo[key] = out
        return out

    def _half_length(self, target: FusedTarget, live) -> float:
        """Absorbing radius of the target, metres, from its length (AIS static data, else its tracks' extents).

        Within a :meth:`step` (``live`` fixed) formed once for the same members and MMSI.
        """
        memo = self._memo
        key = ("half", target.mmsi, tuple(target.members.items()))
        if memo is not None and key in memo:
            return memo[key]
        lengths = [live[(s, i)].length_m for s, i in target.members.items()]
        if target.mmsi is not None:
            lengths.append(self.lengths_by_mmsi.get(target.mmsi, 0.0))
        finite = [v for v in lengths if np.isfinite(v)]
        out = max(self.config.min_extent_m, self.config.absorb_lengths * max(finite, default=0.0))
        if memo is not None:
            memo[key] = out
        return out

    def _ship_half_length(self, mmsi: int | None) -> float:
        """The absorbing radius of the AIS ship ``mmsi`` from its static length alone, m; NaN when unknown.

        What decides whether an AIS ship and another target are one object: the transponder's dimensions are the
        ship's, where a radar track's extent can hold a sidelobe arc or the quay it lies against (harbour_approach
        seed 31: a pier's radar target, its extent grown by a ring of sidelobes, took the AIS of a tanker 400 m
        away).
        """
        length_m = self.lengths_by_mmsi.get(mmsi, math.nan) if mmsi is not None else math.nan
        return max(self.config.min_extent_m, self.config.absorb_lengths * length_m) if math.isfinite(length_m) \
            else math.nan

    def _target_ship_half_length(self, target: FusedTarget, live: dict) -> float:
        """:meth:`_ship_half_length` of the target's AIS track's MMSI, m; NaN without an AIS track or length."""
        return self._ship_half_length(live[("ais", target.members["ais"])].mmsi) if "ais" in target.members \
            else math.nan

    _inside = staticmethod(inside)

    def _ended_still(self, target: FusedTarget) -> bool:
        """Whether an ended target is looked for where it was for ``revive_still_s``: settled as still (iceberg,
        fixed obstacle), or (``revive_slow_as_still``) without AIS, not a vessel, and last reported slower than still
        targets are (STILL_SPEED_FRACTION of ``vessel_speed_mps``; the filter's speed may be negative, its course then
        reversed): one that ended before it settled, its speed's uncertainty not asked (a boat lost two seconds
        after its first plot, its speed still about its prior 0, is kept so too, where it was)."""
        if target.descriptor in STILL_DESCRIPTORS:
            return True
        return self.config.revive_slow_as_still and target.mmsi is None and target.descriptor != "vessel" \
            and target.last_x is not None \
            and abs(float(target.last_x[ekf.U])) < STILL_SPEED_FRACTION * self.config.vessel_speed_mps

    def _revive(self, state, t_s: float) -> FusedTarget | None:
        """The recently ended target where ``state`` (a new track's) may be: within its footprint about its last
        state predicted to ``t_s`` (:meth:`_may_be`)."""
        best, best_d = None, np.inf
        for target in self._ended:
            centre, inside = self._may_be(target, state, t_s)
            if inside:
                d = float(np.hypot(*(state[0][:2] - centre[:2])))
                if d < best_d:
                    best, best_d = target, d
        if best is not None:
            self._ended.remove(best)
            best.absorbed = set()
        return best

    def _may_be(self, target: FusedTarget, state, t_s: float) -> tuple[np.ndarray, bool]:
        """Where an ended target is looked for at ``t_s`` (s), its state (6,), and whether ``state`` lies there.

        A still target (:meth:`_ended_still`) is where it was (its last small speed, a noisy track's drift, is not
        carried on), and the track must lie within its footprint (:meth:`_inside`). A moving one, with
        ``revive_spread``, goes on straight at its last course and speed (a turn rate estimated as it was being
        hidden is the hiding's, not the ship's), and the track's distance from there, less the footprint's radius,
        must pass the association gate (``gate_probability``) in the sum of the track's covariance and that
        prediction's (the trackers' motion model; the turn rate's uncertainty kept: it may have turned either
        way), so that the search widens across its track as the gap grows; without, it goes on at its last turn
        rate too, and the footprint test is as for a still one.
        """
        if self._ended_still(target):
            return target.last_x, self._inside(state, target.last_x, target.radius_m)
        dt_s = t_s - target.last_t_s
        if not self.config.revive_spread or target.last_p is None:
            centre = ekf.predict_mean(target.last_x, dt_s)
            return centre, self._inside(state, centre, target.radius_m)
        straight = target.last_x.copy()
        straight[ekf.R] = 0.0
        centre, spread = ekf.predict(straight, target.last_p, dt_s, ekf.ProcessNoise())
        return centre, within_reach(state, centre, spread, target.radius_m, self._gate)

    def _merge_overlapping(self, states, live, own_position_m: np.ndarray | None = None) -> None:
        """Fold a target into an older one when both are the same object.

        Same object: one lies inside the other's footprint (as for absorbing tracks; when one of them is an AIS
        ship of known length, inside that ship's footprint or the radar's resolution: :meth:`_merge_radius`),
        they are not a
        still target and a moving one (:meth:`_passing`), and either
        exactly one of them has an AIS track (a radar or LiDAR target of an AIS ship) and the other's
        velocity is not known to differ from the AIS ship's (:func:`_moves_apart`: two ships crossing),
        or neither has and they move alike (within 2 m/s). The older target keeps its id; the younger's
        tracks fill the sensors the older lacks and are absorbed otherwise.
        """
        targets = sorted(self.targets, key=lambda t: (t.created_s, t.target_id))
        est = {t.target_id: self._estimate(t, states) for t in targets}
        half = {t.target_id: self._half_length(t, live) for t in targets}
        reach = [self._merge_reach(t, est, half, live, own_position_m) for t in targets]
        apart = _clearly_apart([est[t.target_id] for t in targets], reach)
        gone: set[int] = set()
        for i, older in enumerate(targets):
            if older.target_id in gone:
                continue
            grown = False  # older has taken a target in: its estimate is no longer the one ``apart`` saw
            for j in range(i + 1, len(targets)):
                younger = targets[j]
                if younger.target_id in gone or (apart[i, j] and not grown):
                    continue
                xo, _ = est[older.target_id]
                xy, py = est[younger.target_id]
                radius = self._merge_radius(older, younger, est, half, live, own_position_m)
                if not self._inside((xy, py), xo, radius) or self._passing(older, xo, younger, xy):
                    continue
                n_ais = ("ais" in older.members) + ("ais" in younger.members)
                if n_ais == 2:
                    continue
                if n_ais == 0 and np.hypot(*(ekf.velocity_en(xo) - ekf.velocity_en(xy))) > MERGE_SPEED_MPS:
                    continue
                if n_ais == 1 and _moves_apart(est[older.target_id], (xy, py), "ais" in older.members):
                    continue
                self._folded.update({key: younger for key in younger.members.items()})
                for key in younger.absorbed:
                    self._folded.setdefault(key, younger)
                for sensor, track_id in younger.members.items():
                    if sensor in older.members:
                        older.absorbed.add((sensor, track_id))
                    else:
                        older.members[sensor] = track_id
                older.absorbed |= younger.absorbed
                if older.descriptor == "unknown":
                    older.descriptor = younger.descriptor
                gone.add(younger.target_id)
                grown = True
                est[older.target_id] = self._estimate(older, states)
                half[older.target_id] = self._half_length(older, live)
        self.targets = [t for t in self.targets if t.target_id not in gone]

    def _merge_radius(self, older: FusedTarget, younger: FusedTarget, est: dict, half: dict, live: dict,
                      own_position_m: np.ndarray | None) -> float:
        """Within this of one another (plus the younger's 3 sigma) two targets may be one object, m: the larger of
        their absorbing radii, or, when exactly one is an AIS ship of known length, that ship's
        (:meth:`_ship_half_length`), or half the radar's cross-range resolution at the other's range if larger (its
        radar track may lie anywhere across the beam)."""
        ais, other = (older, younger) if "ais" in older.members else (younger, older)
        ship_m = self._target_ship_half_length(ais, live) if "ais" not in other.members else math.nan
        if not math.isfinite(ship_m):
            return max(half[older.target_id], half[younger.target_id])
        sensor = "radar" if "radar" in other.members else ""
        return max(ship_m, self._unresolved_m(sensor, est[other.target_id][0], own_position_m))

    def _merge_reach(self, target: FusedTarget, est: dict, half: dict, live: dict,
                     own_position_m: np.ndarray | None) -> float:
        """The largest :meth:`_merge_radius` of ``target`` with any other, m (what the vectorised first look,
        :func:`_clearly_apart`, must allow for)."""
        ship_m = self._target_ship_half_length(target, live)
        sensor = "radar" if "radar" in target.members else ""
        return max(half[target.target_id], ship_m if math.isfinite(ship_m) else 0.0,
                   self._unresolved_m(sensor, est[target.target_id][0], own_position_m))

    def _passing(self, a: FusedTarget, xa: np.ndarray, b: FusedTarget, xb: np.ndarray) -> bool:
        """One target has settled as still (iceberg, fixed obstacle) and the other moves: a ship passing a
        berg, two objects however close (busy_open_sea seeds 9 and 11: a 100 m ship passes 75 m from a berg)."""
        moving = self.config.vessel_speed_mps
        return (a.descriptor in STILL_DESCRIPTORS and abs(xb[ekf.U]) > moving) or \
            (b.descriptor in STILL_DESCRIPTORS and abs(xa[ekf.U]) > moving)

    def _split_inconsistent(self, target: FusedTarget, states) -> None:
        """Release members that have drifted away from the target's other tracks.

        An AIS track is the target's identity: when there is one, the other members are checked
        against it and released if inconsistent; the AIS track itself is never released. Without one,
        each member is checked in turn against the fusion of the others still in it, the least precise first
        (``release_least_precise``, a non-finite variance counting as the least; else in the order they joined),
        and each found inconsistent leaves: of two that disagree, the first checked.
        """
        if "ais" in target.members:
            ais_key = ("ais", target.members["ais"])
            xa, pa = states[ais_key]
            moving = self.config.release_beyond_ais_spread and abs(xa[ekf.U]) > self.config.vessel_speed_mps
            for key in [k for k in target.members.items() if k[0] != "ais"]:
                xi, pi_ = states[key]
                d = xi[:2] - xa[:2]
                if self._released(d, pi_[:2, :2] + pa[:2, :2], pa[:2, :2] if moving else None):
                    del target.members[key[0]]
            return
        keys = list(target.members.items())
        if self.config.release_least_precise:  # the widest first: of two that disagree, the better one stays
            keys.sort(key=lambda k: -finite_or_inf(float(np.trace(states[k][1][:2, :2]))))
        for key in keys:
            others = [k for k in target.members.items() if k != key]
            if not others:
                break
            xs = np.array([states[k][0] for k in others])
            ps = np.array([states[k][1] for k in others])
            sensors = [k[0] for k in others]
            x, p = fuse(xs, ps, self.config.rule, velocity_frame(self.config.fuse_velocity, sensors),
                        apart_members(sensors, self.config.fuse_position_apart))
            xi, pi_ = states[key]
            d = xi[:2] - x[:2]
            if self._released(d, pi_[:2, :2] + p[:2, :2]):
                del target.members[key[0]]

    def _released(self, d: np.ndarray, s: np.ndarray, spread: np.ndarray | None = None) -> bool:
        """A member at position difference ``d`` (m, 2) with summed covariance ``s`` (m^2) leaves its target: beyond
        RELEASE_GATES gates, or RELEASE_DISTANCES x ``max_distance_m`` plus FOOTPRINT_SIGMAS standard deviations of
        ``spread`` (m^2; the AIS track's own covariance, its coast between reports) along its major axis."""
        limit_m = RELEASE_DISTANCES * self.config.max_distance_m
        if spread is not None:
            major = _major_variance(float(spread[0, 0]), float(spread[1, 0]), float(spread[1, 1]))
            widening_m = FOOTPRINT_SIGMAS * math.sqrt(max(major, 0.0))
            if math.isfinite(widening_m):  # a broken covariance does not hold a member for ever
                limit_m += widening_m
        return mahalanobis2(d, s) > RELEASE_GATES * self._gate or np.hypot(*d) > limit_m

"""The LiDAR front end's settings (:class:`LidarFrontEndConfig`) and the LiDAR's mount.

Part of the LiDAR front end (:mod:`tdm.frontend.lidar`, module docstring for how each setting is used).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

from groundfloor.recording import LidarDescription
from tdm.frames import Mount
from tdm.recording.scenario import nav_settings

__all__ = ["HDL32E_FIRING_CYCLE_S", "LINK_WINDOW_CYCLES", "LidarFrontEndConfig", "lidar_mount_from_scenario"]

#: HDL-32E firing cycle: 32 firings of 1.152 us + 9.216 us recharge, s (docs/reference.md section 2).
HDL32E_FIRING_CYCLE_S = 46.08e-6
#: Range-image neighbours lie at most two azimuth steps (firing cycles) apart, so they are fired
#: within this many cycles of each other; points a revolution apart (at the seam) are not linked.
LINK_WINDOW_CYCLES = 3


@dataclass(frozen=True)
class LidarFrontEndConfig:
    """Settings of the LiDAR front end (module docstring for how each is used).

    Attributes
    ----------
    ownship_length_m, ownship_beam_m : float
        Own ship's length overall and beam, m. Default: Odin, the thesis's USV (10.9 x 3.5 m,
        scenarios/busy_open_sea.yaml).
    ownship_margin_m : float
        Padding of the own-ship box on every side, m (default 0.5: covers fenders, rails and
        the range noise; nothing nearer than that to the hull is a target to track).
    ownship_centre_x_m : float
        Body-frame x of the middle of the hull, m (0: the body origin is midships, as in the
        recordings' meshes).
    range_min_m, range_max_m : float
        Returns outside this range are dropped, m. Defaults: 0.1 m (drivers cut at 0.1-0.9 m)
        and 100 m (HDL-32E rated range), docs/reference.md section 2.
    min_height_m : float
        Points whose ENU z is below this are sea or foam, m. The sea surface is the plane
        z = 0 (waves move the own ship, not the sea's returns), and foam returns lie within
        centimetres of it; 0.5 m keeps clear of them and of the own ship's heave error while
        keeping all but the lowest part of a target.
    voxel_m : float
        Side of the horizontal voxels (pillars) the points are binned into before clustering,
        m. 0.25 m, well under the tolerance, so clusters match raw-point clustering to within
        a voxel while a close iceberg's ~2000 points become a few hundred voxels.
    cluster_tolerance_m : float
        Euclidean clustering distance on the horizontal plane, m (PCL/Autoware default 0.7 m,
        docs/reference.md section 5).
    ring_link_angle_deg : float
        Minimum angle beta for joining points of nearby rings, deg (10 deg: Bogoslavskyi &
        Stachniss 2016, the depth_clustering default).
    ring_link_max_step : int
        Rings up to this many apart are linked (2: bridges one ring without a return).
    min_points, max_points : int, int or None
        Clusters with fewer (more) raw points are dropped. 10 is the PCL/Autoware minimum
        (docs/reference.md section 5, counted there on voxels). No maximum by default: the
        Autoware maximum of 1000 removes buildings on land, but at sea a big cluster is a big
        target (a close iceberg gives ~2000 points).
    min_surface_fraction : float
        Clusters in which fewer than this fraction of the points have a same-surface
        neighbour along their own ring are dropped as weather. A solid surface is hit by
        successive firings of a laser; backscatter from rain and fog drops (docs/reference.md
        section 2) is not: measured here, 0-3 % of the points of rain clusters
        (rough_sea_rain) against 92-100 % of those of iceberg and ship clusters. 0.5 lies
        well between.
    range_sigma_m : float
        Range accuracy, 1 sigma, m (HDL-32E: < 2 cm at 25 m, docs/reference.md section 2, unverified).
    rotation_hz : float
        Head rotation rate, Hz (HDL-32E default 10 Hz); sets the azimuth step.
    beam_divergence_mrad : float
        Full beam divergence, mrad (no official HDL-32E figure; simulators use about 3 mrad,
        docs/reference.md section 2).
    nav_position_sigma_m : float
        Own-ship position error, 1 sigma per axis, m (GNSS noise and bias; default 0.5 m, a
        typical uncorrected GNSS fix, unverified; :meth:`from_scenario` reads the recording's).
    footprint_variance_scale : float
        The cluster's position covariance holds its footprint's spread, ``L^2 / 12`` along its long axis and
        ``W^2 / 12`` across (a point uniform over the footprint), times this. Default 0.1: the centre from the
        outline's two extreme points is far better known than a point anywhere on the footprint (the Table 3.2
        vessel's clusters scatter 1.1-1.3 m about their bias where the footprint term alone says 5-7 m,
        benchmarks/results/thesis_table32.md), and with the whole spread a LiDAR track of a 25 m ship took
        20 s to catch up with a wrong first velocity (crossing_silent_ship 34, 13 m behind). Tuned on
        busy_open_sea seeds 31-35 with the track's ``extent_sigma_fraction`` (1.0, 0.25, 0.1 and 0.03 tried;
        at 0.1 the median fused error within LiDAR range 2.36-2.60 -> 2.20-2.36 m).
    nav_heading_sigma_deg : float
        Own-ship heading error, 1 sigma, deg (default 0.1 deg, a GNSS compass class,
        unverified; :meth:`from_scenario` reads the recording's).
    centre : {"outline", "mean"}
        How a cluster's position is estimated (module docstring, step 7). "outline" (default):
        the midpoint of the two points farthest left and right across the line of sight;
        "mean": the mean of the points, biased toward the sensor.
    hidden_depth_fraction : float
        With ``centre`` "outline": the centre is put this fraction of half the cluster's visible width
        across the line of sight behind the outline's midpoint, for the depth of the object the sensor does
        not see (a berg's face is its near side, its centre lies behind). Default 0.6, fitted on
        busy_open_sea (seed 7, 300 s; the scenario the TDM is tuned on): the outline midpoints of its
        icebergs lay a median 4.2 m in front of their centres along the line of sight; with 0.6, 0.1 m (for a
        round object seen from afar the visible surface's midpoint lies some 0.5-0.8 of its radius in front
        of its centre). 0: the midpoint itself.
    hidden_depth_max_elongation : float
        Only clusters whose footprint length over width is under this take the hidden depth (default 3):
        a longer one is a hull side seen broadside, whose depth is the hull's beam, not its visible length.
    hidden_depth_fraction_elongated : float
        The same for a longer cluster (a hull side seen broadside): its centre lies half the beam behind the
        side seen, and a hull's beam is a fraction of its length, so it is put this fraction of half its
        visible width behind its outline's midpoint. Default 0.1 (a beam of a tenth of the visible length:
        ships are seen in part), fitted on busy_open_sea (seed 7, 300 s; 0, 0.05, 0.1, 0.13, 0.17, 0.25, 0.35
        tried: median fused error within LiDAR range 2.71, 2.60, 2.48, 2.55, 2.63, 3.28, 3.55 m).
    deskew : bool
        Map each point with the pose at its own time (True) or every point with the pose at
        the scan's first point (False, for comparison only).
    deskew_step_s : float
        The pose is computed on a grid of this step and each point takes the nearest node
        (0: each point its own pose). 0.25 ms: a point is at most 0.125 ms off its own time,
        in which a boat turning at 20 deg/s turns 0.0025 deg (4 mm at 100 m) and moves 1.3 mm
        at 10 m/s, well under the range accuracy; about 8 times fewer pose evaluations than
        points.
    range_cut_margin_m : float or None
        A cluster whose farthest point lies within this of ``range_max_m`` is flagged as cut by the range limit
        (``Detections.range_cut``): the sensor returns nothing beyond the limit, so the object may go on there,
        unseen, and its centre lie deeper than the cluster shows (busy_open_sea seeds 31-35: LiDAR tracks at the
        limit a median 5-7 m in front of their objects' centres). The tracker reports such a track with
        ``TrackerConfig.range_cut_sigma_m`` more along the line of sight. Default 1 m: the HDL-32E's returns stop
        at its rated 100 m, and 1 m is four voxels, well over its 2 cm range noise. None: no flag.
    """

    ownship_length_m: float = 10.9
    ownship_beam_m: float = 3.5
    ownship_margin_m: float = 0.5
    ownship_centre_x_m: float = 0.0
    range_min_m: float = 0.1
    range_max_m: float = 100.0
    min_height_m: float = 0.5
    voxel_m: float = 0.25
    cluster_tolerance_m: float = 0.7
    ring_link_angle_deg: float = 10.0
    ring_link_max_step: int = 2
    min_points: int = 10
    max_points: int | None = None
    min_surface_fraction: float = 0.5
    range_sigma_m: float = 0.02
    rotation_hz: float = 10.0
    beam_divergence_mrad: float = 3.0
    nav_position_sigma_m: float = 0.5
    footprint_variance_scale: float = 0.1
    nav_heading_sigma_deg: float = 0.1
    centre: Literal["outline", "mean"] = "outline"
    hidden_depth_fraction: float = 0.6
    hidden_depth_max_elongation: float = 3.0
    hidden_depth_fraction_elongated: float = 0.1
    deskew: bool = True
    deskew_step_s: float = 2.5e-4
    range_cut_margin_m: float | None = 1.0

    def __post_init__(self):
        def check(ok: bool, name: str, what: str) -> None:
            if not ok:
                raise ValueError(f"LidarFrontEndConfig.{name} must be {what}, got {getattr(self, name)!r}")

        for name in ("ownship_length_m", "ownship_beam_m", "range_max_m", "voxel_m", "cluster_tolerance_m",
                     "range_sigma_m", "rotation_hz"):
            check(getattr(self, name) > 0, name, "> 0")
        for name in ("ownship_margin_m", "range_min_m", "deskew_step_s", "beam_divergence_mrad",
                     "nav_position_sigma_m", "nav_heading_sigma_deg", "ring_link_max_step"):
            check(getattr(self, name) >= 0, name, ">= 0")
        check(self.min_points >= 1, "min_points", ">= 1")
        check(self.max_points is None or self.max_points >= self.min_points, "max_points", "None or >= min_points")
        check(0 <= self.min_surface_fraction <= 1, "min_surface_fraction", "in [0, 1]")
        check(0 <= self.ring_link_angle_deg < 90, "ring_link_angle_deg", "in [0, 90)")
        check(self.centre in ("outline", "mean"), "centre", "'outline' or 'mean'")
        check(self.range_cut_margin_m is None or 0 <= self.range_cut_margin_m < self.range_max_m, "range_cut_margin_m",
              "None or in [0, range_max_m)")

    @classmethod
    def from_scenario(cls, scenario: dict, **overrides) -> "LidarFrontEndConfig":
        """The configuration for a recording, from its resolved ``scenario.yaml``.

        Reads ``own_ship.length_m`` and ``beam_m``; ``sensors.lidar.range_min_m``,
        ``range_max_m``, ``rotation_hz`` and ``beam_divergence_mrad``; and, when present,
        ``sensors.nav`` position and heading noise and bias (combined as root sum of
        squares). Missing keys keep the defaults. The LiDAR's mount is not part of this
        configuration: :func:`lidar_mount_from_scenario` reads it.

        Parameters
        ----------
        scenario : dict
            The parsed ``scenario.yaml`` of a recording.
        **overrides
            Fields to set explicitly (win over the scenario).
        """
        values: dict = {}
        own = scenario.get("own_ship") or {}
        if own.get("length_m") is not None:
            values["ownship_length_m"] = float(own["length_m"])
        if own.get("beam_m") is not None:
            values["ownship_beam_m"] = float(own["beam_m"])
        lidar = LidarDescription.from_scenario(scenario)
        for name in ("range_min_m", "range_max_m", "rotation_hz", "beam_divergence_mrad"):
            if getattr(lidar, name) is not None:
                values[name] = getattr(lidar, name)
        nav = nav_settings(scenario)
        if any(k in nav for k in ("position_noise_m", "position_bias_m")):
            values["nav_position_sigma_m"] = math.hypot(float(nav.get("position_noise_m", 0.0)),
                                                        float(nav.get("position_bias_m", 0.0)))
        if any(k in nav for k in ("heading_noise_deg", "heading_bias_deg")):
            values["nav_heading_sigma_deg"] = math.hypot(float(nav.get("heading_noise_deg", 0.0)),
                                                         float(nav.get("heading_bias_deg", 0.0)))
        values.update(overrides)
        return cls(**values)

    @property
    def azimuth_step_rad(self) -> float:
        """Azimuth between successive firing cycles, rad (0.1659 deg at 10 Hz)."""
        return 2.0 * math.pi * self.rotation_hz * HDL32E_FIRING_CYCLE_S


def lidar_mount_from_scenario(scenario: dict) -> Mount:
    """The LiDAR's mount (``sensors.lidar.mount``) of a resolved ``scenario.yaml`` dict
    (:class:`groundfloor.recording.LidarDescription`)."""
    return LidarDescription.from_scenario(scenario).mount

"""A per-sensor tracker's parameters (:class:`TrackerConfig`) and what a detection counts towards a track's
confirmation (:func:`hit_weight`): the configuration half of :mod:`tdm.tracker`."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from tdm import ekf
from tdm.detections import Detections

__all__ = ["STRONG_HIT", "TrackerConfig", "hit_weight"]

#: What a strong detection counts towards confirmation (:class:`TrackerConfig` ``strong_from_db``), hits.
STRONG_HIT = 1.5

@dataclass(frozen=True)
class TrackerConfig:
    """Parameters of one sensor's tracker (engineering defaults, unverified).

    Attributes
    ----------
    gate_probability : float
        Probability mass inside the association gate (chi-square, 2 dof).
    confirm_m, confirm_n : int
        Confirm a track with M hits in the last N scans that could see it.
    coast_s : float
        Delete a track not updated for this long, s.
    position_floor_m2 : float
        Smallest measurement variance per axis, m^2 (covers centroid jitter as the aspect changes).
    cross_section_sigma_m2 : float
        Measurement noise of the cross-section, m^2.
    max_range_m : float
        Tracks predicted beyond this range from the own ship are out of view: no misses counted.
    init_speed_sigma_mps : float
        Speed uncertainty of a new tentative track, m/s.
    merge_distance_m : float
        Two confirmed tracks of this sensor closer than this, or than half their summed lengths,
        and moving alike (speeds within ``merge_speed_mps``) are one object.
    merge_speed_mps : float
    weak_below_db, strong_from_db : float or None
        Hits weighted by how far the detection stands out of its background
        (:attr:`~tdm.detections.Detections.strength_db`): one weaker than ``weak_below_db`` counts
        ``weak_hit`` towards confirmation, one at least ``strong_from_db`` counts 1.5, the others 1.
        Sea clutter that crosses the threshold mostly does so barely, while a target stands well
        out (busy_open_sea, sea state 4: of the plots that pass the radar front end, clutter's have a
        median strength of 11 dB and 92 % are under 13 dB, objects' a median of 23 dB and 92 % are
        from 15 dB; benchmarks/results/tdm_criteria.md), so weighting the hits lets a real target
        confirm in two scans and keeps marginal clutter from confirming in three or four. None:
        every hit counts 1 (LiDAR).
    weak_hit : float
    weak_rise_db_per_doubling, weak_rise_from_cells : float
        The weak limit of a radar plot covering more than ``weak_rise_from_cells`` of the radar's resolution cells
        (:attr:`~tdm.detections.Detections.resolution_cells`) rises by ``weak_rise_db_per_doubling`` for every
        doubling of its cells: the highest of many independent clutter cells stands further out of the clutter
        level than the highest of a few (the largest of N draws), so a wide patch of sea clutter, which the
        clutter-map detection of extended echoes
        (:attr:`~tdm.frontend.radar_config.RadarFrontEndConfig.clutter_map_detection`) joins into one plot, reaches
        13-16 dB where a few cells of it reach 11-12. Fitted on busy_open_sea seeds 1-4
        (300 s, plots of beam fill 0.5 or more at least 60 m outside every object): the 90th percentile of sea
        clutter's strength rises about 1 dB a doubling, 12.2 dB at 2-4 cells, 13.2 at 4-8, 14.3 at 8-16, 16.0 at
        32-64, and crosses ``weak_below_db`` (13 dB) at about 5 cells. The radar tracker's limit rises at that
        slope from 8 cells: weak bergs paint 13-14 dB over 5-8 cells too (busy_open_sea seed 7), and from 5 cells
        one of them went unreported. ``strong_from_db`` stays flat (raised alike it delayed two bergs, 13 -> 18 s
        and 6 -> 8 s): a plot from it counts :data:`STRONG_HIT` whatever its size (docs/tdm.md, "Tracking").
        0 (default): a flat limit.
    min_beam_fill : float or None
        A detection whose :attr:`~tdm.detections.Detections.beam_fill` is under this is narrower than an
        echo through the antenna can be (a sea spike): it counts ``weak_hit`` whatever its strength.
        None: not checked (LiDAR).
    clutter_extra_hits : float
        In a clutter area (:mod:`tdm.clutter_areas`: a cell of the polar map about the own ship where plots
        that no track takes gather), a track needs this many hits more than ``confirm_m`` to be
        confirmed. 0 (default): no map.
    clutter_cell_range_m, clutter_cell_deg, clutter_memory_scans, clutter_plots_per_scan : float
        The map's cells (depth m, width deg), its memory (scans) and the free plots a scan that make a cell
        a clutter area (:class:`tdm.clutter_areas.ClutterAreas`).
    max_speed_mps : float
        A track faster than this (20 m/s = 39 kn: faster than the ships this TDM is for) is
        deleted: it is clutter joined across scans.
    extent_sigma_fraction : float
        The sensor sees an extended object's near side: where its centre lies is uncertain by this
        fraction of the track's length (its detections' smoothed extent), per axis. Added to the
        covariance the track reports in ``sensor_tracks.jsonl``, not to the filter (the offset is a
        slowly changing bias of the object's aspect, not noise of each detection: a "consider" term, as
        in the Schmidt-Kalman filter) and not to what the fusion weighs and gates with: fed to the
        fusion it widened the track-to-track gates and absorbing radii and made the fused targets worse
        (busy_open_sea, seed 7, 300 s, radar 0.5: median error within LiDAR range 2.55 -> 3.52 m, COG
        RMSE 5.7 -> 10.2 deg; docs/tdm.md). 0: none.
    footprint_width_fraction : float or None
        Report the centre's uncertainty from the footprint over time (:attr:`Track.reported_extent_var_m2`: this
        fraction of the footprint's width, and the length seen before and not now) in place of
        ``extent_sigma_fraction`` of the length; the fusion's consider term keeps the length rule. None: the
        length rule.
    echo_hold_beam_deg : float or None
        A tentative track's detection inside the echo of a confirmed track (:func:`inside_echoes`: within this
        beamwidth plus the confirmed track's half length, as an angle, of its bearing from the own ship, and within its
        half length plus ``echo_hold_range_m`` of its range) counts nothing towards its confirmation: the radar cannot
        tell a second object there from a piece of the first's echo, and pieces of a large still echo that come and
        go from scan to scan, joined across scans, make tracks that seem to move (harbour_approach's pier and the
        ship alongside it). A boat leaving the echo is confirmed on its hits outside it. None (default): every hit
        counts.
    echo_hold_range_m : float
    range_cut_sigma_m : float
        A track last updated by a detection at the sensor's range limit (:attr:`~tdm.detections.Detections.range_cut`:
        a LiDAR cluster of an object that may go on beyond it) reports this standard deviation more along the line
        of sight from the own ship, m (:func:`tdm.fusion_face.sensor_report`; a consider term as the extent's, not
        in the filter). 0: none.
    shadow_misses : bool
        A track predicted in the shadow of one of the scan's detections (farther than it, within the bearings its
        extent across the line of sight covers: :func:`tdm.shadows.shadowed`) that gets no detection records no miss:
        the sensor cannot see there, so it is no evidence against the track (a berg behind a nearer berg). Its coast
        (``coast_s``) still runs. False (default): every unassigned track within ``max_range_m`` misses.
    course_retry_s : float
        A track whose first two detections were too close for their velocity to tell its course (the two-point
        speed under ``COURSE_SIGMAS`` of its standard deviation) tries again from its first detection to each
        later one for this long after it started, s, as the velocity's uncertainty falls with the time between
        them: a 6 m/s ship whose radar plots scatter 5-7 m across the beam moves 15 m between two sweeps, under
        two standard deviations of that two-point velocity, and a track left with an unknown course and no speed
        cannot learn either (its position's change with the course is the speed times the time: none), so its
        plots leave it behind. 0 (default): the second detection only.
    process : ekf.ProcessNoise
    """

    gate_probability: float = 0.999
    confirm_m: int = 3
    confirm_n: int = 5
    coast_s: float = 3.0
    position_floor_m2: float = 1.0
    cross_section_sigma_m2: float = 50.0
    max_range_m: float = 100.0
    init_speed_sigma_mps: float = 8.0
    merge_distance_m: float = 10.0
    merge_speed_mps: float = 3.0
    weak_below_db: float | None = None
    strong_from_db: float | None = None
    weak_hit: float = 0.5
    weak_rise_db_per_doubling: float = 0.0
    weak_rise_from_cells: float = 8.0
    min_beam_fill: float | None = None
    clutter_extra_hits: float = 0.0
    shadow_misses: bool = False
    clutter_cell_range_m: float = 200.0
    clutter_cell_deg: float = 30.0
    clutter_memory_scans: float = 20.0
    clutter_plots_per_scan: float = 0.1
    max_speed_mps: float = 20.0
    extent_sigma_fraction: float = 0.0
    range_cut_sigma_m: float = 0.0
    course_retry_s: float = 0.0
    footprint_width_fraction: float | None = None
    echo_hold_beam_deg: float | None = None
    echo_hold_range_m: float = 10.0
    process: ekf.ProcessNoise = field(default_factory=ekf.ProcessNoise)


def _rise_db(config: TrackerConfig, resolution_cells: float) -> float:
    """How far the weak limit rises for a plot of ``resolution_cells`` resolution cells, dB:
    ``weak_rise_db_per_doubling`` per doubling of the cells over ``weak_rise_from_cells``, 0 under it."""
    over = resolution_cells / config.weak_rise_from_cells
    return config.weak_rise_db_per_doubling * math.log2(over) if over > 1.0 else 0.0


def hit_weight(config: TrackerConfig, dets: Detections, j: int) -> float:
    """What detection ``j`` of ``dets`` counts towards confirmation (:class:`TrackerConfig`, weak and strong hits):
    ``weak_hit`` for a plot narrower than the beam paints (``min_beam_fill``) or under ``weak_below_db``,
    :data:`STRONG_HIT` from ``strong_from_db``, else 1; the weak limit raised for a wide plot
    (``weak_rise_db_per_doubling``); 1 without a strength (LiDAR)."""
    if config.min_beam_fill is not None and dets.beam_fill is not None and dets.beam_fill[j] < config.min_beam_fill:
        return config.weak_hit
    if dets.strength_db is None:
        return 1.0
    strength = float(dets.strength_db[j])
    if config.strong_from_db is not None and strength >= config.strong_from_db:
        return STRONG_HIT
    cells = float(dets.resolution_cells[j]) if dets.resolution_cells is not None else 0.0
    if config.weak_below_db is not None and strength < config.weak_below_db + _rise_db(config, cells):
        return config.weak_hit
    return 1.0

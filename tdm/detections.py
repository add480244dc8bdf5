"""What the front ends hand to the trackers: one scan's detections in ENU.

A scan is one LiDAR revolution or one radar sweep. Each detection is a cluster
(LiDAR) or a plot (radar) reduced to a position with a covariance, a size and
its own time. AIS reports are a separate type (:class:`AisReport`), keyed by MMSI.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from groundfloor.ais import NAV_STATUS_NOT_DEFINED


@dataclass
class Detections:
    """The detections of one scan.

    Attributes
    ----------
    sensor : str
        ``"lidar"`` or ``"radar"``.
    scan_time_s : float
        The scan's reference time (its first point or spoke), s since the recording's start.
    time_s : (N,) float64
        Each detection's own time (mean time of its points or spokes), s.
    position_m : (N, 2) float64
        Centroid in ENU (east, north), metres.
    position_cov_m2 : (N, 2, 2) float64
        Measurement covariance of the position, m^2, from the geometry (extent, resolution).
    cross_section_m2 : (N,) float64
        Size measure: the visible footprint area, m^2 (the thesis's cross-section).
    length_m, width_m : (N,) float64
        Oriented footprint box, metres (length >= width).
    orientation_deg : (N,) float64
        Direction of the box's long side, compass degrees in [0, 180).
    height_m : (N,) float64
        Top of the cluster above the sea, metres (NaN for radar).
    n_cells : (N,) int64
        Points (LiDAR) or range-azimuth cells (radar) in the detection.
    range_m : (N,) float64
        Distance from the sensor, metres.
    strength_db : (N,) float64 or None
        How far each detection stands out of its background, dB: for a radar plot, its peak
        beam-integrated power over the local clutter level (:func:`tdm.frontend.radar.clutter_map`).
        None when the front end has no such measure (LiDAR).
    beam_fill : (N,) float64 or None
        For a radar plot, its azimuth extent over the extent the two-way antenna beam paints
        between the plot's strongest and weakest cells (:func:`tdm.frontend.radar.radar_detections`):
        about 1 or more for an echo received through the antenna, well under 1 for a return
        narrower than the beam can make (a sea spike, interference). None for LiDAR.
    core_width_m : (N,) float64 or None
        For a radar plot, the cross-range width of its core (cells within ``core_db`` of its strongest) less
        the beam's, m (:func:`tdm.frontend.radar.radar_detections`): the size of an object the beam smears.
        None for LiDAR.
    resolution_cells : (N,) float64 or None
        For a radar plot, how many of the radar's resolution cells (a beamwidth by a range resolution) its cells
        cover: ``n_cells`` times the spoke step over ``beam_az_deg`` times the sample spacing over
        ``range_resolution_m`` (:func:`tdm.frontend.radar.radar_detections`), the independent looks at the sea a
        clutter plot of its size holds, whatever the sweep's spokes and samples. None for LiDAR.
    echo_spread_m : (N,) float64 or None
        For a radar plot, how much further the echo it is a fragment of reaches than the plot, m (plots along one
        spoke within :attr:`~tdm.frontend.radar_config.RadarFrontEndConfig.echo_gap_m` of each other are one
        echo; :func:`tdm.frontend.radar_echoes.fragment_spread_m`): 0 for a plot that is its echo. None for LiDAR.
    range_cut : (N,) bool or None
        For a LiDAR cluster, whether its farthest point lies at the sensor's range limit (within
        :attr:`~tdm.frontend.lidar_config.LidarFrontEndConfig.range_cut_margin_m`): its object may go on beyond the
        limit, unseen, and its centre lie metres deeper than the cluster shows. None for radar.
    """

    sensor: str
    scan_time_s: float
    time_s: np.ndarray
    position_m: np.ndarray
    position_cov_m2: np.ndarray
    cross_section_m2: np.ndarray
    length_m: np.ndarray
    width_m: np.ndarray
    orientation_deg: np.ndarray
    height_m: np.ndarray
    n_cells: np.ndarray
    range_m: np.ndarray
    strength_db: np.ndarray | None = None
    beam_fill: np.ndarray | None = None
    core_width_m: np.ndarray | None = None
    echo_spread_m: np.ndarray | None = None
    resolution_cells: np.ndarray | None = None
    range_cut: np.ndarray | None = None

    def __len__(self) -> int:
        return int(self.time_s.shape[0])

    def subset(self, keep: np.ndarray) -> "Detections":
        """The detections where ``keep`` (N,) bool is True, every per-detection array cut alike."""
        n = len(self)
        return Detections(**{name: (value[keep] if isinstance(value, np.ndarray) and value.shape[:1] == (n,)
                                    else value) for name, value in vars(self).items()})

    @classmethod
    def empty(cls, sensor: str, scan_time_s: float) -> "Detections":
        z = np.zeros(0)
        return cls(sensor, float(scan_time_s), z, np.zeros((0, 2)), np.zeros((0, 2, 2)), z, z, z, z, z,
                   np.zeros(0, dtype=np.int64), z)


@dataclass
class AisReport:
    """One decoded AIS position report in ENU.

    Attributes
    ----------
    time_s : float
        Reception time, s since the recording's start (from the TAG block).
    mmsi : int
    position_m : (2,) float64
        ENU (east, north), metres.
    cog_deg, sog_mps : float
        Course and speed over ground (NaN when not available).
    heading_deg : float
        True heading (NaN when not available, AIS 511).
    rot_deg_per_min : float
        Rate of turn (NaN when not available).
    msg_type : int
    nav_status : int
        Navigational status of a Class A report (ITU-R M.1371-5, message 1-3 bits 38-41: 0 under way using
        engine, 1 at anchor, 5 moored, ...); :data:`groundfloor.ais.NAV_STATUS_NOT_DEFINED` (15) for Class B reports, which carry
        none.
    position_extra_var_m2 : float
        Variance per axis, m^2, to add to the AIS position noise: where the report's reference point (its GNSS
        antenna) lies off the hull's centre by an amount or in a direction the static data and the report do
        not give (:mod:`tdm.frontend.ais_reference`); 0 where ``position_m`` is the centre or no static data say
        otherwise.
    centre_offset_m : (2,) float64 or None
        East and north, m, by which ``position_m`` was moved from the transponder's reference point to the hull's
        centre; None where it was not moved.
    """

    time_s: float
    mmsi: int
    position_m: np.ndarray
    cog_deg: float
    sog_mps: float
    heading_deg: float
    rot_deg_per_min: float
    msg_type: int
    nav_status: int = NAV_STATUS_NOT_DEFINED
    position_extra_var_m2: float = 0.0
    centre_offset_m: np.ndarray | None = None


@dataclass
class AisStatic:
    """Static data of one MMSI (types 5, 19 and 24): name, ship type and dimensions in metres.

    ``to_bow_m``, ``to_stern_m``, ``to_port_m``, ``to_starboard_m``: the reference point of the reported
    positions (the GNSS antenna) from the bow, stern, port and starboard sides (ITU-R M.1371-5 dimensions A, B, C,
    D), as the latest static message gave them (NaN before any; 0 as sent); ``length_m = A + B`` and
    ``beam_m = C + D`` (NaN where the sum is 0: not available)."""

    mmsi: int
    name: str = ""
    ship_type: int = 0
    length_m: float = float("nan")
    beam_m: float = float("nan")
    to_bow_m: float = float("nan")
    to_stern_m: float = float("nan")
    to_port_m: float = float("nan")
    to_starboard_m: float = float("nan")


@dataclass
class ReadStats:
    """Counted problems met while reading a recording (printed as warnings, kept in metrics)."""

    warnings: dict[str, int] = field(default_factory=dict)

    def count(self, what: str, n: int = 1) -> None:
        self.warnings[what] = self.warnings.get(what, 0) + n

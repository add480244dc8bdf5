"""LiDAR front end: one Velodyne revolution in, clusters as :class:`~tdm.detections.Detections` out.

Steps (all vectorised, over one sweep or a batch of them, :func:`lidar_clusters_batch`; the graph's
parts are in :mod:`tdm.frontend.lidar_graph`):

1. **Own ship.** ~85 % of a sweep's points hit the own ship. They are dropped first and
   cheaply by a box test in the body frame (sensor points moved by the mount): a vertical
   column ``|x - ownship_centre_x_m| <= length/2 + margin``, ``|y| <= beam/2 + margin``.
   The column is unbounded in z: the HDL-32E looks at most 10.67 deg up (docs/reference.md
   section 2), so nothing but the own ship can be inside it.
2. **Bad returns.** Non-finite points and ranges outside ``[range_min_m, range_max_m]``
   (0 = no return in the Velodyne encoding) are dropped.
3. **Deskew.** Each point goes to ENU with the own-ship pose at its own firing time
   (as :meth:`tdm.frames.OwnshipTrack.sensor_to_enu`; the pose is evaluated on a grid of
   ``deskew_step_s`` and each point takes the nearest node), which undoes the
   rolling-shutter distortion from own-ship yaw, roll, pitch, heave and speed.
4. **Sea.** Points below ``min_height_m`` in ENU are sea and foam: the sea surface is the
   plane z = 0 of the ENU frame (wave motion shows up in the own ship's pose, which step 3
   removes), so returns from foam and wakes lie within centimetres of z = 0. **Land**: with the
   recording's chart (``land``, :mod:`tdm.land`), points on land or within its margin go too.
5. **Voxels.** Points are binned into vertical columns ("pillars", 2D voxels) of
   ``voxel_m`` on the horizontal plane (``np.unique`` of integer keys, with a count per
   voxel); each voxel is represented by the mean of its points.
6. **Clustering.** A graph on voxels, cut into connected components
   (:func:`~tdm.frontend.lidar_graph.components`, the
   labels of ``scipy.sparse.csgraph.connected_components``), has two kinds of edge:

   * Euclidean (PCL/Autoware): voxel centres closer than ``cluster_tolerance_m`` on the
     horizontal plane (the pairs of ``cKDTree.query_pairs``, found on the voxel grid:
     :func:`~tdm.frontend.lidar_graph.voxel_pairs`). Clustering on the horizontal plane
     joins the parts of a target seen at different heights.
   * Range-image links (Bogoslavskyi & Stachniss 2016, "Fast range image-based
     segmentation of sparse 3D laser scans for online operation", IROS;
     PRBonn/depth_clustering): each point is joined to its neighbour along its ring (the
     same laser's next firing) and to the nearest point in azimuth of the next one or two
     rings up, when the angle ``beta = atan2(d2 sin a, d1 - d2 cos a)`` (``d1 >= d2`` the
     two ranges, ``a`` the angle between the two rays) exceeds ``ring_link_angle_deg``,
     i.e. when the two points lie on one surface that is not nearly parallel to the rays,
     and when they were fired within ``LINK_WINDOW_CYCLES`` firing cycles (not across the
     sweep's seam, where the own ship has moved for a revolution). The HDL-32E's rings are 1.333 deg apart, so on a sloping iceberg they fall metres
     apart on the horizontal plane (2-5 m at 40 m range, measured on busy_open_sea) and a
     fixed 0.7 m tolerance alone splits one berg into a cluster per ring (62 % of the
     bergs' sweeps there; 3 % with these links, the rest being pieces of a berg more than
     5 m apart above the sea, or cut by the range limit).

   Clusters with fewer than ``min_points`` raw points (or more than ``max_points``) are
   dropped, and so are clusters in which fewer than ``min_surface_fraction`` of the points
   have a same-surface neighbour along their ring: echoes of rain and fog drops are
   isolated (successive firings of a laser almost never both hit a drop), surfaces are not.

7. **Per cluster** (from the raw points, vectorised with ``np.bincount``,
   ``np.maximum.reduceat`` and one ``np.lexsort``):

   * position: the LiDAR sees only the side facing it, so the mean of the points lies
     toward the sensor by most of the target's half depth (median 8.4 m, up to 9.9 m, for
     the 15 m-radius bergs of busy_open_sea whose centre is within 100 m). By default (``centre="outline"``) the centre
     is the midpoint of the cluster's two outline points, the points farthest left and
     right across the line of sight: for a convex target whose footprint is symmetric
     about its centre (box, ellipse, disc) seen from afar these are the ends of its widest
     section across the line of sight, whose midpoint is the centre (exact for a box,
     short by ``r^2 / D`` for a disc of radius r at distance D). Measured against truth:
     median 4.4 m, at most 7.5 m, for those bergs; median 2.8 m, 90th percentile 5.2 m,
     for ships of 12-50 m at all aspects (the mean: 3.9 m and 10.9 m).
     ``centre="mean"`` gives the plain mean of the points.
   * footprint box by PCA of the horizontal points: length along the principal axis,
     width across (length >= width), orientation of the long side in compass degrees in
     [0, 180); cross-section = length x width;
   * height = highest ENU z; n_cells = raw points; time = mean point time; range =
     horizontal distance from the sensor (at that time) to the position.

Position covariance (ENU, m^2), a sum of independent terms:

``P = R_box diag(L^2, W^2)/12 R_box^T + R_los diag(s_r^2, s_c^2) R_los^T + s_nav^2 I``

* footprint spread: the variance of a uniform distribution over the box (L x W),
  rotated from the box axes to ENU; it stands for where on the target the estimate lies
  (the visible-side bias left, partial occlusion) and grows with the target;
* sensor: along the line of sight ``s_r = range_sigma_m``; across it
  ``s_c^2 = r^2 (da^2/12 + div^2/16 + s_psi^2)`` with ``da = 360 deg x rotation_hz x
  46.08 us`` the azimuth step (uniform quantisation), ``div`` the full beam divergence
  (a uniform disc of diameter ``r div``: variance ``(r div)^2/16`` per axis) and
  ``s_psi`` the own ship's heading error, which turns every point about the sensor; it
  grows with range ``r``;
* navigation: ``s_nav`` the own-ship position error per axis, shared by every point.

``s_r > 0`` keeps P positive definite for any cluster, even a single point.

Range cut: a cluster whose farthest point lies within ``range_cut_margin_m`` of ``range_max_m`` is flagged
(``Detections.range_cut``): the sensor returns nothing beyond its range limit, so the object may go on there and
its centre lie metres deeper than any of the above says. The position and covariance are left as they are (the
offset is a bias shared by the scans of the object while it stays at the limit, which the filter would average
away); the tracker reports it as a consider term (``TrackerConfig.range_cut_sigma_m``).

The settings are :class:`LidarFrontEndConfig` (:mod:`tdm.frontend.lidar_config`), importable from here too.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from tdm.detections import Detections
from tdm.frames import Mount, OwnshipTrack
from tdm.frontend.lidar_config import (HDL32E_FIRING_CYCLE_S, LINK_WINDOW_CYCLES, LidarFrontEndConfig,
                                       lidar_mount_from_scenario)
from tdm.frontend.lidar_graph import components, range_image_links, voxel_grid, voxel_pairs
from tdm.land import LandMask

__all__ = ["HDL32E_FIRING_CYCLE_S", "LIDAR_FIELDS", "LINK_WINDOW_CYCLES", "LidarFrontEndConfig", "lidar_clusters",
           "lidar_clusters_batch", "lidar_detections", "lidar_detections_batch", "lidar_mount_from_scenario"]

#: The sweep arrays the front end reads (what ``tdm run`` loads of a LiDAR sweep file).
LIDAR_FIELDS = ("x", "y", "z", "ring", "time")
#: Variance of a uniform distribution over a width w: w^2 / 12 (footprint box, azimuth step).
UNIFORM_VARIANCE_DIVISOR = 12.0
#: Variance per axis of a uniform disc of diameter d: d^2 / 16 (beam divergence).
DISC_VARIANCE_DIVISOR = 16.0
RAD_PER_MRAD = 1e-3
#: A mount rotation this close to the identity is taken as none (the own-ship test skips the product).
_IDENTITY_ATOL = 1e-12


def lidar_detections(sweep: dict[str, np.ndarray], track: OwnshipTrack, mount: Mount,
                     config: LidarFrontEndConfig | None = None, land: LandMask | None = None) -> Detections:
    """Clusters of one LiDAR revolution as detections in ENU (module docstring for the method).

    Parameters
    ----------
    sweep : dict of (N,) arrays
        One revolution with the recording contract's fields: ``x``, ``y``, ``z`` (float32,
        sensor frame, m), ``ring`` (uint8), ``time`` (float64, s since the recording's
        start); ``intensity`` and ``azimuth_deg`` may be present. Other fields (such as the
        truth ``object_id``) are ignored.
    track : OwnshipTrack
        The own ship's navigation solution (pose at each point's time).
    mount : Mount
        The LiDAR's mounting on the own ship.
    config : LidarFrontEndConfig, optional
        Settings; default ``LidarFrontEndConfig()``.
    land : tdm.land.LandMask, optional
        The chart's land mask: points on it are dropped before clustering (none without).

    Returns
    -------
    Detections
        ``sensor="lidar"``, one row per cluster (see :class:`tdm.detections.Detections`);
        ``scan_time_s`` is the sweep's first point time.
    """
    return lidar_clusters(sweep, track, mount, config, land)[0]


def lidar_detections_batch(sweeps: list[dict[str, np.ndarray]], track: OwnshipTrack, mount: Mount,
                           config: LidarFrontEndConfig | None = None,
                           land: LandMask | None = None) -> list[Detections]:
    """:func:`lidar_detections` of each of several sweeps, computed together (:func:`lidar_clusters_batch`)."""
    return [result[0] for result in lidar_clusters_batch(sweeps, track, mount, config, land)]


def lidar_clusters(sweep: dict[str, np.ndarray], track: OwnshipTrack, mount: Mount,
                   config: LidarFrontEndConfig | None = None,
                   land: LandMask | None = None) -> tuple[Detections, np.ndarray, np.ndarray]:
    """:func:`lidar_detections` plus which sweep points make up each detection.

    Parameters
    ----------
    sweep, track, mount, config, land
        As for :func:`lidar_detections`.

    Returns
    -------
    detections : Detections
        As :func:`lidar_detections` returns.
    point_index : (M,) int64
        Indices into the sweep's arrays of the points that belong to a detection.
    point_label : (M,) int64
        The detection (row of ``detections``) of each of those points.
    """
    return lidar_clusters_batch([sweep], track, mount, config, land)[0]


def lidar_clusters_batch(sweeps: list[dict[str, np.ndarray]], track: OwnshipTrack, mount: Mount,
                         config: LidarFrontEndConfig | None = None,
                         land: LandMask | None = None) -> list[tuple[Detections, np.ndarray, np.ndarray]]:
    """:func:`lidar_clusters` of several sweeps at once, each as it would be alone.

    The sweeps' points go through every step together, each point tagged with its sweep, which every
    grouping key leads with (:mod:`tdm.frontend.lidar_graph`): one pass of each array operation for the
    batch instead of one per sweep, whose cost on the few thousand points a sweep has off the own ship
    is mostly numpy's per-call overhead. Every operation is element by element, or a sum or extreme
    over the points of one voxel or cluster in their sweep's order, so each sweep's result is the one
    :func:`lidar_clusters` gives for it alone (tested).

    Parameters
    ----------
    sweeps : list of dict of (N_s,) arrays
        Revolutions as :func:`lidar_detections` takes them, in any order; their arrays of one
        name must share a dtype.
    track, mount, config, land
        As for :func:`lidar_detections`.

    Returns
    -------
    list of (Detections, point_index, point_label)
        For each sweep, what :func:`lidar_clusters` returns.
    """
    config = config or LidarFrontEndConfig()
    if len({tuple(np.asarray(s[k]).dtype.str for k in LIDAR_FIELDS) for s in sweeps}) > 1:  # the arithmetic differs
        return [lidar_clusters_batch([s], track, mount, config, land)[0] for s in sweeps]
    times = [np.asarray(s["time"], dtype=np.float64) for s in sweeps]
    scan_time_s = np.array([float(t.min()) if t.size else math.nan for t in times])
    n_points = np.array([t.shape[0] for t in times], dtype=np.int64)
    x, y, z, ring = (np.concatenate([np.asarray(s[k]) for s in sweeps]) for k in ("x", "y", "z", "ring"))
    sweep_of_point = np.repeat(np.arange(len(sweeps)), n_points)
    idx, sensor_points, t, range_m = _good_returns(_off_ship(x, y, z, mount, config), x, y, z,
                                                   np.concatenate(times), config)
    if idx.size == 0:
        return [_nothing(s) for s in scan_time_s]
    sweep = sweep_of_point[idx]
    # 3. deskew: every point with the pose at its own time
    enu = _deskewed(track, sensor_points, t if config.deskew else scan_time_s[sweep], sweep, mount,
                    config.deskew_step_s)
    # 4. sea and foam (and the chart's land)
    above = enu[:, 2] >= config.min_height_m
    if land is not None and above.any():  # the chart's land (tdm.land): its points make no cluster
        above &= ~land.contains(enu[:, 0], enu[:, 1])
    if not above.any():
        return [_nothing(s) for s in scan_time_s]
    enu, sensor_points, t, range_m, idx, sweep = (a[above] for a in (enu, sensor_points, t, range_m, idx, sweep))
    # 5., 6. voxels, their graph and its clusters; clusters of too few points or of weather dropped
    label, on_surface = _cluster_labels(enu, sweep, ring[idx].astype(np.int64), sensor_points, range_m, t, config)
    good, counts = _kept_clusters(label, on_surface, config)
    if not good.any():
        return [_nothing(s) for s in scan_time_s]
    member = good[label]
    label = (np.cumsum(good) - 1)[label[member]]
    enu, t, idx, sweep, range_m = enu[member], t[member], idx[member], sweep[member], range_m[member]
    n_cells = counts[good].astype(np.int64)
    cluster_sweep = np.zeros(n_cells.shape[0], dtype=np.int64)
    cluster_sweep[label] = sweep
    detections = _cluster_detections(enu, t, label, n_cells, scan_time_s[cluster_sweep], track, mount, config,
                                     range_m)
    point_start = np.cumsum(n_points) - n_points
    return _per_sweep(detections, scan_time_s, cluster_sweep, idx - point_start[sweep], label, sweep)


def _cluster_detections(enu: np.ndarray, t: np.ndarray, label: np.ndarray, n_cells: np.ndarray,
                        scan_time_s: np.ndarray, track: OwnshipTrack, mount: Mount,
                        config: LidarFrontEndConfig, range_m: np.ndarray) -> dict[str, np.ndarray]:
    """Step 7: the (k,) per-cluster fields of :class:`Detections` of the member points (``label`` (M,),
    ``n_cells`` (k,) points a cluster, ``scan_time_s`` (k,) of each cluster's sweep, ``range_m`` (M,) each
    point's range from the sensor, m)."""
    fp = _footprints(enu, t, label, n_cells, range_m)
    sensor_enu = track.sensor_to_enu(np.zeros((n_cells.shape[0], 3)), fp.mean_t if config.deskew else scan_time_s,
                                     mount)
    if config.centre == "outline":
        depth_fraction = np.where(fp.length_m < config.hidden_depth_max_elongation * fp.width_m,
                                  config.hidden_depth_fraction, config.hidden_depth_fraction_elongated)
        centre_e, centre_n = _outline_centres(enu, label, n_cells, fp, sensor_enu, depth_fraction)
    else:
        centre_e, centre_n = fp.mean_e, fp.mean_n
    los_e = centre_e - sensor_enu[:, 0]
    los_n = centre_n - sensor_enu[:, 1]
    horizontal_range_m = np.hypot(los_e, los_n)
    return dict(time_s=fp.mean_t, position_m=np.stack([centre_e, centre_n], axis=1),
                position_cov_m2=_cluster_cov(fp, los_e, los_n, horizontal_range_m, config),
                cross_section_m2=fp.length_m * fp.width_m, length_m=fp.length_m, width_m=fp.width_m,
                orientation_deg=np.mod(90.0 - np.degrees(fp.phi_long), 180.0), height_m=fp.height_m,
                n_cells=n_cells, range_m=horizontal_range_m, range_cut=_range_cut(fp, config))


def _per_sweep(fields: dict[str, np.ndarray], scan_time_s: np.ndarray, cluster_sweep: np.ndarray,
               point_index: np.ndarray, point_label: np.ndarray,
               point_sweep: np.ndarray) -> list[tuple[Detections, np.ndarray, np.ndarray]]:
    """The batch's clusters (k,) and member points (M,) cut into one (Detections, point_index, point_label)
    per sweep; clusters and points come sweep by sweep (the graph's keys lead with the sweep)."""
    bounds = np.arange(scan_time_s.shape[0] + 1)
    cluster_cut = np.searchsorted(cluster_sweep, bounds)
    point_cut = np.searchsorted(point_sweep, bounds)
    out = []
    for s, scan_time in enumerate(scan_time_s):
        c0, c1 = int(cluster_cut[s]), int(cluster_cut[s + 1])
        if c0 == c1:
            out.append(_nothing(scan_time))
            continue
        p0, p1 = int(point_cut[s]), int(point_cut[s + 1])
        detections = Detections(sensor="lidar", scan_time_s=float(scan_time),
                                **{name: value[c0:c1] for name, value in fields.items()})
        out.append((detections, point_index[p0:p1], point_label[p0:p1] - c0))
    return out


def _off_ship(x: np.ndarray, y: np.ndarray, z: np.ndarray, mount: Mount, config: LidarFrontEndConfig) -> np.ndarray:
    """Indices of the points outside the own ship's body-frame column (step 1), in the sweep's own
    precision (float32)."""
    rot, _, identity = _mount_pose(mount)
    dx = mount.x_m - config.ownship_centre_x_m
    if identity:
        body_x, body_y = x + dx, y + mount.y_m
    else:
        body_x = rot[0, 0] * x + rot[0, 1] * y + rot[0, 2] * z + dx
        body_y = rot[1, 0] * x + rot[1, 1] * y + rot[1, 2] * z + mount.y_m
    half_length = 0.5 * config.ownship_length_m + config.ownship_margin_m
    half_beam = 0.5 * config.ownship_beam_m + config.ownship_margin_m
    return np.nonzero((np.abs(body_x) > half_length) | (np.abs(body_y) > half_beam))[0]


@functools.lru_cache(maxsize=16)
def _mount_pose(mount: Mount) -> tuple[np.ndarray, np.ndarray, bool]:
    """A mount's (3, 3) sensor-to-body rotation and (3,) translation (m), read-only, and whether the
    rotation is the identity: formed once per mount, not once per sweep."""
    rotation, translation = mount.rotation(), mount.translation_m()
    rotation.flags.writeable = translation.flags.writeable = False
    return rotation, translation, bool(np.allclose(rotation, np.eye(3), rtol=0.0, atol=_IDENTITY_ATOL))


def _good_returns(idx: np.ndarray, x: np.ndarray, y: np.ndarray, z: np.ndarray, time_s: np.ndarray,
                  config: LidarFrontEndConfig) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Of the points ``idx``, those with a finite return within the range limits (step 2): their
    indices, sensor-frame points (N, 3) m, times s and ranges m."""
    sensor_points = np.stack([x[idx], y[idx], z[idx]], axis=1).astype(np.float64)
    t = time_s[idx]
    range_m = np.sqrt(np.einsum("ij,ij->i", sensor_points, sensor_points))
    ok = np.isfinite(range_m) & np.isfinite(t) & (range_m > 0)
    ok &= (range_m >= config.range_min_m) & (range_m <= config.range_max_m)
    return idx[ok], sensor_points[ok], t[ok], range_m[ok]


def _cluster_labels(enu: np.ndarray, sweep: np.ndarray, ring: np.ndarray, sensor_points: np.ndarray,
                    range_m: np.ndarray, t: np.ndarray, config: LidarFrontEndConfig) -> tuple[np.ndarray, np.ndarray]:
    """Each point's cluster (steps 5 and 6: voxels, Euclidean pairs of voxels + ring links, connected
    components; numbered sweep by sweep), and whether it lies on a surface along its ring."""
    grid = voxel_grid(enu, sweep, config.voxel_m, config.cluster_tolerance_m)
    pair_i, pair_j = voxel_pairs(grid, config.cluster_tolerance_m)
    link_i, link_j, on_surface = range_image_links(ring, sweep, sensor_points, range_m, t, config)
    link_i, link_j = grid.inverse[link_i], grid.inverse[link_j]
    between = link_i != link_j
    rows = np.concatenate([pair_i, link_i[between]])
    cols = np.concatenate([pair_j, link_j[between]])
    return components(rows, cols, grid.keys.shape[0])[grid.inverse], on_surface


def _kept_clusters(label: np.ndarray, on_surface: np.ndarray, config: LidarFrontEndConfig
                   ) -> tuple[np.ndarray, np.ndarray]:
    """(C,) bool clusters kept (size in raw points, echoes from surfaces rather than weather) and (C,)
    their point counts."""
    counts = np.bincount(label)
    good = counts >= config.min_points
    if config.max_points is not None:
        good &= counts <= config.max_points
    good &= np.bincount(label, on_surface, counts.shape[0]) >= config.min_surface_fraction * counts
    return good, counts


@dataclass
class _Footprint:
    """Per cluster (k,): mean point (m), mean time (s), height (m), footprint box (m) and the ENU angle
    of its long side (rad); each cluster's first position in the points sorted by cluster; the range of its
    farthest point from the sensor (m)."""

    mean_e: np.ndarray
    mean_n: np.ndarray
    mean_t: np.ndarray
    height_m: np.ndarray
    length_m: np.ndarray
    width_m: np.ndarray
    phi_long: np.ndarray
    starts: np.ndarray
    farthest_m: np.ndarray


def _footprints(enu: np.ndarray, t: np.ndarray, label: np.ndarray, n_cells: np.ndarray,
                range_m: np.ndarray) -> _Footprint:
    """Mean, height, PCA footprint box and farthest point's range (``range_m`` (M,), m) of every cluster (step 7),
    vectorised over clusters."""
    k = n_cells.shape[0]
    order = np.argsort(label, kind="stable")
    starts = np.concatenate([[0], np.cumsum(n_cells)[:-1]])
    mean_e = np.bincount(label, enu[:, 0], k) / n_cells
    mean_n = np.bincount(label, enu[:, 1], k) / n_cells
    mean_t = np.bincount(label, t, k) / n_cells
    height_m = np.maximum.reduceat(enu[order, 2], starts)
    de = enu[:, 0] - mean_e[label]
    dn = enu[:, 1] - mean_n[label]
    c_ee = np.bincount(label, de * de, k) / n_cells
    c_nn = np.bincount(label, dn * dn, k) / n_cells
    c_en = np.bincount(label, de * dn, k) / n_cells
    # footprint box: principal axis of the 2x2 scatter [[c_ee, c_en], [c_en, c_nn]] at ENU angle phi
    phi = 0.5 * np.arctan2(2.0 * c_en, c_ee - c_nn)
    along = de * np.cos(phi)[label] + dn * np.sin(phi)[label]
    across = -de * np.sin(phi)[label] + dn * np.cos(phi)[label]
    extent_along = np.maximum.reduceat(along[order], starts) - np.minimum.reduceat(along[order], starts)
    extent_across = np.maximum.reduceat(across[order], starts) - np.minimum.reduceat(across[order], starts)
    swap = extent_across > extent_along
    length_m = np.where(swap, extent_across, extent_along)
    width_m = np.where(swap, extent_along, extent_across)
    phi_long = np.where(swap, phi + 0.5 * np.pi, phi)
    return _Footprint(mean_e, mean_n, mean_t, height_m, length_m, width_m, phi_long, starts,
                      np.maximum.reduceat(range_m[order], starts))


def _outline_centres(enu: np.ndarray, label: np.ndarray, n_cells: np.ndarray, fp: _Footprint,
                     sensor_enu: np.ndarray, depth_fraction: np.ndarray | float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """(k,) east and north of each cluster's centre, m: the midpoint of its two outline points, farthest
    left and right across the line of sight from the sensor to the points' mean (step 7), moved
    ``depth_fraction`` (k,) of half the distance between them further along the line of sight (the depth
    the sensor does not see)."""
    los_angle = np.arctan2(fp.mean_n - sensor_enu[:, 1], fp.mean_e - sensor_enu[:, 0])
    u_e, u_n = np.cos(los_angle), np.sin(los_angle)
    rel_e = enu[:, 0] - sensor_enu[label, 0]
    rel_n = enu[:, 1] - sensor_enu[label, 1]
    depth = rel_e * u_e[label] + rel_n * u_n[label]
    cross = -rel_e * u_n[label] + rel_n * u_e[label]
    by_cross = np.lexsort((cross, label))
    left = by_cross[fp.starts]
    right = by_cross[fp.starts + n_cells - 1]
    centre_cross = 0.5 * (cross[left] + cross[right])
    centre_depth = 0.5 * (depth[left] + depth[right]) + depth_fraction * 0.5 * (cross[right] - cross[left])
    centre_e = sensor_enu[:, 0] + centre_depth * u_e - centre_cross * u_n
    centre_n = sensor_enu[:, 1] + centre_depth * u_n + centre_cross * u_e
    return centre_e, centre_n


def _range_cut(fp: _Footprint, config: LidarFrontEndConfig) -> np.ndarray:
    """(k,) bool: the cluster's farthest point lies within ``range_cut_margin_m`` of the sensor's range limit, so its
    object may go on beyond the limit, unseen (all False when the margin is None)."""
    if config.range_cut_margin_m is None:
        return np.zeros(fp.length_m.shape[0], dtype=bool)
    return fp.farthest_m >= config.range_max_m - config.range_cut_margin_m


def _cluster_cov(fp: _Footprint, los_e: np.ndarray, los_n: np.ndarray, horizontal_range_m: np.ndarray,
                 config: LidarFrontEndConfig) -> np.ndarray:
    """(k, 2, 2) ENU position covariance, m^2: footprint spread + sensor + navigation (module docstring)."""
    k = fp.length_m.shape[0]
    cov = config.footprint_variance_scale * _axes_cov(fp.phi_long, fp.length_m ** 2 / UNIFORM_VARIANCE_DIVISOR,
                                                      fp.width_m ** 2 / UNIFORM_VARIANCE_DIVISOR)
    cross_var = horizontal_range_m ** 2 * (config.azimuth_step_rad ** 2 / UNIFORM_VARIANCE_DIVISOR
                                           + (RAD_PER_MRAD * config.beam_divergence_mrad) ** 2
                                           / DISC_VARIANCE_DIVISOR
                                           + math.radians(config.nav_heading_sigma_deg) ** 2)
    cov += _axes_cov(np.arctan2(los_n, los_e), np.full(k, config.range_sigma_m ** 2), cross_var)
    cov += config.nav_position_sigma_m ** 2 * np.eye(2)
    return cov


def _deskewed(track: OwnshipTrack, points_sensor_m: np.ndarray, t_s: np.ndarray, sweep: np.ndarray, mount: Mount,
              step_s: float) -> np.ndarray:
    """:meth:`OwnshipTrack.sensor_to_enu` with the pose taken at the nearest node of a time grid, per sweep.

    For each sweep, the pose is evaluated exactly at nodes ``step_s`` apart from its points' earliest
    time to their latest, and each point takes its nearest node: at most ``step_s / 2`` off its own
    time. With ``step_s = 0`` (or a grid with more nodes than the sweep has points) every point of the
    sweep gets its own pose.

    Parameters
    ----------
    points_sensor_m : (N, 3) float64
        Points in the sensor frame, m.
    t_s : (N,) float64
        Their times, s.
    sweep : (N,) int64
        Each point's sweep, non-decreasing.

    Returns
    -------
    (N, 3) float64
        ENU points, m.
    """
    starts = np.flatnonzero(np.r_[True, sweep[1:] != sweep[:-1]])  # each sweep's first point
    count = np.diff(np.r_[starts, sweep.shape[0]])
    t0 = np.minimum.reduceat(t_s, starts)
    if step_s > 0:
        n_nodes = np.ceil((np.maximum.reduceat(t_s, starts) - t0) / step_s).astype(np.int64) + 1
        gridded = n_nodes <= count
    else:
        n_nodes, gridded = count + 1, np.zeros(starts.shape[0], dtype=bool)
    n_nodes = np.where(gridded, n_nodes, count)  # a sweep off the grid: a node per point, at its time
    node_start = np.cumsum(n_nodes) - n_nodes
    segment = np.repeat(np.arange(starts.shape[0]), count)
    own_time = ~gridded[segment]
    node = np.where(own_time, np.arange(sweep.shape[0]) - starts[segment],
                    np.rint((t_s - t0[segment]) / (step_s if step_s > 0 else 1.0)).astype(np.int64))
    node_segment = np.repeat(np.arange(starts.shape[0]), n_nodes)
    node_t = t0[node_segment] + step_s * (np.arange(node_segment.shape[0]) - node_start[node_segment])
    node_t[~gridded[node_segment]] = t_s[own_time]
    node += node_start[segment]
    rotation, translation, _ = _mount_pose(mount)
    body = points_sensor_m @ rotation.T + translation
    return np.einsum("nij,nj->ni", track.rotation(node_t)[node], body) + track.position_m(node_t)[node]


def _nothing(scan_time_s: float) -> tuple[Detections, np.ndarray, np.ndarray]:
    empty = np.zeros(0, dtype=np.int64)
    return Detections.empty("lidar", scan_time_s), empty, empty


def _axes_cov(angle_rad: np.ndarray, var_along: np.ndarray, var_across: np.ndarray) -> np.ndarray:
    """(K, 2, 2) ENU covariance of variances along / across axes at ENU angles (K,), rad."""
    c, s = np.cos(angle_rad), np.sin(angle_rad)
    cov = np.empty(angle_rad.shape + (2, 2))
    cov[:, 0, 0] = var_along * c * c + var_across * s * s
    cov[:, 1, 1] = var_along * s * s + var_across * c * c
    cov[:, 0, 1] = cov[:, 1, 0] = (var_along - var_across) * c * s
    return cov

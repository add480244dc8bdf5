"""LiDAR front end: one Velodyne revolution in, clusters as :class:`~tdm.detections.Detections` out.

Steps (all vectorised; the only Python loop is over ring offsets):

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
6. **Clustering.** A graph on voxels, cut into connected components (:func:`_components`, the
   labels of ``scipy.sparse.csgraph.connected_components``), has two kinds of edge:

   * Euclidean (PCL/Autoware): voxel centres closer than ``cluster_tolerance_m`` on the
     horizontal plane (``cKDTree.query_pairs``). Clustering on the horizontal plane
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

The settings are :class:`LidarFrontEndConfig` (:mod:`tdm.frontend.lidar_config`), importable from here too.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from tdm.detections import Detections
from tdm.frames import Mount, OwnshipTrack
from tdm.frontend.lidar_config import (HDL32E_FIRING_CYCLE_S, LINK_WINDOW_CYCLES, LidarFrontEndConfig,
                                       lidar_mount_from_scenario)
from tdm.land import LandMask

__all__ = ["HDL32E_FIRING_CYCLE_S", "LINK_WINDOW_CYCLES", "LidarFrontEndConfig", "lidar_clusters", "lidar_detections",
           "lidar_mount_from_scenario"]

#: Range-image neighbours lie within this many azimuth steps of each other (a firing cycle apart,
#: or two when one firing had no return).
NEIGHBOUR_AZIMUTH_STEPS = 2
#: Spare azimuth bins per ring in the range image's keys, beyond one revolution (the bins of a
#: ring stay apart from the next ring's whatever the rounding of the azimuths).
_SPARE_AZIMUTH_BINS = 8
#: Variance of a uniform distribution over a width w: w^2 / 12 (footprint box, azimuth step).
UNIFORM_VARIANCE_DIVISOR = 12.0
#: Variance per axis of a uniform disc of diameter d: d^2 / 16 (beam divergence).
DISC_VARIANCE_DIVISOR = 16.0
RAD_PER_MRAD = 1e-3
#: A mount rotation this close to the identity is taken as none (the own-ship test skips the product).
_IDENTITY_ATOL = 1e-12


def _range_image_links(ring: np.ndarray, points_m: np.ndarray, range_m: np.ndarray, t_s: np.ndarray,
                       config: LidarFrontEndConfig) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Pairs of points on one surface, neighbours in the range image (module docstring, step 6).

    The points are sorted by (ring, azimuth bin of one azimuth step). Along a ring, each
    point is paired with the next one when it lies within two azimuth steps; across rings,
    with the point nearest in azimuth (within two steps) of the ring ``step`` above
    (``step = 1 .. ring_link_max_step``). A pair is kept when ``beta > theta``. With
    ``p, q`` the two points (ranges ``d1 >= d2``), ``d2 sin a = |p x q| / d1`` and
    ``d2 cos a = p.q / d1``, so ``d2 sin a > tan(theta) (d1 - d2 cos a)`` reads
    ``|p x q|^2 > tan^2(theta) (d1^2 - p.q)^2`` (both sides >= 0), with
    ``|p x q|^2 = |p|^2 |q|^2 - (p.q)^2``: no angles needed. Neighbours must also be
    fired within ``LINK_WINDOW_CYCLES`` firing cycles of each other: at the sweep's seam,
    points next to each other in azimuth were fired a revolution apart, and the own ship
    has moved in between.

    Parameters
    ----------
    ring : (N,) int64
        Laser ring of each point (0 = lowest).
    points_m : (N, 3) float64
        Points in the sensor frame, m.
    range_m : (N,) float64
        Their ranges, m.
    t_s : (N,) float64
        Their times, s.

    Returns
    -------
    i, j : (K,) intp
        Indices of linked points.
    on_surface : (N,) bool
        Points linked to a neighbour along their own ring (the same laser's next or
        previous firing hit the same surface).
    """
    n = ring.shape[0]
    on_surface = np.zeros(n, dtype=bool)
    if n < 2:
        return np.zeros(0, dtype=np.intp), np.zeros(0, dtype=np.intp), on_surface
    step_rad = config.azimuth_step_rad
    n_bins = int(math.ceil(2.0 * math.pi / step_rad)) + _SPARE_AZIMUTH_BINS
    azimuth_bin = ((np.arctan2(points_m[:, 1], points_m[:, 0]) + math.pi) / step_rad).astype(np.int64)
    key = ring * n_bins + azimuth_bin
    order = np.argsort(key, kind="stable")
    sorted_key = key[order]
    range2 = range_m * range_m
    tan2 = math.tan(math.radians(config.ring_link_angle_deg)) ** 2
    window_s = LINK_WINDOW_CYCLES * HDL32E_FIRING_CYCLE_S

    def same_surface(i, j):
        dot = np.einsum("ij,ij->i", points_m[i], points_m[j])
        r2i, r2j = range2[i], range2[j]
        gap = np.maximum(r2i, r2j) - dot
        return (r2i * r2j - dot * dot > tan2 * gap * gap) & (np.abs(t_s[i] - t_s[j]) <= window_s)

    # along each ring: successive points in the sorted order
    close = np.nonzero(sorted_key[1:] - sorted_key[:-1] <= NEIGHBOUR_AZIMUTH_STEPS)[0]
    i, j = order[close], order[close + 1]
    linked = same_surface(i, j)
    firsts, seconds = [i[linked]], [j[linked]]
    on_surface[firsts[0]] = True
    on_surface[seconds[0]] = True
    # across rings
    for step in range(1, config.ring_link_max_step + 1):
        query = key + step * n_bins
        pos = np.searchsorted(sorted_key, query)
        lo = order[np.maximum(pos - 1, 0)]
        hi = order[np.minimum(pos, n - 1)]
        d_lo = np.abs(key[lo] - query)  # in azimuth bins when in the right ring
        d_hi = np.abs(key[hi] - query)
        i = np.nonzero(np.minimum(d_lo, d_hi) <= NEIGHBOUR_AZIMUTH_STEPS)[0]
        j = np.where(d_hi[i] < d_lo[i], hi[i], lo[i])
        linked = same_surface(i, j)
        firsts.append(i[linked])
        seconds.append(j[linked])
    return np.concatenate(firsts), np.concatenate(seconds), on_surface


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
    config = config or LidarFrontEndConfig()
    time_s = np.asarray(sweep["time"], dtype=np.float64)
    scan_time_s = float(time_s.min()) if time_s.size else math.nan
    x, y, z = (np.asarray(sweep[k]) for k in ("x", "y", "z"))
    idx, sensor_points, t, range_m = _good_returns(_off_ship(x, y, z, mount, config), x, y, z, time_s, config)
    if idx.size == 0:
        return _nothing(scan_time_s)
    # 3. deskew: every point with the pose at its own time
    enu = _sensor_to_enu(track, sensor_points, t if config.deskew else np.full_like(t, scan_time_s), mount,
                         config.deskew_step_s)
    # 4. sea and foam (and the chart's land)
    above = enu[:, 2] >= config.min_height_m
    if land is not None:  # the chart's land (tdm.land): its points make no cluster
        above &= ~land.contains(enu[:, 0], enu[:, 1])
    if not above.any():
        return _nothing(scan_time_s)
    enu, sensor_points, t, range_m, idx = enu[above], sensor_points[above], t[above], range_m[above], idx[above]
    # 5., 6. voxels, their graph and its clusters; clusters of too few points or of weather dropped
    inverse, centres = _voxels(enu, config.voxel_m)
    ring = np.asarray(sweep["ring"])[idx].astype(np.int64)
    label, on_surface = _cluster_labels(inverse, centres, ring, sensor_points, range_m, t, config)
    good, counts = _kept_clusters(label, on_surface, config)
    if not good.any():
        return _nothing(scan_time_s)
    new_id = np.cumsum(good) - 1
    member = good[label]
    label = new_id[label[member]]
    enu, t, idx = enu[member], t[member], idx[member]
    k = int(good.sum())
    n_cells = counts[good].astype(np.int64)
    # 7. per-cluster statistics; the sensor at each cluster's time, and the line of sight to the points' mean
    fp = _footprints(enu, t, label, n_cells)
    sensor_enu = track.sensor_to_enu(np.zeros((k, 3)), fp.mean_t if config.deskew else np.full(k, scan_time_s), mount)
    if config.centre == "outline":
        depth_fraction = np.where(fp.length_m < config.hidden_depth_max_elongation * fp.width_m,
                                  config.hidden_depth_fraction, 0.0)
        centre_e, centre_n = _outline_centres(enu, label, n_cells, fp, sensor_enu, depth_fraction)
    else:
        centre_e, centre_n = fp.mean_e, fp.mean_n
    los_e = centre_e - sensor_enu[:, 0]
    los_n = centre_n - sensor_enu[:, 1]
    horizontal_range_m = np.hypot(los_e, los_n)
    detections = Detections(
        sensor="lidar",
        scan_time_s=scan_time_s,
        time_s=fp.mean_t,
        position_m=np.stack([centre_e, centre_n], axis=1),
        position_cov_m2=_cluster_cov(fp, los_e, los_n, horizontal_range_m, config),
        cross_section_m2=fp.length_m * fp.width_m,
        length_m=fp.length_m,
        width_m=fp.width_m,
        orientation_deg=np.mod(90.0 - np.degrees(fp.phi_long), 180.0),
        height_m=fp.height_m,
        n_cells=n_cells,
        range_m=horizontal_range_m,
    )
    return detections, idx, label


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


def _voxels(enu: np.ndarray, voxel_m: float) -> tuple[np.ndarray, np.ndarray]:
    """Horizontal voxels (pillars) of the points (step 5): each point's voxel, and the voxels' mean
    points (V, 2), m."""
    cell = np.floor(enu[:, :2] / voxel_m).astype(np.int64)
    cell -= cell.min(axis=0)
    voxel_key = cell[:, 0] * (int(cell[:, 1].max()) + 1) + cell[:, 1]
    _, inverse, voxel_count = np.unique(voxel_key, return_inverse=True, return_counts=True)
    inverse = inverse.reshape(-1)
    n_voxels = voxel_count.shape[0]
    centres = np.stack([np.bincount(inverse, enu[:, 0], n_voxels), np.bincount(inverse, enu[:, 1], n_voxels)],
                       axis=1) / voxel_count[:, None]
    return inverse, centres


def _cluster_labels(inverse: np.ndarray, centres: np.ndarray, ring: np.ndarray, sensor_points: np.ndarray,
                    range_m: np.ndarray, t: np.ndarray, config: LidarFrontEndConfig) -> tuple[np.ndarray, np.ndarray]:
    """Each point's cluster (step 6: Euclidean pairs of voxels + ring links, connected components), and
    whether it lies on a surface along its ring."""
    n_voxels = centres.shape[0]
    pairs = cKDTree(centres).query_pairs(config.cluster_tolerance_m, output_type="ndarray")
    link_i, link_j, on_surface = _range_image_links(ring, sensor_points, range_m, t, config)
    link_i, link_j = inverse[link_i], inverse[link_j]
    between = link_i != link_j
    rows = np.concatenate([pairs[:, 0], link_i[between]])
    cols = np.concatenate([pairs[:, 1], link_j[between]])
    return _components(rows, cols, n_voxels)[inverse], on_surface


def _components(rows: np.ndarray, cols: np.ndarray, n: int) -> np.ndarray:
    """(n,) connected component of each of ``n`` nodes joined by the undirected edges ``rows[k] - cols[k]`` (E,),
    numbered in the order of each component's lowest node: the labels of
    ``scipy.sparse.csgraph.connected_components`` (which numbers components as its scan over the nodes
    meets them), without its per-call graph checks.

    Min-label hooking with pointer jumping (Shiloach & Vishkin, "An O(log n) parallel connectivity
    algorithm", J. Algorithms 3(1), 1982): every node points at a node of no higher index; each round
    hooks the root of each edge's higher end on the lower, then every pointer jumps to its root. A
    component's lowest node never moves, so at the end it is every member's root.
    """
    parent = np.arange(n)
    while rows.size:  # a few rounds: each at least halves the trees' depth
        low = np.minimum(parent[rows], parent[cols])
        np.minimum.at(parent, parent[rows], low)
        np.minimum.at(parent, parent[cols], low)
        while True:  # pointer jumping until every node points at its root
            jumped = parent[parent]
            if np.array_equal(jumped, parent):
                break
            parent = jumped
        if np.array_equal(parent[rows], parent[cols]):
            break
    return np.unique(parent, return_inverse=True)[1].reshape(-1)


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
    of its long side (rad); each cluster's first position in the points sorted by cluster."""

    mean_e: np.ndarray
    mean_n: np.ndarray
    mean_t: np.ndarray
    height_m: np.ndarray
    length_m: np.ndarray
    width_m: np.ndarray
    phi_long: np.ndarray
    starts: np.ndarray


def _footprints(enu: np.ndarray, t: np.ndarray, label: np.ndarray, n_cells: np.ndarray) -> _Footprint:
    """Mean, height and PCA footprint box of every cluster (step 7), vectorised over clusters."""
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
    return _Footprint(mean_e, mean_n, mean_t, height_m, length_m, width_m, phi_long, starts)


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


def _cluster_cov(fp: _Footprint, los_e: np.ndarray, los_n: np.ndarray, horizontal_range_m: np.ndarray,
                 config: LidarFrontEndConfig) -> np.ndarray:
    """(k, 2, 2) ENU position covariance, m^2: footprint spread + sensor + navigation (module docstring)."""
    k = fp.length_m.shape[0]
    cov = _axes_cov(fp.phi_long, fp.length_m ** 2 / UNIFORM_VARIANCE_DIVISOR,
                    fp.width_m ** 2 / UNIFORM_VARIANCE_DIVISOR)
    cross_var = horizontal_range_m ** 2 * (config.azimuth_step_rad ** 2 / UNIFORM_VARIANCE_DIVISOR
                                           + (RAD_PER_MRAD * config.beam_divergence_mrad) ** 2
                                           / DISC_VARIANCE_DIVISOR
                                           + math.radians(config.nav_heading_sigma_deg) ** 2)
    cov += _axes_cov(np.arctan2(los_n, los_e), np.full(k, config.range_sigma_m ** 2), cross_var)
    cov += config.nav_position_sigma_m ** 2 * np.eye(2)
    return cov


def _sensor_to_enu(track: OwnshipTrack, points_sensor_m: np.ndarray, t_s: np.ndarray, mount: Mount,
                   step_s: float) -> np.ndarray:
    """:meth:`OwnshipTrack.sensor_to_enu` with the pose taken at the nearest node of a time grid.

    The pose is evaluated exactly at nodes ``step_s`` apart spanning ``t_s`` and each point
    takes its nearest node: at most ``step_s / 2`` off its own time. With ``step_s = 0`` (or
    a grid with more nodes than points) every point gets its own pose.

    Parameters
    ----------
    points_sensor_m : (N, 3) float64
        Points in the sensor frame, m.
    t_s : (N,) float64
        Their times, s.

    Returns
    -------
    (N, 3) float64
        ENU points, m.
    """
    t0 = float(t_s.min())
    n_nodes = int(math.ceil((float(t_s.max()) - t0) / step_s)) + 1 if step_s > 0 else t_s.shape[0] + 1
    if n_nodes > t_s.shape[0]:
        return track.sensor_to_enu(points_sensor_m, t_s, mount)
    node = np.rint((t_s - t0) / step_s).astype(np.intp)
    node_t = t0 + step_s * np.arange(n_nodes)
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

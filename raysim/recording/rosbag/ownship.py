"""Bag streams of the own ship from its navigation solution (``ownship.jsonl``) at :data:`OUT_RATE_HZ`.

Per output epoch: ``/ownship/fix`` (NavSatFix), ``/ownship/pose`` (PoseStamped, frame ``map``),
``/tf`` (map -> base_link), ``/ownship/imu`` (Imu, frame ``base_link``) and ``/ownship/odom``
(Odometry, map -> base_link). Rates and accelerations are central differences of the solution over
:data:`DIFF_SPAN_S`; every covariance is the one the navigation error model implies
(``sensors.nav``, docs/physics.md "Own-ship navigation"):

- position: per horizontal axis ``position_noise_m^2 + position_bias_m^2`` (white noise plus the
  stationary variance of the Gauss-Markov bias); the model has no vertical error, and up reports
  the horizontal variance so that no consumer takes the altitude as exact;
- roll, pitch: ``attitude_noise_deg^2``; heading: ``heading_noise_deg^2 + heading_bias_deg^2``;
- angular rate of a difference over ``T``: ``2 sigma^2 / T^2`` with sigma the white noise (a bias
  cancels); linear velocity ``velocity_noise_mps^2``; acceleration ``2 velocity_noise_mps^2 / T^2``;
- a variance the model makes zero is reported as :data:`FLOOR_VARIANCE` (never exactly 0).

The NavSatFix altitude is ellipsoidal (WGS84), as receivers report it: the heave ``z`` plus
``sensors.nav.geoid_separation_m``. Covariance type DIAGONAL_KNOWN (2), ENU.
"""

from __future__ import annotations

import itertools
import json
import math
from pathlib import Path
from typing import Iterator

import numpy as np

from raysim.recording.rosbag.msgs import BagMessage, header, make, point, pose, quaternion, zyx_quaternions

__all__ = ["ownship_streams", "OUT_RATE_HZ", "DIFF_SPAN_S", "GRAVITY_MPS2", "FLOOR_VARIANCE"]

OUT_RATE_HZ = 10.0
DIFF_SPAN_S = 0.2  # central differences over +-0.1 s
GRAVITY_MPS2 = 9.80665  # standard gravity (BIPM): an accelerometer at rest reads +g along up
FLOOR_VARIANCE = 1e-6
_KEYS = ("t", "lat", "lon", "x", "y", "z", "heading_deg", "roll_deg", "pitch_deg", "cog_deg", "sog_mps")
_BLOCK_ROWS = 5000


def _blocks(path: Path, halo: int) -> Iterator[tuple[dict[str, np.ndarray], int, int, int]]:
    """Columns of ``ownship.jsonl`` block by block, with ``halo`` rows of context either side.

    Yields
    ------
    cols : dict of (M,) float arrays
        Rows ``first .. first + M - 1`` of the file.
    first : int
        File index of the block's first row.
    lo, hi : int
        The rows this block owns (file indices ``lo <= k < hi``); every row is owned once.
    """
    rows: list[list[float]] = []
    first = owned = 0
    with open(path, encoding="utf-8") as handle:
        while True:
            chunk = list(itertools.islice(handle, _BLOCK_ROWS))
            rows += [[float(r[k]) for k in _KEYS] for r in map(json.loads, chunk)]
            end = first + len(rows)
            hi = end if not chunk else end - halo
            if hi > owned:
                arr = np.array(rows, dtype=np.float64).reshape(-1, len(_KEYS))
                yield {k: arr[:, i] for i, k in enumerate(_KEYS)}, first, owned, hi
                owned = hi
                drop = max(0, owned - halo - first)
                rows, first = rows[drop:], first + drop
            if not chunk:
                return


def _variances(nav) -> dict[str, float]:
    """Variances of the navigation error model (SI units, rad), floored at :data:`FLOOR_VARIANCE`."""
    d2r = math.radians(1.0)
    raw = {"position": nav.position_noise_m**2 + nav.position_bias_m**2,
           "attitude": (nav.attitude_noise_deg * d2r) ** 2,
           "heading": ((nav.heading_noise_deg * d2r) ** 2 + (nav.heading_bias_deg * d2r) ** 2),
           "roll_rate": 2 * (nav.attitude_noise_deg * d2r) ** 2 / DIFF_SPAN_S**2,
           "yaw_rate": 2 * (nav.heading_noise_deg * d2r) ** 2 / DIFF_SPAN_S**2,
           "velocity": nav.velocity_noise_mps**2,
           "acceleration": 2 * nav.velocity_noise_mps**2 / DIFF_SPAN_S**2}
    return {k: max(v, FLOOR_VARIANCE) for k, v in raw.items()}


def _kinematics(c: dict[str, np.ndarray], k: np.ndarray, d: int) -> dict[str, np.ndarray]:
    """Orientation, body rates, body velocity and specific force at rows ``k`` (central differences).

    Parameters
    ----------
    c : dict of (M,) arrays
        Block columns.
    k : (K,) int
        Rows of the block to evaluate.
    d : int
        Half-span of the differences, rows (clipped at the block's ends).
    """
    from scipy.spatial.transform import Rotation

    m = c["t"].size
    a, b = np.clip(k - d, 0, m - 1), np.clip(k + d, 0, m - 1)
    yaw = np.radians(90.0 - c["heading_deg"])
    # body FLU: pitch positive nose down (the file's pitch is bow up positive), roll starboard down positive
    q_all = zyx_quaternions(yaw, -np.radians(c["pitch_deg"]), np.radians(c["roll_deg"]))
    rot = Rotation.from_quat(q_all)
    span = np.maximum(c["t"][b] - c["t"][a], 1e-9)
    omega_body = (rot[a].inv() * rot[b]).as_rotvec() / span[:, None]
    cog = np.radians(c["cog_deg"])
    v_en = np.stack([c["sog_mps"] * np.sin(cog), c["sog_mps"] * np.cos(cog)], axis=1)
    v_up = (c["z"][b] - c["z"][a]) / span
    v_world = np.column_stack([v_en[k], v_up])
    acc_en = (v_en[b] - v_en[a]) / span[:, None]
    half = np.maximum((c["t"][b] - c["t"][a]) / 2.0, 1e-9)
    acc_up = np.where(b - a == 2 * d, (c["z"][b] - 2 * c["z"][k] + c["z"][a]) / half**2, 0.0)
    force_world = np.column_stack([acc_en, acc_up + GRAVITY_MPS2])
    body = rot[k].inv()
    return {"q": q_all[k], "omega": omega_body, "v_body": body.apply(v_world), "f_body": body.apply(force_world)}


def _diag(values, size: int) -> np.ndarray:
    cov = np.zeros((size, size))
    cov[np.diag_indices(size)] = values
    return cov.ravel()


def _epoch_messages(t_ns: int, row: dict, kin: dict, var: dict, altitude_m: float) -> Iterator[BagMessage]:
    """The five messages of one own-ship epoch."""
    q, omega, v, f = kin["q"], kin["omega"], kin["v_body"], kin["f_body"]
    pos, att, hdg = var["position"], var["attitude"], var["heading"]
    rates = [var["roll_rate"], var["roll_rate"], var["yaw_rate"]]
    fix = make("sensor_msgs/msg/NavSatFix", header=header(t_ns, "base_link"),
               status=make("sensor_msgs/msg/NavSatStatus", status=0, service=1), latitude=row["lat"],
               longitude=row["lon"], altitude=altitude_m, position_covariance=_diag([pos, pos, pos], 3),
               position_covariance_type=2)
    yield BagMessage(t_ns, "/ownship/fix", "sensor_msgs/msg/NavSatFix", fix)
    here = pose(row["x"], row["y"], row["z"], q)
    yield BagMessage(t_ns, "/ownship/pose", "geometry_msgs/msg/PoseStamped",
                     make("geometry_msgs/msg/PoseStamped", header=header(t_ns, "map"), pose=here))
    tf = make("geometry_msgs/msg/TransformStamped", header=header(t_ns, "map"), child_frame_id="base_link",
              transform=make("geometry_msgs/msg/Transform",
                             translation=point(row["x"], row["y"], row["z"], msgtype="geometry_msgs/msg/Vector3"),
                             rotation=quaternion(q)))
    yield BagMessage(t_ns, "/tf", "tf2_msgs/msg/TFMessage", make("tf2_msgs/msg/TFMessage", transforms=[tf]))
    vec = "geometry_msgs/msg/Vector3"
    imu = make("sensor_msgs/msg/Imu", header=header(t_ns, "base_link"), orientation=quaternion(q),
               orientation_covariance=_diag([att, att, hdg], 3), angular_velocity=point(*omega, msgtype=vec),
               angular_velocity_covariance=_diag(rates, 3), linear_acceleration=point(*f, msgtype=vec),
               linear_acceleration_covariance=_diag([var["acceleration"]] * 2 + [FLOOR_VARIANCE], 3))
    yield BagMessage(t_ns, "/ownship/imu", "sensor_msgs/msg/Imu", imu)
    odom = make("nav_msgs/msg/Odometry", header=header(t_ns, "map"), child_frame_id="base_link",
                pose=make("geometry_msgs/msg/PoseWithCovariance", pose=here,
                          covariance=_diag([pos, pos, pos, att, att, hdg], 6)),
                twist=make("geometry_msgs/msg/TwistWithCovariance",
                           twist=make("geometry_msgs/msg/Twist", linear=point(*v, msgtype=vec),
                                      angular=point(*omega, msgtype=vec)),
                           covariance=_diag([var["velocity"]] * 2 + [FLOOR_VARIANCE] + rates, 6)))
    yield BagMessage(t_ns, "/ownship/odom", "nav_msgs/msg/Odometry", odom)


def ownship_streams(recording: Path, scenario, t0_ns: int) -> Iterator[BagMessage]:
    """Every own-ship message of the bag, in time order (:data:`OUT_RATE_HZ`)."""
    path = recording / "ownship.jsonl"
    if not path.is_file():
        return
    nav = scenario.sensors.nav
    step = max(1, int(round(nav.rate_hz / OUT_RATE_HZ)))
    d = max(1, int(round(DIFF_SPAN_S / 2.0 * nav.rate_hz)))
    var = _variances(nav)
    geoid_m = float(getattr(nav, "geoid_separation_m", 0.0))
    for cols, first, lo, hi in _blocks(path, halo=d):
        index = np.arange(-(-lo // step) * step, hi, step)
        if index.size == 0:
            continue
        k = index - first
        kin = _kinematics(cols, k, d)
        for j, row_k in enumerate(k.tolist()):
            row = {key: float(cols[key][row_k]) for key in _KEYS}
            t_ns = t0_ns + int(round(row["t"] * 1e9))
            yield from _epoch_messages(t_ns, row, {key: val[j] for key, val in kin.items()}, var,
                                       row["z"] + geoid_m)

"""Whether the velocities the fusion weighs are as good as their covariances say: velocity NEES per sensor.

Usage::

    python benchmarks/tdm_velocity_consistency.py RECORDING [RECORDING ...] [--whole]
                                                  [--out benchmarks/results/tdm_velocity_consistency.md]

The evaluation (tdm/evaluate.py) scores positions and their covariances only: ``detected_targets.jsonl`` and
``sensor_tracks.jsonl`` carry no velocity covariance (docs/formats.md). The fusion, though, weighs each sensor's
velocity by its covariance (:func:`tdm.fusion_rules.fuse`), so a sensor whose velocity is worse than it says pulls the
fused course and speed towards its errors. This runs the TDM (default configuration) on each recording and, at every
output epoch, takes each fused target's members' states as the fusion weighed them (:class:`tdm.fusion.Fuser`, with
every weight applied) and the fused state, matches each to the nearest truth object within ``MATCH_M`` (the
evaluation's cut-off), and forms the east-north velocity error ``dv`` and its NEES ``dv^T Q^-1 dv`` (2 dof; ``Q``
the covariance turned to east and north velocity, :func:`tdm.fusion_rules.to_cartesian`). Per sensor, over every
matched state and apart for states matched to still objects (truth under ``STILL_MPS``) and to moving ones: the mean
NEES (2 for a consistent one), the fractions in its 95 % interval, under it (the sensor claims less than it does) and
over it, the rms and the median absolute velocity error against the median reported standard deviation per axis.
``--whole``: each recording a second time with every member fused whole (``FusionConfig.fuse_position_apart``
empty, the rule until 2026-11-29), beside.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from benchmarks.common import machine_line  # noqa: E402
import tdm.pipeline as pipeline  # noqa: E402
from tdm.eval_scoring import NEES_95_INTERVAL  # noqa: E402
from tdm.eval_truth import read_truth_enu, truth_at  # noqa: E402
from tdm.frames import EnuFrame  # noqa: E402
from tdm.fusion import Fuser  # noqa: E402
from tdm.fusion_rules import to_cartesian  # noqa: E402

#: A state is matched to the nearest truth object within this, m (the evaluation's cut-off, tdm/evaluate.py).
MATCH_M = 50.0
#: A truth object slower than this is still (a berg drifting, a ship at anchor), m/s: 1 kn.
STILL_MPS = 0.5
SENSORS = ("ais", "lidar", "radar", "fused")


class _RecordingFuser(Fuser):
    """A :class:`Fuser` that keeps, at each step, every member's state as the fusion weighed it and the fused one."""

    rows: list

    def step(self, t_s, tracks_by_sensor, own_position_m=None, own_velocity_mps=None):
        estimates = super().step(t_s, tracks_by_sensor, own_position_m, own_velocity_mps)
        for est in estimates:
            for sensor, track_id in est.target.members.items():
                x, p = self.weighed[(sensor, track_id)]
                self.rows.append((t_s, sensor, x, p))
            self.rows.append((t_s, "fused", est.x, est.p))
        return estimates


def weighed_states(recording: Path, whole: bool = False
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, EnuFrame]:
    """Run the TDM on ``recording`` (``whole``: with ``FusionConfig.fuse_position_apart`` empty) and return the
    weighed states: times (R,) s, sensors (R,) str, states (R, 6), covariances (R, 6, 6), in the TDM's frame
    (returned too).

    The run's fuser is made a :class:`_RecordingFuser` as the pipeline's tracking state is built (the pipeline has
    no hook for it; its ``_Tracking`` is patched for the run and restored).
    """
    rows: list = []
    frames: list = []
    tracking_init = pipeline._Tracking.__init__

    def init(self, *args, **kwargs):
        tracking_init(self, *args, **kwargs)
        self.fuser.__class__ = _RecordingFuser
        self.fuser.rows = rows
        frames.append(self.ownship.frame)

    pipeline._Tracking.__init__ = init
    try:
        with tempfile.TemporaryDirectory() as out:
            config = pipeline.TdmConfig.for_recording(recording, workers=1)
            if whole:
                fusion = dataclasses.replace(config.fusion_config, fuse_position_apart=())
                config = dataclasses.replace(config, fusion_config=fusion)
            pipeline.run_tdm(recording, Path(out), config)
    finally:
        pipeline._Tracking.__init__ = tracking_init
    t = np.array([r[0] for r in rows])
    return t, np.array([r[1] for r in rows]), np.array([r[2] for r in rows]), np.array([r[3] for r in rows]), frames[0]


def velocity_nees(recording: Path, whole: bool = False) -> dict[str, dict[str, float]]:
    """Per sensor (and ``fused``), keyed by its name, and apart for the states matched to still and to moving truth
    objects (``"<sensor>, still objects"``, ``"<sensor>, moving objects"``; a key only where there are such states):
    ``n``, ``nees_mean``, ``in_95``, ``under_95``, ``over_95``, ``rms_error_mps`` and ``median_error_mps`` (per axis)
    and ``reported_sd_mps`` (median, per axis) over the matched weighed states of ``recording`` (``whole``:
    :func:`weighed_states`)."""
    t, sensor, x, p, frame = weighed_states(recording, whole)
    epochs, row = np.unique(t, return_inverse=True)
    truth_frame, truth = read_truth_enu(recording)
    at = truth_at(truth, epochs)  # (E, K) per truth object, NaN where it has no samples
    east, north = truth_frame.to_local(*frame.to_geodetic(x[:, 0], x[:, 1]))
    cog_rad = np.radians(at.cog_deg)
    pos = np.stack([at.east_m, at.north_m], axis=-1)[row]
    vel = np.stack([at.sog_mps * np.sin(cog_rad), at.sog_mps * np.cos(cog_rad)], axis=-1)[row]
    dist = np.hypot(pos[..., 0] - east[:, None], pos[..., 1] - north[:, None])
    dist = np.where(np.isfinite(dist), dist, np.inf)
    nearest = np.argmin(dist, axis=1)
    rows = np.arange(t.size)
    matched = dist[rows, nearest] <= MATCH_M
    y, q = to_cartesian(x, p)
    dv = y[:, 2:4] - vel[rows, nearest]
    qv = q[:, 2:4, 2:4]
    value = np.einsum("ni,nij,nj->n", dv, np.linalg.inv(qv), dv)
    still = np.hypot(*vel[rows, nearest].T) < STILL_MPS
    out = {}
    for name in SENSORS:
        parts = (("", matched), (", still objects", matched & still), (", moving objects", matched & ~still))
        for part, objects in parts:
            sel = objects & (sensor == name) & np.isfinite(value)
            if sel.any():
                out[name + part] = _consistency(value[sel], dv[sel], qv[sel])
    return out


def _consistency(value: np.ndarray, dv: np.ndarray, qv: np.ndarray) -> dict[str, float]:
    """The figures of :func:`velocity_nees` over (M,) NEES ``value``, (M, 2) errors ``dv`` (m/s) and (M, 2, 2)
    covariances ``qv`` ((m/s)^2): the fractions under and over the 95 % interval beside the fraction in it."""
    lo, hi = NEES_95_INTERVAL
    return {"n": int(value.size), "nees_mean": float(np.mean(value)),
            "in_95": float(np.mean((value >= lo) & (value <= hi))), "under_95": float(np.mean(value < lo)),
            "over_95": float(np.mean(value > hi)), "rms_error_mps": float(np.sqrt(np.mean(dv ** 2))),
            "median_error_mps": float(np.median(np.abs(dv))),
            "reported_sd_mps": float(np.median(np.sqrt(np.trace(qv, axis1=1, axis2=2) / 2.0)))}


def _table(results: dict[str, dict]) -> list[str]:
    lines = ["| recording | sensor | states | NEES mean (2 consistent) | in 95 % interval | under it | over it "
             "| rms error per axis [m/s] | median abs. error per axis [m/s] | reported sd per axis, median [m/s] |",
             "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for rec, per in results.items():
        for name, m in per.items():
            lines.append(f"| {rec} | {name} | {m['n']} | {m['nees_mean']:.2f} | {m['in_95']:.2f} | "
                         f"{m['under_95']:.2f} | {m['over_95']:.2f} | {m['rms_error_mps']:.3f} | "
                         f"{m['median_error_mps']:.3f} | {m['reported_sd_mps']:.3f} |")
    return lines


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("recordings", type=Path, nargs="+")
    parser.add_argument("--whole", action="store_true", help="also with every track fused whole")
    parser.add_argument("--out", type=Path, default=ROOT / "benchmarks/results/tdm_velocity_consistency.md")
    args = parser.parse_args(argv)
    results = {}
    for rec in args.recordings:
        for whole in (False, True) if args.whole else (False,):
            name = f"{rec.name}, every track whole" if whole else rec.name
            results[name] = velocity_nees(rec, whole)
            print(name, {k: round(v["nees_mean"], 2) for k, v in results[name].items()}, flush=True)
    lines = ["# Velocity consistency per sensor, as the fusion weighs it", "", machine_line(
        "tdm_velocity_consistency", False), "", "Method: the script's docstring. Default TDM configuration.", "",
        *_table(results), ""]
    args.out.write_text("\n".join(lines))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

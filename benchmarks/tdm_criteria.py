"""The TDM's done-when criteria (issue 22) on every scenario and seed, and the radar plot strengths behind them.

Usage::

    python benchmarks/tdm_criteria.py [--heldout benchmarks/results/tdm_heldout.json] [--quick] [--fresh]
                                      [--out benchmarks/results/tdm_criteria.md] [--json FILE]

- **The criteria, run by run.** Read from the held-out benchmark's runs (benchmarks/tdm_heldout.py, which renders
  every scenario for 300 s with seeds 31-35 and runs the TDM, tuned on busy_open_sea only, with its default
  configuration; its ``--json``, committed as benchmarks/results/tdm_heldout.json). One row per run and one column
  per criterion of issue 22's "Done when" (the limits are tdm_heldout.py's ``CRITERIA``, not repeated here): the
  value, marked where it does not meet its limit, and the objects behind each failure (the objects reported more
  than 10 s after coming into view or never, those with more than one id switch). Then per scenario the runs that
  meet each criterion and every criterion. Why each failure happens: docs/tdm.md, "Where the criteria fail, and
  why".
- **Radar plot strengths** (behind the radar tracker's hit weights, ``TdmConfig.radar_tracker``): renders
  scenarios/busy_open_sea.yaml (the tuning scenario, its own seed) for 300 s into ``/tmp/tdm_bench_bos`` (shared
  with benchmarks/tdm_speed.py; reused when a matching render newer than the scenario and the renderer's code is
  there, ``--fresh`` renders again; ``--quick``: 90 s into ``/tmp/tdm_bench_bos_90``) and takes every plot of its
  first 60 sweeps that passes the radar front end (:func:`tdm.frontend.radar.radar_detections`), split into plots
  on an object (within 20 m of its hull's outline, from truth) and the rest (sea clutter): the strength
  (``Detections.strength_db``, dB over the local clutter level) percentiles and the fractions under 13 dB and from
  15 dB (weak_below_db, strong_from_db), and, of the plots from 15 dB, the median beam fill and the fraction under
  0.5 (``Detections.beam_fill``, min_beam_fill).

Until 2026-11-29 this page held issue 7's criteria on two scenarios; that page is in
benchmarks/results/tdm_criteria_history.md.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from benchmarks.common import ensure_recording, machine_line  # noqa: E402
from benchmarks.tdm_heldout import CRITERIA, HELD_OUT, TUNED, passes  # noqa: E402
from tdm.detections import ReadStats  # noqa: E402
from tdm.frames import EnuFrame  # noqa: E402
from tdm.pipeline import DetectionStream, TdmConfig  # noqa: E402

BOS = ROOT / "scenarios" / "busy_open_sea.yaml"
HELDOUT_JSON = ROOT / "benchmarks" / "results" / "tdm_heldout.json"
#: Short column labels of the criteria (tdm_heldout.CRITERIA's keys).
SHORT = {"latency_max_s": "latency [s]", "missed_within_1500_m": "missed", "median_error_within_lidar_m":
         "error within LiDAR range [m]", "median_error_beyond_lidar_m": "error beyond [m]",
         "id_switches_max": "id switches", "false_targets_per_min": "false targets / min",
         "nees_fraction_in_95": "fused NEES in interval"}
#: Decimals a criterion's value is shown with (the NEES fraction with three, so that 0.796 does not read 0.80).
DECIMALS = {"latency_max_s": 0, "median_error_within_lidar_m": 2, "median_error_beyond_lidar_m": 2,
            "false_targets_per_min": 2, "nees_fraction_in_95": 3}
#: A plot within this distance of an object's outline (truth position less half its length) is on it, m.
ON_OBJECT_M = 20.0
STRENGTH_SWEEPS = 60


class HeldoutMissing(Exception):
    """The held-out benchmark's runs are not there (or not readable as it writes them)."""


def load_heldout(path: Path) -> dict:
    """The held-out benchmark's JSON (``{"generated", "seeds", "duration_s", "runs"}``).

    Raises
    ------
    HeldoutMissing
        No such file, not JSON, or not of that shape: one line saying which and what to run.
    """
    try:
        data = json.loads(Path(path).read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise HeldoutMissing(f"{path}: no such file; run `python benchmarks/tdm_heldout.py --json {path}` first") from None
    except (OSError, ValueError) as exc:
        raise HeldoutMissing(f"{path}: not readable as JSON ({exc})") from None
    if not isinstance(data, dict) or not isinstance(data.get("runs"), list):
        raise HeldoutMissing(f"{path}: no 'runs' list (made by benchmarks/tdm_heldout.py --json before 2026-11-29?); "
                             "run it again")
    return data


def verdicts(run: dict) -> dict[str, bool | None]:
    """Per criterion key: met (True), not met (False) or not applicable (None) for one run."""
    return {key: passes(run.get(key), limit, sense) for key, _, limit, sense in CRITERIA}


def what_fails(run: dict) -> list[str]:
    """The objects and figures behind one run's failed criteria, one phrase each."""
    v, out = verdicts(run), []
    limit = {key: lim for key, _, lim, _ in CRITERIA}
    if v["latency_max_s"] is False or v["missed_within_1500_m"] is False:
        late = sorted(((lat, name) for name, lat in run.get("latency_by_object_s", {}).items()
                       if lat is not None and lat > limit["latency_max_s"]), reverse=True)
        names = [f"{name} {lat:.0f} s" for lat, name in late] + [f"{name} never" for name in run.get("missed_names", [])]
        out.append("late: " + ", ".join(names))
    if v["id_switches_max"] is False:
        by_object = run.get("id_switches_by_object")
        if by_object is None:
            out.append(f"id switches: {run['id_switches_max']} (objects not recorded)")
        else:
            many = sorted(((n, name) for name, n in by_object.items() if n > limit["id_switches_max"]), reverse=True)
            out.append("id switches: " + ", ".join(f"{name} {n}" for n, name in many))
    for key, phrase in (("false_targets_per_min", "false targets"), ("nees_fraction_in_95", "NEES"),
                        ("median_error_within_lidar_m", "error within LiDAR range"),
                        ("median_error_beyond_lidar_m", "error beyond LiDAR range")):
        if v[key] is False:
            out.append(f"{phrase} {run[key]:.{DECIMALS[key]}f}")
    return out


def _cell(value, ok: bool | None, key: str) -> str:
    if value is None:
        return "-"
    if isinstance(value, float) and math.isinf(value):
        text = "missed"
    elif isinstance(value, float):
        text = f"{value:.{DECIMALS.get(key, 2)}f}"
    else:
        text = str(value)
    return f"**{text}, not met**" if ok is False else text


def _order(runs: list[dict]) -> list[dict]:
    rank = {name: k for k, name in enumerate((TUNED, *HELD_OUT))}
    return sorted(runs, key=lambda r: (rank.get(r["scenario"], len(rank)), r["scenario"], r["seed"]))


def criteria_lines(heldout: dict) -> list[str]:
    """Markdown: every run against every criterion, then per scenario the runs that meet them."""
    runs = _order(heldout["runs"])
    keys = [key for key, *_ in CRITERIA]
    lines = ["| scenario | seed | " + " | ".join(SHORT[k] for k in keys) + " | met | what fails |",
             "|---|---:|" + "---:|" * (len(keys) + 1) + "---|",
             "| asked | | " + " | ".join(("<= " if sense == "max" else ">= ") + str(limit)
                                         for _, _, limit, sense in CRITERIA) + " | | |"]
    cells_met = cells_judged = runs_all = 0
    for r in runs:
        v = verdicts(r)
        judged = [ok for ok in v.values() if ok is not None]
        cells_met, cells_judged, runs_all = cells_met + sum(judged), cells_judged + len(judged), runs_all + all(judged)
        tag = " (tuned)" if r["scenario"] == TUNED else ""
        lines.append(f"| {r['scenario']}{tag} | {r['seed']} | " + " | ".join(_cell(r.get(k), v[k], k) for k in keys)
                     + f" | {sum(judged)}/{len(judged)} | {'; '.join(what_fails(r)) or '-'} |")
    lines += ["", f"**{cells_met} of the {cells_judged} (run, criterion) cells are met; {runs_all} of the {len(runs)} "
                  "runs meet every criterion.**", "",
              "| scenario | runs | " + " | ".join(SHORT[k] for k in keys) + " | every criterion |",
              "|---|---:|" + "---:|" * (len(keys) + 1)]
    for scenario in dict.fromkeys(r["scenario"] for r in runs):
        mine = [verdicts(r) for r in runs if r["scenario"] == scenario]
        counts = []
        for k in keys:
            judged = [v[k] for v in mine if v[k] is not None]
            counts.append(f"{sum(judged)}/{len(judged)}" if judged else "-")
        every = sum(all(ok for ok in v.values() if ok is not None) for v in mine)
        tag = " (tuned)" if scenario == TUNED else ""
        lines.append(f"| {scenario}{tag} | {len(mine)} | " + " | ".join(counts) + f" | {every}/{len(mine)} |")
    return lines + [""] + switch_lines(runs)


def switch_lines(runs: list[dict]) -> list[str]:
    """Markdown: per run, the most id switches of one object, CLEAR MOT's and the per-epoch assignment's."""
    lines = ["Id switches are counted on the CLEAR MOT correspondence (tdm/eval_identity.py; Bernardin and "
             "Stiefelhagen 2008, as py-motmetrics): an object keeps its target while that target stays within the "
             "cut-off. Counted on the optimal assignment at each epoch instead (the evaluation's count until "
             "2026-11-29), the most switches of one object per run, seeds in order:", "",
             "| scenario | CLEAR MOT (the criterion) | per-epoch assignment |", "|---|---|---|"]
    for scenario in dict.fromkeys(r["scenario"] for r in runs):
        mine = [r for r in runs if r["scenario"] == scenario]
        lines.append(f"| {scenario} | {', '.join(str(r.get('id_switches_max')) for r in mine)} | "
                     + ", ".join(str(r.get("id_switches_per_epoch_assignment_max", "-")) for r in mine) + " |")
    return lines


def plot_strengths(recording: Path, sweeps: int = STRENGTH_SWEEPS) -> dict:
    """Strengths (dB over the clutter level) and beam fills of the radar plots on objects and of the others."""
    stream = DetectionStream(recording, TdmConfig.for_recording(recording, workers=0), ReadStats())
    frame: EnuFrame = stream.ownship.frame
    positions, half_lengths = {}, {}
    with open(recording / "truth.jsonl", encoding="utf-8") as f:
        for line in f:
            row = json.loads(line)
            if row["kind"] == "ownship":
                continue
            key = round(row["t"], 1)
            positions.setdefault(key, []).append(frame.to_enu(row["lat"], row["lon"]))
            half_lengths.setdefault(key, []).append(0.5 * row["length_m"])
    on, off, n = [], [], 0
    for _, sensor, dets in stream.events():
        if sensor != "radar":
            continue
        n += 1
        if n > sweeps:
            break
        if not len(dets):
            continue
        keys = np.round(dets.time_s, 1)
        for key in np.unique(keys):  # a few truth epochs per sweep
            sel = keys == key
            objs = np.asarray(positions[float(key)], dtype=float)
            d = np.linalg.norm(dets.position_m[sel, None, :] - objs[None], axis=2) - np.asarray(half_lengths[float(key)])
            near = d.min(axis=1) <= ON_OBJECT_M
            both = np.stack([dets.strength_db[sel], dets.beam_fill[sel]], axis=1)
            on.append(both[near])
            off.append(both[~near])
    return {name: _strength_figures(np.concatenate(values) if values else np.zeros((0, 2)), min(n, sweeps))
            for name, values in (("objects", on), ("clutter", off))}


def _strength_figures(both: np.ndarray, sweeps: int) -> dict:
    """(P, 2) strengths dB and beam fills -> the figures of one row of the strengths table."""
    v, fill = both[:, 0], both[:, 1]
    strong = fill[v >= 15.0]
    nan = float("nan")
    return {"plots": int(v.size), "per_sweep": v.size / max(sweeps, 1),
            "p10_db": float(np.percentile(v, 10)) if v.size else nan,
            "p50_db": float(np.percentile(v, 50)) if v.size else nan,
            "p90_db": float(np.percentile(v, 90)) if v.size else nan,
            "under_13_db": float(np.mean(v < 13.0)) if v.size else nan,
            "from_15_db": float(np.mean(v >= 15.0)) if v.size else nan,
            "from_15_db_fill_p50": float(np.median(strong)) if strong.size else nan,
            "from_15_db_fill_under_half": float(np.mean(strong < 0.5)) if strong.size else nan}


def strength_lines(strengths: dict, duration_s: float) -> list[str]:
    """Markdown: the plot strengths table and what the tracker makes of it."""
    lines = [f"## Radar plot strengths, busy_open_sea ({duration_s:.0f} s render), first {STRENGTH_SWEEPS} sweeps", "",
             "Plots that pass the front end; 'objects': within 20 m of an object's outline (truth).", "",
             "| plots on | per sweep | p10 [dB] | median [dB] | p90 [dB] | under 13 dB | from 15 dB "
             "| from 15 dB: median beam fill | from 15 dB: fill under 0.5 |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for name, s in strengths.items():
        lines.append(f"| {name} | {s['per_sweep']:.1f} | {s['p10_db']:.1f} | {s['p50_db']:.1f} | {s['p90_db']:.1f} | "
                     f"{s['under_13_db']:.2f} | {s['from_15_db']:.2f} | {s['from_15_db_fill_p50']:.2f} | "
                     f"{s['from_15_db_fill_under_half']:.2f} |")
    return lines + ["", "The radar tracker counts a plot under 13 dB as half a hit and one from 15 dB as 1.5 hits",
                    "(3 needed in 4 scans): most clutter plots never add up, most object plots confirm in two scans.",
                    "The 13 dB rises 1 dB for every doubling of a plot's resolution cells beyond 8",
                    "(`TrackerConfig.weak_rise_db_per_doubling`: the strongest of many clutter cells stands further out).",
                    "Beam fill (`Detections.beam_fill`): a plot's azimuth extent over what the two-way beam paints",
                    "between its strongest and weakest cells. The tracker counts a plot with a fill under 0.5 as half a",
                    "hit, whatever its strength: a sea spike narrower than the beam. With the clutter-map detection of",
                    "extended echoes (on since 2026-11-29) a spike is mostly joined with the clutter cells about it into a",
                    "plot that fills the beam, and is then weighed by its strength and size."]


def report(heldout: dict, heldout_path: Path, strengths: dict, duration_s: float, quick: bool = False) -> str:
    """The page: the criteria run by run (:func:`criteria_lines`) and the plot strengths (:func:`strength_lines`)."""
    seeds = heldout.get("seeds") or sorted({r["seed"] for r in heldout["runs"]})
    source = heldout_path.relative_to(ROOT) if heldout_path.is_relative_to(ROOT) else heldout_path
    made = heldout.get("generated", "no date recorded").rstrip(".")
    made = made[:1].lower() + made[1:]
    lines = ["# TDM done-when criteria (issue 22), every scenario", "", machine_line("tdm_criteria", quick), "",
             f"The criteria, run by run, from `{source}` ({made}): "
             f"default TDM configuration, tuned on {TUNED} only; every scenario rendered for "
             f"{heldout.get('duration_s', 300):g} s with seeds {', '.join(str(s) for s in seeds)} (benchmarks/tdm_heldout.py; "
             "its page, benchmarks/results/tdm_heldout.md, has the medians, GOSPA and the fusion against its best "
             "sensor). A value in bold does not meet its limit; 'what fails' names the objects behind it: those reported "
             "more than 10 s after coming into view, or never, and those with more than one id switch. Why each "
             "failure happens: docs/tdm.md, \"Where the criteria fail, and why\".", "",
             *criteria_lines(heldout), "", *strength_lines(strengths, duration_s)]
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--heldout", type=Path, default=HELDOUT_JSON, help="benchmarks/tdm_heldout.py's --json")
    parser.add_argument("--fresh", action="store_true", help="render busy_open_sea again even if a matching render exists")
    parser.add_argument("--quick", action="store_true", help="the plot strengths on 90 s of busy_open_sea")
    parser.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results" / "tdm_criteria.md")
    parser.add_argument("--json", type=Path, help="also write the verdicts and strengths as JSON")
    args = parser.parse_args(argv)
    try:
        heldout = load_heldout(args.heldout)
    except HeldoutMissing as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    duration_s, directory = (90.0, Path("/tmp/tdm_bench_bos_90")) if args.quick else (300.0, Path("/tmp/tdm_bench_bos"))
    recording, _ = ensure_recording(BOS, directory, duration_s, fresh=args.fresh)
    strengths = plot_strengths(recording)
    text = report(heldout, args.heldout.resolve(), strengths, duration_s, args.quick)
    print(text)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(text, encoding="utf-8")
    if args.json:
        runs = [{"scenario": r["scenario"], "seed": r["seed"], "verdicts": verdicts(r), "what_fails": what_fails(r)}
                for r in _order(heldout["runs"])]
        args.json.write_text(json.dumps({"runs": runs, "radar_plot_strengths": strengths}, indent=2) + "\n",
                             encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())

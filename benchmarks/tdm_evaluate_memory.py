"""Peak memory of ``tdm evaluate`` against the recording's length, before and after the streaming reads.

Usage::

    python benchmarks/tdm_evaluate_memory.py [--quick] [--fresh] [--before REV] [--out FILE]

- Renders scenarios/busy_open_sea.yaml with AIS and navigation only (``raysim render --sensors
  ais,nav --no-progress`` in a child process) for 600 s and 2400 s (``--quick``: 60 s and 240 s)
  into ``/tmp/tdm_evaluate_memory/rNNN`` (reused when there; ``--fresh`` renders again), then runs
  ``tdm run`` on each (no workers).
- Measures ``tdm evaluate RECORDING`` (metrics.json and both pictures) and ``tdm evaluate
  --no-plots`` in a child process each: peak resident memory (``ru_maxrss`` from ``os.wait4``) and
  wall time. *After*: the ``tdm`` package of this working tree. *Before*: the ``tdm`` package of git
  revision ``--before`` (default :data:`BEFORE_REV`, the last commit whose ``tdm.evaluate`` read
  truth.jsonl whole), exported with ``git archive`` into a temporary directory; both run from a
  neutral directory with ``PYTHONPATH`` set, so nothing else differs.
- Checks that both give the same ``metrics.json`` bytes.
- Writes a Markdown table to ``--out`` (default ``benchmarks/results/tdm_evaluate_memory.md``;
  ``--quick``: ``..._quick.md``). Asked (issue 17): the longer run's peak within about 1.3 times the
  shorter run's.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tarfile
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from benchmarks.common import machine_line  # noqa: E402

SCENARIO = ROOT / "scenarios" / "busy_open_sea.yaml"
#: The last commit before ``tdm evaluate`` read its inputs streaming (issue 17).
BEFORE_REV = "f21aa6d8b33fc83172ffa7b4c699576599e8ed7c"
#: Asked: peak memory of the long run over the short run's.
ASKED_RATIO = 1.3
#: Runs a ``tdm`` command in a child process: ``python -c CHILD tdm-args...``.
CHILD = "import sys; from tdm.cli import main; sys.exit(main(sys.argv[1:]))"


def render(duration_s: float, folder: Path, fresh: bool) -> Path:
    """busy_open_sea, AIS and navigation only, for ``duration_s``, with ``tdm run``'s outputs; reused when there."""
    rec = folder / f"r{int(duration_s)}"
    if fresh or not (rec / "tdm" / "detected_targets.jsonl").is_file():
        if rec.exists():
            shutil.rmtree(rec)
        subprocess.run([sys.executable, "-m", "raysim.cli", "render", str(SCENARIO), "-o", str(rec), "--duration",
                        str(duration_s), "--sensors", "ais,nav", "--no-progress"], check=True, cwd=ROOT,
                       stdout=subprocess.DEVNULL)
        subprocess.run([sys.executable, "-c", CHILD, "run", str(rec), "--workers", "0"], check=True, cwd=ROOT,
                       stdout=subprocess.DEVNULL)
    return rec


def export_tdm(rev: str, into: Path) -> Path:
    """The ``tdm`` package of git revision ``rev`` under ``into`` (a directory for ``PYTHONPATH``)."""
    into.mkdir(parents=True, exist_ok=True)
    archive = into / "tdm.tar"
    with open(archive, "wb") as handle:
        subprocess.run(["git", "archive", rev, "tdm"], check=True, cwd=ROOT, stdout=handle)
    with tarfile.open(archive) as tar:
        tar.extractall(into, filter="data")
    archive.unlink()
    return into


def measure(code_root: Path, recording: Path, plots: bool, cwd: Path) -> tuple[float, float]:
    """(peak resident memory MB, wall s) of ``tdm evaluate recording`` with the ``tdm`` package under ``code_root``."""
    env = {**os.environ, "PYTHONPATH": str(code_root)}
    args = ["evaluate", str(recording)] + ([] if plots else ["--no-plots"])
    start = time.perf_counter()
    proc = subprocess.Popen([sys.executable, "-c", CHILD, *args], cwd=cwd, env=env, stdout=subprocess.DEVNULL)
    _, status, usage = os.wait4(proc.pid, 0)
    wall_s = time.perf_counter() - start
    if os.waitstatus_to_exitcode(status) != 0:
        raise RuntimeError(f"tdm evaluate {recording} failed with the code of {code_root}")
    return usage.ru_maxrss / 1024.0, wall_s


def tree_state() -> str:
    """``HEAD <short hash>``, and the tdm files with uncommitted changes when there are any (they are measured too)."""
    head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True, text=True).stdout.strip()
    dirty = subprocess.run(["git", "status", "--porcelain", "--", "tdm"], cwd=ROOT, capture_output=True,
                           text=True).stdout.split("\n")
    changed = sorted(line[3:] for line in dirty if line.strip())
    return f"HEAD {head}" + (f", with uncommitted changes in {', '.join(changed)}" if changed else "")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="60 s and 240 s recordings instead of 600 s and 2400 s")
    parser.add_argument("--fresh", action="store_true", help="render again even if the recordings are there")
    parser.add_argument("--before", default=BEFORE_REV, help="git revision whose tdm is 'before'")
    parser.add_argument("--recordings", type=Path, default=Path("/tmp/tdm_evaluate_memory"))
    parser.add_argument("--out", type=Path)
    args = parser.parse_args(argv)
    durations = (60.0, 240.0) if args.quick else (600.0, 2400.0)
    out = args.out or ROOT / "benchmarks" / "results" / f"tdm_evaluate_memory{'_quick' if args.quick else ''}.md"
    args.recordings.mkdir(parents=True, exist_ok=True)
    recs = {d: render(d, args.recordings, args.fresh) for d in durations}

    results, same = {}, {}
    with tempfile.TemporaryDirectory() as tmp:
        before_root, neutral = export_tdm(args.before, Path(tmp) / "before"), Path(tmp) / "cwd"
        neutral.mkdir()
        for d, rec in recs.items():  # loop over recordings: before, then after, each with and without pictures
            metrics = {}
            for label, code_root in (("before", before_root), ("after", ROOT)):
                for plots in (True, False):
                    results[(d, label, plots)] = measure(code_root, rec, plots, neutral)
                metrics[label] = (rec / "tdm" / "metrics.json").read_bytes()
            same[d] = metrics["before"] == metrics["after"]

    lines = ["# tdm evaluate: peak memory against the recording's length", "",
             machine_line("tdm_evaluate_memory", args.quick), "",
             f"`tdm evaluate` on busy_open_sea rendered with AIS and navigation only (`raysim render --sensors ais,nav`, "
             f"then `tdm run`), in a child process each: peak resident memory (`ru_maxrss` of `os.wait4`) and wall time. "
             f"Before: the `tdm` package of `{args.before[:10]}` (truth.jsonl and the reports read whole as Python "
             f"dicts). After: this working tree ({tree_state()}; line by line into numpy columns, the 10 Hz truth "
             f"kept only around the epochs). Asked (issue 17): the {durations[1]:.0f} s peak within about {ASKED_RATIO} times the "
             f"{durations[0]:.0f} s peak.", "",
             "| tdm evaluate | " + " | ".join(f"{d:.0f} s" for d in durations) + " | ratio |",
             "|---|" + "---:|" * (len(durations) + 1)]
    for label in ("before", "after"):
        for plots in (True, False):
            peaks = [results[(d, label, plots)][0] for d in durations]
            walls = [results[(d, label, plots)][1] for d in durations]
            name = f"{label}{'' if plots else ', --no-plots'}"
            lines.append(f"| {'**' if label == 'after' and plots else ''}{name}: peak MB"
                         f"{'**' if label == 'after' and plots else ''} | "
                         + " | ".join(f"{p:.0f}" for p in peaks) + f" | {peaks[1] / peaks[0]:.2f} |")
            lines.append(f"| {name}: wall s | " + " | ".join(f"{w:.1f}" for w in walls) + " | |")
    sizes = {d: (recs[d] / "truth.jsonl").stat().st_size / 1e6 for d in durations}
    n_lines = {d: sum(1 for _ in open(recs[d] / "truth.jsonl", "rb")) for d in durations}
    lines += ["", "truth.jsonl: " + ", ".join(f"{d:.0f} s: {n_lines[d]:,} lines, {sizes[d]:.0f} MB" for d in durations)
              + ". metrics.json before and after: " + ", ".join(f"{d:.0f} s {'identical' if same[d] else 'DIFFERENT'}"
                                                                 for d in durations) + "."]
    text = "\n".join(lines) + "\n"
    print(text)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(text, encoding="utf-8")
    json_figures = {f"{d:.0f}s/{label}/{'plots' if plots else 'no-plots'}": {"peak_mb": v[0], "wall_s": v[1]}
                    for (d, label, plots), v in results.items()}
    print(json.dumps(json_figures))
    return 0 if all(same.values()) else 1


if __name__ == "__main__":
    sys.exit(main())

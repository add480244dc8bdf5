"""The ``tdm`` command (docs/contracts.md "Command line").

- ``tdm run RECORDING [-o DIR] [--fusion simple|ci] [--lidar-source auto|npz|pcap] [--workers N]``
  writes ``DIR/detected_targets.jsonl`` and ``DIR/sensor_tracks.jsonl`` (default DIR = RECORDING/tdm);
- ``tdm evaluate RECORDING`` writes ``RECORDING/tdm/metrics.json`` and the plots, and prints a table;
- ``tdm info RECORDING`` summarises a recording.

Bad input: one line on stderr naming the file, the place and what is wrong, exit code 2. Outputs
appear whole or not at all (:mod:`tdm.staging`); an output that cannot be written (a full disk) prints
``error: <DIR>: writing: no space left on device``, exit code 2; Ctrl-C exits with 130, SIGTERM with 143.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from tdm import __version__
from tdm.errors import RecordingError


class _Parser(argparse.ArgumentParser):
    def error(self, message: str):
        raise RecordingError("command line", self.prog, message)


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="tdm", description="Target detection module: recordings in, detected targets out.")
    parser.add_argument("--version", action="version", version=f"tdm {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    info = sub.add_parser("info", help="summarise a recording directory")
    info.add_argument("recording", type=Path)
    run = sub.add_parser("run", help="detect and track targets in a recording")
    run.add_argument("recording", type=Path)
    run.add_argument("-o", "--out", type=Path, default=None, help="output directory (default RECORDING/tdm)")
    run.add_argument("--fusion", choices=("simple", "ci"), default="simple",
                     help="fusion rule: thesis eq. 3.2 (simple) or covariance intersection (ci)")
    run.add_argument("--lidar-source", choices=("auto", "npz", "pcap"), default="auto",
                     help="read LiDAR from the NPZ sweeps or the Velodyne PCAP (auto: NPZ when present)")
    run.add_argument("--workers", type=int, default=2, help="front-end worker processes (0: none)")
    ev = sub.add_parser("evaluate", help="score RECORDING/tdm against the recording's truth")
    ev.add_argument("recording", type=Path)
    ev.add_argument("--no-plots", action="store_true", help="skip the pictures")
    return parser


def run_command(recording: Path, out: Path | None = None, fusion: str = "simple", lidar_source: str = "auto",
                workers: int = 2, progress: bool | None = None):
    """``tdm run`` as a function (used by ``raysim run``); its files appear in ``out`` together or not at all."""
    from tdm.io import read_manifest
    from tdm.pipeline import TdmConfig, run_tdm
    from tdm.staging import StagedOutputs

    read_manifest(recording)  # a recording directory at all?
    config = TdmConfig.for_recording(recording, fusion=fusion, lidar_source=lidar_source, workers=max(0, int(workers)))
    out_dir = Path(out) if out is not None else Path(recording) / "tdm"
    with StagedOutputs(out_dir) as staged:
        result = run_tdm(recording, staged.path, config, progress=sys.stderr.isatty() if progress is None else progress)
        staged.commit()
    result.out_dir = out_dir
    return result


def evaluate_command(recording: Path, plots: bool = True) -> dict:
    """``tdm evaluate`` as a function: metrics.json and the plots (together or not at all); returns the metrics."""
    from tdm.evaluate import evaluate, write_metrics
    from tdm.io import read_manifest
    from tdm.staging import StagedOutputs

    read_manifest(recording)  # a recording directory at all?
    metrics = evaluate(recording)
    with StagedOutputs(Path(recording) / "tdm") as staged:
        write_metrics(staged.root, metrics)  # writes <root>/tdm/metrics.json, i.e. into staged.path
        if plots:
            from tdm.plots import plot_errors, plot_tracks

            plot_tracks(recording, staged.path / "tracks.png")
            plot_errors(recording, metrics, staged.path / "errors.png")
        staged.commit()
    return metrics


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``tdm`` console script (exit codes: 0, 2 bad input or unwritable output, 130, 143)."""
    from tdm.staging import EXIT_TERMINATED, sigterm_as_interrupt

    with sigterm_as_interrupt() as sigterm:  # SIGTERM ends a command as Ctrl-C does
        try:
            return _main(argv)
        except Exception:
            if not sigterm.received:
                raise
            print("error: terminated; nothing was written", file=sys.stderr)  # it surfaced as another exception
            return EXIT_TERMINATED


def _main(argv: list[str] | None) -> int:
    from tdm.staging import report_fault

    parser = build_parser()
    args = None
    try:
        args = parser.parse_args(argv)
        if args.command == "info":
            from tdm.recording.summary import summarise

            summary = summarise(args.recording)  # every file checked as far as its headers (tdm.recording)
            print("\n".join(summary.lines(args.recording)))
            for what, n in sorted(summary.warnings.items()):
                print(f"warning: {what}: {n}", file=sys.stderr)
        elif args.command == "run":
            if args.workers < 0:
                raise RecordingError("command line", "--workers", "must be >= 0")
            result = run_command(args.recording, args.out, args.fusion, args.lidar_source, args.workers)
            scans = ", ".join(f"{k} {v}" for k, v in result.scans.items())
            print(f"tdm: {result.n_targets} targets, {result.n_target_lines} target lines over {result.n_epochs} epochs "
                  f"({scans}) -> {result.out_dir}")
            for what, n in sorted(result.warnings.items()):
                print(f"warning: {what}: {n}", file=sys.stderr)
        elif args.command == "evaluate":
            from tdm.evaluate import format_table

            metrics = evaluate_command(args.recording, plots=not args.no_plots)
            print(format_table(metrics))
            for what, n in sorted((metrics.get("warnings") or {}).items()):
                print(f"warning: {what}: {n}", file=sys.stderr)
        return 0
    except (RecordingError, OSError, KeyboardInterrupt) as exc:  # one line on stderr (groundfloor.staging)
        code = report_fault(exc, getattr(args, "out", None), bad_input=RecordingError)
        if code is not None:
            return code
        raise  # an OSError that is no write fault: a bug, with its traceback


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())

"""The ``tdm`` command (docs/contracts.md "Command line").

- ``tdm run RECORDING [-o DIR] [--fusion simple|ci] [--lidar-source auto|npz|pcap] [--workers N]``
  writes ``DIR/detected_targets.jsonl`` and ``DIR/sensor_tracks.jsonl`` (default DIR = RECORDING/tdm);
- ``tdm evaluate RECORDING`` writes ``RECORDING/tdm/metrics.json`` and the plots, and prints a table;
- ``tdm info RECORDING`` summarises a recording.

Bad input: one line on stderr naming the file, the place and what is wrong, exit code 2.
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
    """``tdm run`` as a function (used by ``raysim run``)."""
    from tdm.io import read_manifest
    from tdm.pipeline import TdmConfig, run_tdm

    read_manifest(recording)  # a recording directory at all?
    config = TdmConfig.for_recording(recording, fusion=fusion, lidar_source=lidar_source, workers=max(0, int(workers)))
    return run_tdm(recording, out, config, progress=sys.stderr.isatty() if progress is None else progress)


def evaluate_command(recording: Path, plots: bool = True) -> dict:
    """``tdm evaluate`` as a function: metrics.json and the plots; returns the metrics."""
    from tdm.evaluate import evaluate, write_metrics
    from tdm.io import read_manifest

    read_manifest(recording)  # a recording directory at all?
    metrics = evaluate(recording)
    write_metrics(recording, metrics)
    if plots:
        from tdm.plots import plot_errors, plot_tracks

        out = Path(recording) / "tdm"
        plot_tracks(recording, out / "tracks.png")
        plot_errors(recording, metrics, out / "errors.png")
    return metrics


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``tdm`` console script."""
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
        if args.command == "info":
            from tdm.io import read_manifest, read_ownship

            manifest = read_manifest(args.recording)
            nav = read_ownship(args.recording)
            print(f"{args.recording}: scenario {manifest.get('scenario')}, seed {manifest.get('seed')}, "
                  f"{manifest.get('duration_s')} s, sensors {', '.join(manifest.get('sensors_rendered', [])) or 'none'}")
            print(f"  own ship: {nav['t'].shape[0]} navigation samples, {nav['t'][-1]:.1f} s")
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
        return 0
    except RecordingError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())

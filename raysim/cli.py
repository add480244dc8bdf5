"""The ``raysim`` command: it only wires (docs/contracts.md "Command line").

Bad input of any kind prints one line ``error: <file>: <place>: <what>`` on
stderr and exits with code 2, leaving nothing behind. So does an output that cannot
be written (a full disk: ``error: <directory>: writing: no space left on device``).
Ctrl-C exits with code 130 and SIGTERM with 143, after the same cleanup.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
from pathlib import Path

from raysim import __version__
from raysim.errors import InputError

SENSOR_NAMES = ("lidar", "radar", "ais", "nav")


class _Parser(argparse.ArgumentParser):
    def error(self, message: str):  # one line, exit 2, like every other bad input
        raise InputError("command line", self.prog, message)


def _duration(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise InputError("command line", "--duration", f"not a number: {text!r}") from None
    if not (math.isfinite(value) and 0 < value <= 86_400):
        raise InputError("command line", "--duration", f"must be > 0 and <= 86400 s, got {text}")
    return value


def _seed(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise InputError("command line", "--seed", f"not an integer: {text!r}") from None
    if value < 0:
        raise InputError("command line", "--seed", f"must be >= 0, got {value}")
    return value


def _sensors(text: str) -> tuple[str, ...]:
    names = tuple(n.strip() for n in text.split(",") if n.strip())
    for name in names:
        if name not in SENSOR_NAMES:
            raise InputError("command line", "--sensors", f"unknown sensor {name!r} (known: {', '.join(SENSOR_NAMES)})")
    if not names:
        raise InputError("command line", "--sensors", "name at least one sensor")
    return names


def _formats(text: str) -> tuple[str, ...]:
    from raysim.recording.pointclouds import FORMATS

    names = tuple(n.strip() for n in text.split(",") if n.strip())
    for name in names:
        if name not in FORMATS:
            raise InputError("command line", "--formats", f"unknown format {name!r} (known: {', '.join(FORMATS)})")
    return names


def _count(option: str):
    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise InputError("command line", option, f"not an integer: {text!r}") from None
        if value < 1:
            raise InputError("command line", option, f"must be >= 1, got {value}")
        return value

    return parse


def _vary(text: str):
    from raysim.batch import parse_vary

    return parse_vary(text)


def _route(text: str) -> list[list[float]]:
    points = []
    for part in text.split(";"):
        try:
            lat, lon = (float(v) for v in part.split(","))
        except ValueError:
            raise InputError("command line", "--route", f"expected 'lat,lon;lat,lon;...', got {part!r}") from None
        points.append([lat, lon])
    return points


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="raysim", description="Physics-based raw sensor renderer for autonomous surface vessels.")
    parser.add_argument("--version", action="version", version=f"raysim {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)

    def common(p, sensors: bool):
        p.add_argument("scenario", type=Path, help="scenario YAML file")
        p.add_argument("-o", "--out", type=Path, help="recording directory (default: runs/<scenario name>)")
        p.add_argument("--duration", type=_duration, help="override duration_s")
        p.add_argument("--seed", type=_seed, help="override the seed")
        if sensors:
            p.add_argument("--sensors", type=_sensors, help="comma-separated subset of lidar,radar,ais,nav")
        p.add_argument("--formats", type=_formats, default=(),
                       help="extra LiDAR point-cloud files: comma-separated pcd,kitti")
        p.add_argument("--no-progress", action="store_true", help="no progress bars")

    common(sub.add_parser("render", help="render a scenario into a recording directory"), sensors=True)
    common(sub.add_parser("run", help="render, then run and evaluate the TDM"), sensors=False)

    imp = sub.add_parser("import-hilsim", help="convert the 2017 HIL simulator's configuration files")
    imp.add_argument("obstacles", type=Path)
    imp.add_argument("sensors", type=Path)
    imp.add_argument("dynamics", type=Path, nargs="?")
    imp.add_argument("-o", "--out", type=Path, required=True, help="scenario YAML to write")
    imp.add_argument("--name", default=None, help="scenario name (default: the output file's stem)")
    imp.add_argument("--route", type=_route, help="own-ship waypoints 'lat,lon;lat,lon;...' (default: lie still at the start)")
    imp.add_argument("--speed-kn", type=float, default=8.0, help="own-ship speed on the route, knots")
    imp.add_argument("--duration", type=_duration, default=300.0, help="scenario duration, s")

    batch = sub.add_parser("batch", help="render, run and evaluate many seeds and variants on Dask (docs/batch.md)")
    batch.add_argument("scenario", type=Path, help="scenario YAML file")
    batch.add_argument("-o", "--out", type=Path, required=True, help="batch directory (runs/, results/, summary.csv)")
    batch.add_argument("--seeds", type=_count("--seeds"), default=1, help="runs per variant, seeds base .. base + N - 1")
    batch.add_argument("--seed", type=_seed, help="first seed (default: the scenario's)")
    batch.add_argument("--vary", type=_vary, action="append", default=[], metavar="KEY=V1,V2,...",
                       help="a scenario key path and its values; repeat for more keys (all combinations run)")
    batch.add_argument("--duration", type=_duration, help="override duration_s")
    batch.add_argument("--scheduler", help="address of a Dask scheduler (default: a local cluster)")
    batch.add_argument("--workers", type=_count("--workers"), help="local cluster worker processes (default: one per core)")
    batch.add_argument("--no-progress", action="store_true", help="no progress lines")

    bench = sub.add_parser("bench", help="run the benchmarks and print their tables")
    bench.add_argument("--quick", action="store_true", help="fewer rays and repetitions")
    bench.add_argument("--json", type=Path, help="also write the results as JSON")

    rcs = sub.add_parser("rcs", help="radar cross-section of a mesh by shooting and bouncing rays (docs/radar.md)")
    rcs.add_argument("mesh", type=Path, help="mesh file (.obj/.stl/.ply/.glb), body frame, m")
    rcs.add_argument("--material", default="steel", help="steel (perfect conductor) or a raysim material name")
    rcs.add_argument("--range-m", type=float, default=1000.0, help="range, m (far field: reported only)")
    rcs.add_argument("--aspects", type=_count("--aspects"), default=360, help="aspects over 360 deg")
    rcs.add_argument("--elevation-deg", type=float, default=0.0, help="radar elevation above the xy plane, deg")
    rcs.add_argument("--frequency-ghz", type=float, default=9.41, help="radar frequency, GHz")
    rcs.add_argument("--polarisation", default="HH", help="HH, VV, HV or VH")
    rcs.add_argument("--sea", action="store_true", help="sea at z = 0 (Fresnel reflection of sea water, rough)")
    rcs.add_argument("--sea-state", type=float, default=3, help="Douglas sea state 0..6 of --sea (default 3)")
    rcs.add_argument("--plating-rms-mm", type=float, default=3.0,
                     help="rms unfairness of the plating, mm (default 3: ship plating; 0: smooth)")
    rcs.add_argument("--bounces", type=_count("--bounces"), default=3, help="maximum bounces per ray")
    rcs.add_argument("--ray-spacing-m", type=float, help="ray-tube side, m (default lambda/4, coarser for big meshes)")
    rcs.add_argument("--json", type=Path, help="also write the results as JSON")
    from raysim.live.command import add_live_parser

    add_live_parser(sub, _duration, _seed)
    return parser


def _load(args):
    """The scenario of the command line, with its overrides applied."""
    from raysim.scenario import load_scenario, with_overrides

    scenario = load_scenario(args.scenario)
    return with_overrides(scenario, args.duration, args.seed, getattr(args, "sensors", None))


def _out_dir(args, scenario) -> Path:
    return args.out if args.out is not None else Path("runs") / scenario.name


def _render_processes() -> int:
    """Processes to render the sensors in (:func:`raysim.render.render`): 2 with two or more cores."""
    return 2 if (os.cpu_count() or 1) >= 2 else 1


def cmd_render(args) -> int:
    from raysim.render import render

    scenario = _load(args)
    result = render(scenario, _out_dir(args, scenario), progress=False if args.no_progress else None,
                    formats=args.formats, processes=_render_processes())
    _summary(result)
    return 0


def cmd_run(args) -> int:
    """The main job: render, run the TDM on the recording, evaluate it; the targets join the bag."""
    from raysim.runner import render_detect_evaluate
    from tdm.evaluate import format_table

    scenario = _load(args)
    result, metrics = render_detect_evaluate(scenario, _out_dir(args, scenario),
                                             progress=False if args.no_progress else None, formats=args.formats,
                                             processes=_render_processes())
    _summary(result)
    print(format_table(metrics))
    return 0


def cmd_batch(args) -> int:
    """Monte-Carlo batch: every (variant, seed) rendered, run and evaluated on Dask; DIR/summary.csv."""
    from raysim.batch import plan_batch, progress_printer, run_batch

    runs = plan_batch(args.scenario, seeds=args.seeds, vary=args.vary, duration_s=args.duration, base_seed=args.seed)
    try:
        rows = run_batch(runs, args.out, scheduler=args.scheduler, workers=args.workers,
                         progress=progress_printer(not args.no_progress))
    except KeyboardInterrupt as exc:
        from raysim.recording.staging import report_fault

        return report_fault(exc, nothing_written="the finished runs are kept: the same command goes on from there")
    failed = [r for r in rows if r["status"] != "ok"]
    print(f"batch of {len(rows)} runs in {args.out}: {len(rows) - len(failed)} ok, {len(failed)} failed; "
          f"summary in {args.out / 'summary.csv'}")
    for row in failed:
        print(f"  failed: {row['run']}: {row['error']}")
    return 1 if failed else 0


#: manifest ``wall_time_s`` key -> the summary's name for that part of the run (the rest is "render")
WALL_PARTS = {"tdm": "tdm", "rosbag": "bag", "pictures": "pictures", "pointclouds": "point clouds"}


def _bytes_text(n_bytes: int) -> str:
    """``4.4 GB``, ``89 MB``, ``512 B``: decimal units, two or three significant digits."""
    for unit, size in (("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if n_bytes >= size:
            value = n_bytes / size
            return f"{value:.1f} {unit}" if value < 10 else f"{value:.0f} {unit}"
    return f"{n_bytes} B"


def _doc(name: str) -> str:
    """Path of the source tree's ``docs/<name>``: relative when under the working directory, else absolute."""
    path = Path(__file__).resolve().parents[1] / "docs" / name
    if not path.parent.is_dir():  # installed without the source tree
        return f"docs/{name}"
    try:
        return str(path.relative_to(Path.cwd().resolve()))
    except ValueError:
        return str(path)


def summary_lines(out_dir: Path, manifest: dict) -> list[str]:
    """What ``raysim render`` / ``raysim run`` print at the end.

    Parameters
    ----------
    out_dir : Path
        The recording directory written.
    manifest : dict
        Its manifest.json (``wall_time_s`` holds the parts of the time: :data:`WALL_PARTS`).

    Returns
    -------
    list of str
        What was done, in how long (total and per part) and how many bytes were written; the
        counts; sensors not rendered; where to look next (the bag in Foxglove, the pictures, the docs).
    """
    m, out = manifest, Path(out_dir)
    wall = m["wall_time_s"]
    parts = {label: wall[key] for key, label in WALL_PARTS.items() if key in wall}
    parts = {"render": wall.get("render", wall["total"] - sum(parts.values())), **parts}
    times = ", ".join(f"{label} {s:.1f} s" for label, s in parts.items())
    if sum(parts.values()) > wall["total"] + 0.1 * len(parts):  # parts that ran side by side
        times += "; the bag beside the evaluation and the pictures"
    written = sum(p.stat().st_size for p in out.rglob("*") if p.is_file())
    verb = "rendered, detected and evaluated" if "tdm" in wall else "rendered"
    lines = [f"{verb} {m['scenario']} ({m['duration_s']:g} s, seed {m['seed']}) into {out} in {wall['total']:.1f} s "
             f"({times}); {_bytes_text(written)} written",
             "  " + ", ".join(f"{k}: {v}" for k, v in m["counts"].items())]
    if m["sensors_not_available"]:
        lines.append(f"  not rendered (not implemented in this version): {', '.join(m['sensors_not_available'])}")
    bags = sorted((out / "rosbag").glob("*.mcap"))
    if bags:
        lines.append(f"  next: open {bags[0]} in Foxglove with the layout {_doc('foxglove_layout.json')}")
    folders = [f"{out / d}/" for d in ("radar/ppi", "lidar/bev") if any((out / d).glob("*.png"))]
    pictures = [str(out / "map.png"), *folders]
    pictures += [str(p) for p in sorted((out / "tdm").glob("*.png"))]
    lines.append(f"  pictures: {', '.join(pictures)}")
    lines.append(f"  every file and how to open it: {_doc('formats.md')}")
    return lines


def _summary(result) -> None:
    print("\n".join(summary_lines(result.out_dir, result.manifest)))


def cmd_import_hilsim(args) -> int:
    from raysim.hilsim import import_hilsim, scenario_text
    from raysim.recording.staging import atomic_path
    from raysim.scenario import load_scenario

    name = args.name or args.out.stem
    scenario, comments = import_hilsim(args.obstacles, args.sensors, args.dynamics, name=name, route=args.route,
                                       speed_kn=args.speed_kn, duration_s=args.duration)
    files = " ".join(p.name for p in (args.obstacles, args.sensors, args.dynamics) if p is not None)
    if args.route:
        route = ";".join(f"{lat:.6f},{lon:.6f}" for lat, lon in args.route)
        files += f' --route "{route}" --speed-kn {args.speed_kn:g}'
    header = [f"Made by `raysim import-hilsim {files}` from the 2017 thesis's configuration files.",
              "Thesis parameters without a native key are kept as comments below."]
    text = scenario_text(scenario, comments, header)
    with atomic_path(args.out) as tmp:
        tmp.write_text(text, encoding="utf-8")
        try:
            load_scenario(tmp)  # the result must be a valid scenario
        except InputError as exc:
            raise InputError(exc.file.replace(tmp.name, args.out.name), exc.where, exc.what) from None
    print(f"wrote {args.out}: {len(scenario['obstacles'])} obstacles, {len(scenario['ships'])} ships")
    return 0


BENCHMARKS = ("ray_engine", "lidar", "radar", "rosbag", "tdm_speed", "tdm_criteria", "batch_throughput")


def cmd_rcs(args) -> int:
    """Radar cross-section of a mesh over a turn of aspects (:mod:`raysim.rcs`)."""
    from raysim.rcs.command import run

    return run(args)


def cmd_bench(args) -> int:
    """Run the benchmarks and print their tables (the committed results files are left untouched).

    The benchmarks are scripts of the source tree's benchmarks/ folder (the ray engine's
    first, one run of it); an installed copy without that folder says so in one line (exit 1).
    With ``--json`` the file holds ``{"ray_engine": ..., "<script>": ...}``.
    """
    import importlib.util
    import json
    import tempfile

    folder = Path(__file__).resolve().parents[1] / "benchmarks"
    if not (folder / "ray_engine.py").is_file():
        print(f"error: raysim bench runs the scripts of the source tree's benchmarks/ folder; {folder} has none",
              file=sys.stderr)
        return 1
    combined = {}
    with tempfile.TemporaryDirectory() as tmp:
        for name in BENCHMARKS:
            if not (folder / f"{name}.py").is_file():
                continue
            spec = importlib.util.spec_from_file_location(f"raysim_bench_{name}", folder / f"{name}.py")
            module = importlib.util.module_from_spec(spec)
            spec.loader.exec_module(module)
            json_path = Path(tmp) / f"{name}.json"
            argv = ["--out", str(Path(tmp) / f"{name}.md"), "--json", str(json_path)] + (["--quick"] if args.quick else [])
            argv += ["--runs", "1"] if name == "ray_engine" else []
            if module.main(argv) != 0:
                return 1
            combined[name] = json.loads(json_path.read_text(encoding="utf-8"))
    if args.json:
        args.json.write_text(json.dumps(combined, indent=2) + "\n", encoding="utf-8")
    return 0


def cmd_live(args) -> int:
    """Live mode: the sensors' packets on the network on the wall clock (raysim.live)."""
    from raysim.live.command import cmd_live as live

    return live(args, _load)


COMMANDS = {"render": cmd_render, "run": cmd_run, "batch": cmd_batch, "import-hilsim": cmd_import_hilsim,
            "bench": cmd_bench, "rcs": cmd_rcs, "live": cmd_live}


def _after_interrupt(exc: BaseException) -> bool:
    """Whether ``exc`` came of a Ctrl-C: a KeyboardInterrupt among its causes and contexts."""
    seen = set()
    while exc is not None and id(exc) not in seen:
        if isinstance(exc, KeyboardInterrupt):
            return True
        seen.add(id(exc))
        exc = exc.__cause__ or exc.__context__
    return False


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``raysim`` console script.

    Exit codes: 0 done, 1 a batch with failed runs, 2 bad input or an output that cannot be
    written (full disk, quota, read-only, I/O error), 130 Ctrl-C, 143 SIGTERM; the last four print
    one line ``error: ...`` on stderr and leave no staging directory behind.
    """
    from raysim.recording.staging import Terminated, report_fault, sigterm_as_interrupt

    args = None
    try:
        with sigterm_as_interrupt() as sigterm:
            try:
                args = build_parser().parse_args(argv)
                return COMMANDS[args.command](args)
            except Exception as exc:
                if sigterm.received:  # SIGTERM surfaced as another exception (from a C extension)
                    raise Terminated() from exc
                if _after_interrupt(exc):  # Ctrl-C surfaced so (Open3D's import: "initialization failed")
                    raise KeyboardInterrupt() from exc
                raise
    except (InputError, OSError, KeyboardInterrupt) as exc:  # bad input, a write fault, an interrupt: one line
        code = report_fault(exc, getattr(args, "out", None), bad_input=InputError)
        if code is None:  # an OSError that is no write fault: a bug, with its traceback
            raise
        return code


def console() -> None:
    """The ``raysim`` console script: :func:`main`, then exit with its code.

    After SIGTERM or Ctrl-C (codes 143 and 130) the cleanup has run and its line is printed; the
    process then ends at once, without the interpreter's finalization, which while the ray engine's
    worker threads wind down after the interrupt turned the exit code into 1 in about half the runs
    (tests/raysim/test_faults.py).
    """
    from groundfloor.staging import EXIT_INTERRUPTED, EXIT_TERMINATED

    code = main()
    if code in (EXIT_TERMINATED, EXIT_INTERRUPTED):
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(code)
    sys.exit(code)


if __name__ == "__main__":  # pragma: no cover
    console()

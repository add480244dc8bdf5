"""The corpus of malformed scenarios (issue 17: "Every bad input: one line, exit 2, nothing lost").

Every case is made from the default scenario ``scenarios/busy_open_sea.yaml`` by one hand-made
slip, and names the error line ``raysim render`` must print: ``error: <file>: <place>: <what>``
with exit code 2. Small cases are committed under ``scenarios/`` next to this file with their
index ``expected.json``; special files (FIFOs, sockets, symlink loops) and big ones (a million
aliases, 30,000 buoys) are made at test time (``generated``). Rewrite the committed ones with::

    python tests/raysim/corpus/make_scenarios.py

In an expectation, ``{dir}`` stands for the case's folder (resolved) and ``#`` in ``place`` for
a number (a line or column that depends on the YAML parser).
"""

from __future__ import annotations

import json
import os
import socket
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[2]
BASE_PATH = REPO / "scenarios" / "busy_open_sea.yaml"
CORPUS = HERE / "scenarios"
INDEX = CORPUS / "expected.json"

#: The own ship's start in the base scenario (its first waypoint and the origin).
LAT0, LON0 = 59.4377744115633, 10.471651180041
ROUTE = """  route:
    speed_kn: 8.0
    waypoints:
    - [59.4377744115633, 10.471651180041]
    - [59.438762, 10.472885]
    - [59.437281, 10.477643]
    - [59.438851, 10.479229]
    - [59.441185, 10.476057]
    - [59.441185, 10.469007]
"""


@dataclass(frozen=True)
class Case:
    """One malformed scenario and the error line it must give.

    Attributes
    ----------
    name : str
        Also the scenario's file name (``<name>.yaml``) unless ``make`` says otherwise.
    description : str
        The slip, in words.
    place, what : str
        The error's place and the start of its message.
    make : callable
        ``make(folder, name) -> path``: writes the case (and its mesh / CSV files) into ``folder``
        and returns the path to render.
    file : str or None
        The file the error names, relative to the folder; None: the scenario itself.
    generated : bool
        Made at test time (special or big files), not committed.
    """

    name: str
    description: str
    place: str
    what: str
    make: Callable[[Path], Path]
    file: str | None = None
    generated: bool = False


def base_text() -> str:
    return BASE_PATH.read_text(encoding="utf-8")


def edit(*pairs: tuple[str, str]) -> str:
    """The base scenario with each ``old`` replaced by ``new`` (each ``old`` must occur)."""
    text = base_text()
    for old, new in pairs:
        if old not in text:
            raise ValueError(f"not in the base scenario: {old!r}")
        text = text.replace(old, new, 1)
    return text


def line_of(text: str, snippet: str, occurrence: int = 1) -> int:
    """1-based line of the ``occurrence``-th ``snippet`` in ``text``."""
    at = -1
    for _ in range(occurrence):
        at = text.index(snippet, at + 1)
    return text.count("\n", 0, at) + 1


def with_obstacle(lines: str) -> str:
    """The base scenario with one more obstacle (``obstacles[14]``) given by its YAML lines."""
    return edit(("ships:\n", lines + "ships:\n"))


def mesh_obstacle(mesh: str) -> str:
    return with_obstacle(f"- name: Pier\n  kind: mesh\n  position: [59.438807, 10.472209]\n  mesh: {mesh}\n")


def csv_own_ship(csv_name: str) -> str:
    return edit((ROUTE, f"  trajectory_csv: {csv_name}\n"))


def track(rows: list[tuple], columns: str = "t_s,lat,lon,heading_deg") -> str:
    """CSV text: a header and one line per row (``t_s, lat, lon`` and heading 0 unless the row says more)."""
    lines = [columns]
    for row in rows:
        values = list(row) + [0.0] * (len(columns.split(",")) - len(row))
        lines.append(",".join(repr(v) if isinstance(v, float) else str(v) for v in values))
    return "\n".join(lines) + "\n"


def straight_track(n: int = 32, step_s: float = 10.0) -> list[tuple[float, float, float]]:
    """A track north from the start at 4 m/s, ``n`` samples ``step_s`` apart."""
    return [(i * step_s, round(LAT0 + i * 0.000359, 9), LON0) for i in range(n)]


# ----------------------------------------------------------------------------- writers


def text_case(text: str | Callable[[], str], name: str | None = None):
    """``make`` writing ``text`` as the case's scenario."""

    def make(folder: Path, _name: str) -> Path:
        path = folder / f"{name or _name}.yaml"
        path.write_text(text() if callable(text) else text, encoding="utf-8")
        return path

    return make


def bytes_case(data: bytes):
    def make(folder: Path, name: str) -> Path:
        path = folder / f"{name}.yaml"
        path.write_bytes(data)
        return path

    return make


def with_files(scenario: str, files: dict[str, str | bytes]):
    """``make`` writing the scenario and its side files (``{name}`` in names and text: the case name)."""

    def make(folder: Path, name: str) -> Path:
        for file_name, content in files.items():
            target = folder / file_name.format(name=name)
            if isinstance(content, bytes):
                target.write_bytes(content)
            else:
                target.write_text(content, encoding="utf-8")
        path = folder / f"{name}.yaml"
        path.write_text(scenario.replace("{name}", name), encoding="utf-8")
        return path

    return make


def special_case(scenario: str | None, special: str, kind: str):
    """``make`` for a special file at ``special`` (a FIFO, socket, symlink loop, directory, ...).

    With ``scenario`` None the special file is the scenario itself.
    """

    def make(folder: Path, name: str) -> Path:
        target = folder / special.format(name=name)
        if kind == "fifo":
            os.mkfifo(target)
        elif kind == "socket":
            server = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
            server.bind(str(target))
            server.close()  # the socket file stays
        elif kind == "loop":
            os.symlink(target.name + ".2", target)
            os.symlink(target.name, str(target) + ".2")
        elif kind == "broken":
            os.symlink("nowhere.glb", target)
        elif kind == "directory":
            target.mkdir()
        elif kind == "sparse":
            with open(target, "wb") as handle:
                handle.truncate(17_000_000)
        if scenario is None:
            return target
        path = folder / f"{name}.yaml"
        path.write_text(scenario.replace("{special}", target.name), encoding="utf-8")
        return path

    return make


# ----------------------------------------------------------------------------- big texts


def billion_laughs() -> str:
    lines = ['lol0: &lol0 ["lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol"]']
    for i in range(1, 10):
        lines.append(f"lol{i}: &lol{i} [" + ", ".join([f"*lol{i - 1}"] * 10) + "]")
    return "name: billion_laughs\n" + "\n".join(lines) + "\nobstacles: *lol9\n"


def million_aliases() -> str:
    head = edit(("obstacles:\n- name: Iceberg_1\n",
                 "buoy: &buoy {name: B, kind: buoy, position: [59.4379, 10.473]}\nobstacles:\n- name: Iceberg_1\n"))
    head, tail = head.split("ships:\n", 1)
    return head + "- *buoy\n" * 1_000_000 + "ships:\n" + tail


def buoys(n: int) -> str:
    rows = "".join(f"- {{name: B{i}, kind: buoy, position: [{59.4388 + (i // 100) * 0.00002:.6f}, "
                   f"{10.4700 + (i % 100) * 0.00004:.6f}]}}\n" for i in range(n))
    return edit(("ships:\n", rows + "ships:\n"))


def deep_flow(levels: int) -> str:
    return "name: deep\nobstacles: " + "[" * levels + "]" * levels + "\n"


def deep_block(levels: int) -> str:
    return "name: deep\n" + "".join("  " * i + f"k{i}:\n" for i in range(levels)) + "  " * levels + "v: 1\n"


# ----------------------------------------------------------------------------- the cases

_DUP_DURATION = edit(("seed: 7\n", "seed: 7\nduration_s: 99999\n"))
_DUP_LENGTH = edit(("  beam_m: 3.5\n", "  beam_m: 3.5\n  length_m: 109\n"))
_DUP_FLOW = edit(("  ais:\n    enabled: true\n    mmsi: 257000001\n",
                  "  ais: {enabled: true, mmsi: 257000001, mmsi: 257000003}\n"))
_DUP_ITEM = edit(("- name: support_vessel\n  kind: ship\n", "- name: support_vessel\n  kind: ship\n  name: tender\n"))
_DUP_TOP = base_text() + "obstacles: []\n"
_NEAR_TRACK = straight_track()

CASES: list[Case] = [
    # --- the tracebacks
    Case("start_year_9999", "a start time whose run passes year 9999", "start_time",
         "the run (duration_s 300 s from 9999-12-31T23:59:00Z) ends after 2038-01-19T03:14:07Z",
         text_case(edit(("start_time: '2017-06-01T12:00:00Z'", "start_time: '9999-12-31T23:59:00Z'")))),
    Case("start_before_year_1_utc", "a start time before year 1 in UTC (quoted)", "start_time",
         "0001-01-01T00:30:00+01:00 is before 0001-01-01T00:00:00Z",
         text_case(edit(("start_time: '2017-06-01T12:00:00Z'", "start_time: '0001-01-01T00:30:00+01:00'")))),
    Case("start_before_year_1_utc_unquoted", "a start time before year 1 in UTC (a YAML timestamp)", "start_time",
         "0001-01-01T00:30:00+01:00 is before 0001-01-01T00:00:00Z",
         text_case(edit(("start_time: '2017-06-01T12:00:00Z'", "start_time: 0001-01-01T00:30:00+01:00")))),
    Case("start_before_1970", "a start time before the PCAP's and the bag's epoch", "start_time",
         "1969-12-31T23:59:59Z is before 1970-01-01T00:00:00Z",
         text_case(edit(("start_time: '2017-06-01T12:00:00Z'", "start_time: '1969-12-31T23:59:59Z'")))),
    Case("start_after_2106", "a start time past the PCAP's 32-bit unsigned seconds", "start_time",
         "the run (duration_s 300 s from 2106-02-08T00:00:00Z) ends after 2038-01-19T03:14:07Z",
         text_case(edit(("start_time: '2017-06-01T12:00:00Z'", "start_time: '2106-02-08T00:00:00Z'")))),
    Case("end_after_2038", "a run that ends past the ROS 2 bag's signed 32-bit seconds", "start_time",
         "the run (duration_s 300 s from 2038-01-19T03:10:00Z) ends after 2038-01-19T03:14:07Z",
         text_case(edit(("start_time: '2017-06-01T12:00:00Z'", "start_time: '2038-01-19T03:10:00Z'")))),
    Case("radius_1e-300", "radius_m: 1.0e-300, zero in float32", "obstacles[0].radius_m",
         "1e-300 is below 1.175e-38, the smallest normal float32",
         text_case(edit(("  radius_m: 15.0\n", "  radius_m: 1.0e-300\n")))),
    Case("deep_flow_20000", "20,000 nested flow sequences", "line 2, column #",
         "not valid YAML: exceeded maximum nesting depth", text_case(deep_flow(20_000))),
    Case("mesh_symlink_loop", "a mesh path that is a symlink loop", "obstacles[14].mesh",
         "symlink loop: loop.glb leads back to itself",
         special_case(mesh_obstacle("{special}"), "loop.glb", "loop"), generated=True),
    # --- the hangs and silent acceptances
    Case("million_aliases", "a million obstacles that are YAML aliases of one mapping", "line #",
         "more than 10,000 alias uses", text_case(million_aliases), generated=True),
    Case("buoys_30000", "30,000 distinct buoys", "line #", "more than 100,000 YAML nodes",
         text_case(lambda: buoys(30_000)), generated=True),
    Case("duration_given_twice", "duration_s given twice, the second 99999",
         f"line {line_of(_DUP_DURATION, 'duration_s', 2)}",
         f"key 'duration_s' given twice (first at line {line_of(_DUP_DURATION, 'duration_s')})",
         text_case(_DUP_DURATION)),
    Case("key_given_twice_nested", "own_ship.length_m given twice", f"line {line_of(_DUP_LENGTH, 'length_m', 2)}",
         f"key 'length_m' given twice (first at line {line_of(_DUP_LENGTH, 'length_m')})", text_case(_DUP_LENGTH)),
    Case("key_given_twice_flow", "a key given twice in a flow mapping",
         f"line {line_of(_DUP_FLOW, 'mmsi: 257000003')}, column 41", "key 'mmsi' given twice (first at column 24)",
         text_case(_DUP_FLOW)),
    Case("key_given_twice_list_item", "a ship's name given twice", f"line {line_of(_DUP_ITEM, 'name: tender')}",
         f"key 'name' given twice (first at line {line_of(_DUP_ITEM, 'name: support_vessel')})", text_case(_DUP_ITEM)),
    Case("key_given_twice_top_level", "obstacles given again at the end", f"line {line_of(_DUP_TOP, 'obstacles: []')}",
         f"key 'obstacles' given twice (first at line {line_of(_DUP_TOP, 'obstacles:')})", text_case(_DUP_TOP)),
    Case("csv_other_side_of_earth", "a trajectory CSV that jumps to the other side of the Earth in 10 s", "line 3",
         "lat, lon: moves 20,015 km in 10 s", with_files(csv_own_ship("{name}.csv"), {"{name}.csv": track(
             [(0.0, LAT0, LON0), (10.0, -LAT0, LON0 - 180.0), (400.0, -LAT0, LON0 - 180.0)])}),
         file="csv_other_side_of_earth.csv"),
    Case("scenario_fifo", "the scenario path is a FIFO", "(file)", "is a FIFO (named pipe), not a scenario file",
         special_case(None, "{name}.yaml", "fifo"), generated=True),
    # --- special files
    Case("scenario_symlink_loop", "the scenario path is a symlink loop", "(file)", "symlink loop",
         special_case(None, "{name}.yaml", "loop"), generated=True),
    Case("scenario_socket", "the scenario path is a socket", "(file)", "is a socket, not a scenario file",
         special_case(None, "s.yaml", "socket"), generated=True),
    Case("scenario_directory", "the scenario path is a directory", "(file)", "is a directory, not a scenario file",
         special_case(None, "{name}.yaml", "directory"), generated=True),
    Case("scenario_device", "the scenario path is /dev/null", "(file)", "is a device, not a scenario file",
         lambda folder, name: Path("/dev/null"), generated=True),
    Case("scenario_too_large", "a 17 MB scenario file", "(file)", "is 17 MB; a scenario file may be at most 16 MB",
         special_case(None, "{name}.yaml", "sparse"), generated=True),
    Case("scenario_missing", "the scenario file does not exist", "(file)", "file not found",
         lambda folder, name: folder / "no_such_scenario.yaml", generated=True),
    Case("mesh_fifo", "a mesh path that is a FIFO", "obstacles[14].mesh", "{dir}/pier.glb: is a FIFO",
         special_case(mesh_obstacle("{special}"), "pier.glb", "fifo"), generated=True),
    Case("mesh_broken_symlink", "a mesh path that is a symlink to nothing", "obstacles[14].mesh",
         "file not found: {dir}/nowhere.glb", special_case(mesh_obstacle("{special}"), "pier.glb", "broken"),
         generated=True),
    Case("mesh_device", "a mesh path that is /dev/zero", "obstacles[14].mesh", "/dev/zero: is a device, not a mesh file",
         text_case(mesh_obstacle("/dev/zero"))),
    Case("mesh_directory", "a mesh path that is a directory", "obstacles[14].mesh",
         "{dir}: is a directory, not a mesh file", text_case(mesh_obstacle("."))),
    Case("mesh_missing", "a mesh file that does not exist", "obstacles[14].mesh", "file not found: {dir}/pier_v2.glb",
         text_case(mesh_obstacle("pier_v2.glb"))),
    Case("mesh_garbage", "a mesh file that is no mesh", "obstacles[14].mesh", "{dir}/mesh_garbage.stl: ",
         with_files(mesh_obstacle("{name}.stl"), {"{name}.stl": b"\x00\x01 definitely not a mesh \xff" * 10})),
    Case("mesh_empty", "an empty mesh file", "obstacles[14].mesh", "{dir}/mesh_empty.stl: no triangles",
         with_files(mesh_obstacle("{name}.stl"), {"{name}.stl": b""})),
    Case("mesh_nan_vertex", "a mesh with a NaN vertex", "obstacles[14].mesh",
         "{dir}/mesh_nan_vertex.obj: mesh has non-finite", with_files(
             mesh_obstacle("{name}.obj"), {"{name}.obj": "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n"})),
    Case("csv_fifo", "a trajectory CSV that is a FIFO", "own_ship.trajectory_csv", "{dir}/track.csv: is a FIFO",
         special_case(csv_own_ship("{special}"), "track.csv", "fifo"), generated=True),
    Case("csv_directory", "a trajectory CSV path that is a directory", "own_ship.trajectory_csv",
         "{dir}: is a directory, not a trajectory CSV", text_case(csv_own_ship("."))),
    Case("csv_missing", "a trajectory CSV that does not exist", "own_ship.trajectory_csv",
         "file not found: {dir}/track.csv", text_case(csv_own_ship("track.csv"))),
    # --- YAML structure
    Case("billion_laughs", "nine levels of ten aliases each", "line 6", "more than 100,000 YAML nodes",
         text_case(billion_laughs())),
    Case("deep_block_150", "150 nested block mappings", "line 102", "nested deeper than 100 levels",
         text_case(deep_block(150))),
    Case("recursive_alias", "an alias inside the node it names", "line 1", "alias *a is used inside the node it names",
         text_case("obstacles: &a [*a]\n")),
    Case("undefined_alias", "an alias to no anchor", "line 28, column 13", "not valid YAML: found undefined alias",
         text_case(edit(("duration_s: 300.0", "duration_s: *long")))),
    Case("python_tag", "a tag that would construct a Python object", "line 26, column 7",
         "not valid YAML: could not determine a constructor",
         text_case(edit(("name: busy_open_sea", "name: !!python/object/apply:os.getcwd []")))),
    Case("unclosed_bracket", "a flow sequence left open", "line #, column #", "not valid YAML",
         text_case(edit(("    - [59.438762, 10.472885]\n", "    - [59.438762, 10.472885\n")))),
    Case("tab_indent", "a tab for indentation", "line 34, column 1", "not valid YAML",
         text_case(edit(("  sea_state: 4\n", "\tsea_state: 4\n")))),
    Case("timestamp_month_13", "an unquoted start time in month 13", "line 27, column 13",
         "not valid YAML: not a valid time '2017-13-01T12:00:00Z'",
         text_case(edit(("start_time: '2017-06-01T12:00:00Z'", "start_time: 2017-13-01T12:00:00Z")))),
    Case("timestamp_year_0", "an unquoted start time in year 0", "line 27, column 13",
         "not valid YAML: not a valid time '0000-06-01'",
         text_case(edit(("start_time: '2017-06-01T12:00:00Z'", "start_time: 0000-06-01")))),
    Case("empty_file", "an empty file", "(file)", "file is empty", text_case("")),
    Case("comments_only", "only comments", "(file)", "file holds no scenario", text_case("# nothing yet\n")),
    Case("top_level_list", "a list at the top", "(top level)", "must be a mapping", text_case("- busy_open_sea\n")),
    Case("not_utf8", "a Latin-1 byte in a name", "byte #", "not a UTF-8 text file",
         bytes_case(base_text().replace("name: odin", "name: \xd8din").encode("latin-1"))),
    # --- times, numbers and sizes
    Case("start_not_iso", "a start time in words", "start_time", "must be an ISO 8601 UTC time",
         text_case(edit(("start_time: '2017-06-01T12:00:00Z'", "start_time: yesterday")))),
    Case("start_number", "a start time given as a number", "start_time", "must be an ISO 8601 UTC time",
         text_case(edit(("start_time: '2017-06-01T12:00:00Z'", "start_time: 1496318400")))),
    Case("radius_1e-300_as_text", "radius_m: 1e-300, which YAML 1.1 reads as text", "obstacles[0].radius_m",
         "must be a number, got the string '1e-300' (YAML reads 1e-300 as text: write 1.0e-300)",
         text_case(edit(("  radius_m: 15.0\n", "  radius_m: 1e-300\n")))),
    Case("length_below_1cm", "own_ship.length_m of 10 micrometres", "own_ship.length_m", "must be at least 0.01 m",
         text_case(edit(("  length_m: 10.9\n", "  length_m: 1.09e-5\n")))),
    Case("height_below_1cm", "an iceberg 1 mm high", "obstacles[1].height_m", "must be at least 0.01 m",
         text_case(edit(("  radius_m: 15.0\n- name: Iceberg_3", "  radius_m: 15.0\n  height_m: 0.001\n- name: Iceberg_3")))),
    Case("radar_resolve_1cm", "radar rays 1 cm apart", "sensors.radar.resolve_m", "must be at least 0.5 m",
         text_case(edit(("    range_m: 1852.0\n", "    range_m: 1852.0\n    resolve_m: 0.01\n")))),
    Case("wind_subnormal", "a wind speed subnormal in float32", "environment.wind_speed_mps",
         "1e-40 is below 1.175e-38", text_case(edit(("wind_speed_mps: 10.0", "wind_speed_mps: 1.0e-40")))),
    Case("rain_control_beyond_float32", "a rain control beyond the largest float32",
         "sensors.radar.rain_clutter_control_m", "1e+39 is beyond 3.403e+38", text_case(edit(
             ("    range_m: 1852.0\n", "    range_m: 1852.0\n    rain_clutter_control_m: 1.0e+39\n")))),
    Case("duration_400_digits", "a duration of 400 digits", "duration_s",
         "must be a finite number, got an integer of 400 digits",
         text_case(edit(("duration_s: 300.0", "duration_s: 1" + "0" * 399)))),
    Case("duration_negative", "a negative duration", "duration_s", "must be > 0",
         text_case(edit(("duration_s: 300.0", "duration_s: -300")))),
    Case("duration_zero", "a zero duration", "duration_s", "must be > 0",
         text_case(edit(("duration_s: 300.0", "duration_s: 0")))),
    Case("duration_nan", "a NaN duration", "duration_s", "must be a finite number",
         text_case(edit(("duration_s: 300.0", "duration_s: .nan")))),
    Case("duration_words", "a duration in words", "duration_s", "must be a number, got the string 'five minutes'",
         text_case(edit(("duration_s: 300.0", "duration_s: five minutes")))),
    Case("duration_boolean", "a boolean duration", "duration_s", "must be a number, got a boolean",
         text_case(edit(("duration_s: 300.0", "duration_s: yes")))),
    Case("duration_two_days", "a duration over a day", "duration_s", "must be <= 86400",
         text_case(edit(("duration_s: 300.0", "duration_s: 172800")))),
    Case("wind_infinite", "an infinite wind", "environment.wind_speed_mps", "must be a finite number",
         text_case(edit(("wind_speed_mps: 10.0", "wind_speed_mps: .inf")))),
    Case("seed_negative", "a negative seed", "seed", "must be >= 0", text_case(edit(("seed: 7", "seed: -7")))),
    Case("seed_float", "a fractional seed", "seed", "must be an integer", text_case(edit(("seed: 7", "seed: 7.5")))),
    Case("sea_state_9", "a sea state off the Douglas scale", "environment.sea_state", "must be <= 6",
         text_case(edit(("sea_state: 4", "sea_state: 9")))),
    Case("heading_360", "a heading of 360", "obstacles[14].heading_deg", "must be < 360",
         text_case(with_obstacle("- name: Buoy_1\n  kind: buoy\n  position: [59.4379, 10.473]\n  heading_deg: 360\n"))),
    Case("radar_spokes_huge", "a million spokes", "sensors.radar.spokes", "must be <= 8192",
         text_case(edit(("    range_m: 1852.0\n", "    range_m: 1852.0\n    spokes: 1000000\n")))),
    # --- keys and structure of the scenario
    Case("unknown_top_key", "a misspelt top-level key", "durration_s", "unknown key",
         text_case(edit(("duration_s: 300.0", "durration_s: 300.0")))),
    Case("unknown_nested_key", "a misspelt sensor key", "sensors.lidar.range_max", "unknown key",
         text_case(edit(("    range_max_m: 100.0", "    range_max: 100.0")))),
    Case("environment_list", "environment as a list", "environment", "must be a mapping",
         text_case(edit(("environment:\n  sea_state: 4\n  wind_speed_mps: 10.0\n  wind_from_deg: 90.0\n",
                         "environment: [4, 10.0, 90.0]\n")))),
    Case("latitude_95", "a latitude past the pole", "obstacles[0].position", "latitude must be within [-90, 90]",
         text_case(edit(("  position: [59.436573, 10.470952]", "  position: [95.436573, 10.470952]")))),
    Case("lat_lon_swapped_far", "a waypoint 120 km away", "ships[1].waypoints[1]", "is 1",
         text_case(edit(("  - [59.432853, 10.460502]", "  - [60.532853, 10.460502]")))),
    Case("waypoint_not_pair", "a waypoint with one number", "own_ship.route.waypoints[1]", "must be a list of 2 items",
         text_case(edit(("    - [59.438762, 10.472885]\n", "    - [59.438762]\n")))),
    Case("waypoint_repeated", "a waypoint given twice in a row", "own_ship.route.waypoints", "waypoint 2 repeats",
         text_case(edit(("    - [59.437281, 10.477643]\n", "    - [59.438762, 10.472885]\n")))),
    Case("mmsi_8_digits", "an MMSI of 8 digits", "ships[0].ais.mmsi", "an MMSI has exactly 9 digits",
         text_case(edit(("    mmsi: 257000001", "    mmsi: 25700000")))),
    Case("mmsi_duplicate", "two ships with one MMSI", "ships[1].ais.mmsi", "MMSI 257000001 is already used",
         text_case(edit(("    mmsi: 257000002", "    mmsi: 257000001")))),
    Case("name_duplicate", "two obstacles with one name", "obstacles[1].name", "name 'Iceberg_1' is already used",
         text_case(edit(("- name: Iceberg_2\n", "- name: Iceberg_1\n")))),
    Case("own_ship_two_modes", "a route and a position", "own_ship", "give only one of route, trajectory_csv, position",
         text_case(edit(("  beam_m: 3.5\n", "  beam_m: 3.5\n  position: [59.4377, 10.4716]\n")))),
    Case("own_ship_no_mode", "no route, CSV or position", "own_ship", "needs a route, a trajectory_csv or a position",
         text_case(edit((ROUTE, "")))),
    Case("unknown_material", "an unknown material", "own_ship.material", "unknown material 'kryptonite'",
         text_case(edit(("  beam_m: 3.5\n", "  beam_m: 3.5\n  material: kryptonite\n")))),
    Case("lidar_model", "an unknown LiDAR model", "sensors.lidar.model", "must be one of 'HDL-32E'",
         text_case(edit(("    range_max_m: 100.0", "    model: VLP-16\n    range_max_m: 100.0")))),
    Case("anchored_with_speed", "one waypoint and a speed", "ships[1].speed_kn", "a ship with one waypoint is anchored",
         text_case(edit(("  - [59.438875, 10.483932]\n  - [59.432853, 10.460502]\n", "  - [59.438875, 10.483932]\n")))),
    Case("ais_name_charset", "an AIS name off the 6-bit set", "ships[0].ais.name", "characters",
         text_case(edit(("    mmsi: 257000001", "    mmsi: 257000001\n    name: ØDIN")))),
    # --- trajectory CSV content
    Case("csv_65_mps", "a trajectory step of 65 m/s", "line 5",
         "lat, lon: moves 648.7 m in 10 s (64.9 m/s) from line 4; a vessel does at most 60 m/s", with_files(
        csv_own_ship("{name}.csv"), {"{name}.csv": track(
            _NEAR_TRACK[:3] + [(30.0, _NEAR_TRACK[2][1] + 650.0 / 111_412.0, LON0)]
            + [(t, lat + 610.0 / 111_412.0, lon) for t, lat, lon in _NEAR_TRACK[4:]])}), file="csv_65_mps.csv"),
    Case("csv_far_from_origin", "a trajectory 67 km north of the origin", "line 2", "is 66.7 km from the origin", with_files(
        csv_own_ship("{name}.csv"), {"{name}.csv": track([(t, lat + 0.6, lon) for t, lat, lon in _NEAR_TRACK])}),
        file="csv_far_from_origin.csv"),
    Case("csv_roll_120", "a roll of 120 deg", "line 4", "roll_deg: must be within [-90, 90] deg", with_files(
        csv_own_ship("{name}.csv"), {"{name}.csv": track(
            [(t, lat, lon, 0.0, 120.0 if i == 2 else 1.0) for i, (t, lat, lon) in enumerate(_NEAR_TRACK)],
            "t_s,lat,lon,heading_deg,roll_deg")}), file="csv_roll_120.csv"),
    Case("csv_nan", "a NaN latitude", "line 3", "lat: must be finite", with_files(
        csv_own_ship("{name}.csv"), {"{name}.csv": track(_NEAR_TRACK).replace(repr(_NEAR_TRACK[1][1]), "nan", 1)}),
        file="csv_nan.csv"),
    Case("csv_time_backwards", "time going backwards", "line 4", "t_s must increase strictly", with_files(
        csv_own_ship("{name}.csv"), {"{name}.csv": track(
            _NEAR_TRACK[:2] + [(5.0, _NEAR_TRACK[2][1], LON0)] + _NEAR_TRACK[3:])}), file="csv_time_backwards.csv"),
    Case("csv_too_short", "a trajectory of 100 s for a 300 s scenario", "own_ship.trajectory_csv",
         "covers 0..100 s but duration_s is 300", with_files(
             csv_own_ship("{name}.csv"), {"{name}.csv": track(_NEAR_TRACK[:11])})),
    Case("csv_not_utf8", "a Latin-1 byte in a trajectory comment", "byte #", "not a UTF-8 text file", with_files(
        csv_own_ship("{name}.csv"), {"{name}.csv": b"# Tr\xf8ndelag\n" + track(_NEAR_TRACK).encode()}),
        file="csv_not_utf8.csv"),
    Case("csv_unknown_column", "a speed column", "line 1", "unknown column 'speed'", with_files(
        csv_own_ship("{name}.csv"), {"{name}.csv": track(
            [(t, lat, lon, 0.0, 4.0) for t, lat, lon in _NEAR_TRACK], "t_s,lat,lon,heading_deg,speed")}),
        file="csv_unknown_column.csv"),
    # --- scene size
    Case("buoys_1500", "1,500 buoys: more objects than a scene may hold", "obstacles", "1,517 objects",
         text_case(lambda: buoys(1_500)), generated=True),
]


def write_case(case: Case, folder: Path) -> Path:
    """Write ``case`` into ``folder``; the path to render."""
    return case.make(folder, case.name)


def expected_line(case: Case, folder: Path, scenario: Path) -> tuple[str, str, str]:
    """(file, place, what prefix) of the case's error, ``{dir}`` filled in (``#`` in place kept)."""
    directory = str(folder.resolve())
    file = str(scenario) if case.file is None else str(folder.resolve() / case.file)
    return file, case.place, case.what.replace("{dir}", directory)


def index() -> list[dict]:
    """The index of every case (committed and generated), as written to expected.json."""
    return [{"name": c.name, "description": c.description,
             "scenario": None if c.generated else f"{c.name}.yaml",
             "file": c.file, "place": c.place, "what": c.what, "exit_code": 2, "generated": c.generated}
            for c in CASES]


def main(argv: list[str] | None = None) -> int:
    """Rewrite the committed cases and expected.json (the folder is emptied first)."""
    CORPUS.mkdir(exist_ok=True)
    for old in CORPUS.iterdir():
        old.unlink()
    for case in CASES:
        if not case.generated:
            write_case(case, CORPUS)
    INDEX.write_text(json.dumps(index(), indent=1, ensure_ascii=False) + "\n", encoding="utf-8")
    print(f"wrote {sum(not c.generated for c in CASES)} cases and {INDEX.name} into {CORPUS} "
          f"({sum(c.generated for c in CASES)} more are made at test time)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

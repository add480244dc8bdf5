"""What ``raysim run`` / ``raysim render`` leave and say: same seed, same bytes; progress lines
without a terminal; the closing summary; the pictures' labels."""

from __future__ import annotations

import contextlib
import io
import json
import re
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from raysim.cli import _bytes_text, main
from tests.conftest import REPO

BUSY = REPO / "scenarios" / "busy_open_sea.yaml"
#: the manifest's wall-clock values: the only bytes two runs of one seed may differ in
WALL_CLOCK_KEYS = ("wall_time_s",)
#: stages of `raysim run` on busy_open_sea, in order (every sensor of the scenario is on)
#: In the order they start (a run this short has no second processes: raysim.second_process.MIN_SCENARIO_S).
RUN_STAGES = ("world", "truth", "ownship", "lidar", "radar", "ais", "nav", "tdm run", "tdm evaluate",
              "rosbag", "pictures")


def _main(argv: list[str]) -> tuple[int, str, str]:
    """Run ``raysim`` with stdout and stderr captured (stderr is then not a terminal)."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(argv)
    return code, out.getvalue(), err.getvalue()


@pytest.fixture(scope="module")
def two_runs(tmp_path_factory) -> dict:
    """Two `raysim run`s of busy_open_sea, 6 s, seed 7, into two directories (the second --no-progress)."""
    base = tmp_path_factory.mktemp("two_runs")
    runs = {}
    for name, extra in (("a", []), ("b", ["--no-progress"])):
        code, out, err = _main(["run", str(BUSY), "-o", str(base / name), "--duration", "6", "--seed", "7", *extra])
        assert code == 0, err
        runs[name] = {"dir": base / name, "out": out, "err": err}
    return runs


def _files(root: Path) -> dict[str, Path]:
    return {p.relative_to(root).as_posix(): p for p in sorted(root.rglob("*")) if p.is_file()}


def test_same_seed_same_bytes(two_runs):
    a, b = (_files(two_runs[k]["dir"]) for k in ("a", "b"))
    assert sorted(a) == sorted(b)
    assert {"rosbag/metadata.yaml", "tdm/tracks.png", "tdm/errors.png", "map.png", "radar/ppi/000000.png",
            "lidar/bev/000000.png"} <= set(a)
    differ = [name for name in a if name != "manifest.json" and a[name].read_bytes() != b[name].read_bytes()]
    assert differ == []
    ma, mb = (json.loads(files["manifest.json"].read_text()) for files in (a, b))
    for key in WALL_CLOCK_KEYS:
        ma.pop(key), mb.pop(key)
    assert ma == mb


def test_plots_are_titled_by_scenario_and_seed_not_the_staging_directory(two_runs):
    from tdm.plots import recording_title

    assert recording_title(two_runs["a"]["dir"]) == "busy_open_sea (seed 7)"
    for name in ("tracks.png", "errors.png"):  # matplotlib writes no Software or date chunk
        data = (two_runs["a"]["dir"] / "tdm" / name).read_bytes()
        assert b"partial" not in data and b"Software" not in data and b"matplotlib" not in data.lower()


def test_every_stage_of_a_run_says_when_it_starts_and_ends(two_runs):
    lines = two_runs["a"]["err"].splitlines()
    for stage in RUN_STAGES:
        mine = [line for line in lines if line.startswith(f"raysim: {stage}: ")]
        assert len(mine) == 2 and mine[0].endswith(" ...") and re.search(r" done in \d+\.\d s$", mine[1]), (stage, mine)
    starts = [line.split(": ")[1] for line in lines if line.endswith(" ...")]
    assert starts == list(RUN_STAGES)
    assert two_runs["b"]["err"] == ""  # --no-progress: silent


def test_the_summary_names_what_the_time_covers_the_bytes_and_where_to_look(two_runs):
    run = two_runs["a"]
    lines = run["out"].splitlines()
    manifest = json.loads((run["dir"] / "manifest.json").read_text())
    wall = manifest["wall_time_s"]
    head = re.fullmatch(r"rendered, detected and evaluated busy_open_sea \(6 s, seed 7\) into (.+) in ([\d.]+) s "
                        r"\(render ([\d.]+) s, tdm ([\d.]+) s, bag ([\d.]+) s, pictures ([\d.]+) s"
                        r"(; the bag beside the evaluation and the pictures)?\); (.+) written", lines[0])
    assert head, lines[0]
    assert Path(head[1]) == run["dir"] and float(head[2]) == pytest.approx(wall["total"], abs=0.051)
    for k, key in ((3, "render"), (4, "tdm"), (5, "rosbag"), (6, "pictures")):
        assert float(head[k]) == pytest.approx(wall[key], abs=0.051)
    parts = sum(float(head[k]) for k in (3, 4, 5, 6))
    if head[7]:  # side by side: the parts take longer than the whole
        assert parts > wall["total"]
    else:
        assert parts == pytest.approx(wall["total"], abs=0.21)
    written = sum(p.stat().st_size for p in run["dir"].rglob("*") if p.is_file())
    assert head[8] == _bytes_text(written) and head[8].endswith(" MB")
    assert lines[1].startswith("  ") and "lidar/sweeps: 59" in lines[1]
    rest = "\n".join(lines[2:5])
    assert f"{run['dir'] / 'rosbag'}" in rest and "Foxglove" in rest and "foxglove_layout.json" in rest
    for picture in ("map.png", "radar/ppi/", "lidar/bev/", "tdm/tracks.png", "tdm/errors.png"):
        assert str(run["dir"] / picture.rstrip("/")) in rest, picture
    assert "docs/formats.md" in rest
    assert "OSPA" in run["out"]  # the metrics table follows


@pytest.mark.parametrize("n_bytes, text", [(0, "0 B"), (999, "999 B"), (1500, "1.5 kB"), (65_400_000, "65 MB"),
                                           (4_400_000_000, "4.4 GB")])
def test_bytes_are_written_in_decimal_units(n_bytes, text):
    assert _bytes_text(n_bytes) == text


def test_render_prints_a_line_per_stage_and_a_render_only_summary(tmp_path, capfd):
    out = tmp_path / "rec"
    assert main(["render", str(BUSY), "-o", str(out), "--duration", "2", "--sensors", "lidar,ais,nav",
                 "--formats", "pcd"]) == 0
    printed = capfd.readouterr()
    for stage in ("world", "truth", "ownship", "lidar", "ais", "nav", "rosbag", "pictures", "pointclouds"):
        assert re.search(rf"^raysim: {stage}: .* \.\.\.$", printed.err, re.M), stage
        assert re.search(rf"^raysim: {stage}: .*done in \d+\.\d s$", printed.err, re.M), stage
    assert "raysim: lidar: 20 revolutions of the HDL-32E ..." in printed.err
    assert "tdm" not in printed.err
    first = printed.out.splitlines()[0]
    assert re.fullmatch(r"rendered busy_open_sea \(2 s, seed 7\) into .+ in [\d.]+ s \(render [\d.]+ s, bag [\d.]+ s, "
                        r"pictures [\d.]+ s, point clouds [\d.]+ s\); .+ written", first), first
    assert "radar/ppi" not in printed.out  # no radar, no PPIs to point at


def test_the_pictures_carry_their_labels(two_runs):
    run = two_runs["a"]["dir"]
    ppi = np.asarray(Image.open(run / "radar" / "ppi" / "000001.png").convert("RGB"))
    bev = np.asarray(Image.open(run / "lidar" / "bev" / "000000.png").convert("RGB"))
    world_map = np.asarray(Image.open(run / "map.png").convert("RGB"))
    assert ppi.shape == (800, 800, 3) and bev.shape == (800, 800, 3) and world_map.shape == (1000, 1000, 3)
    # the PPI's four corners lie outside the display circle: only the labels are drawn there
    for rows, cols in ((slice(0, 40), slice(0, 120)), (slice(0, 40), slice(620, 800)),
                       (slice(760, 800), slice(0, 160)), (slice(750, 800), slice(680, 800))):
        assert (ppi[rows, cols].sum(axis=-1) > 200).sum() > 50, (rows, cols)
    from raysim.recording.bev import BOX_COLOUR, KEY_FILL

    key = bev[734:794, 604:794]
    assert (np.all(key == KEY_FILL, axis=-1)).mean() > 0.5 and np.all(key == BOX_COLOUR, axis=-1).sum() > 40
    assert (bev[:40, :300].sum(axis=-1) > 300).sum() > 100  # the time, top left
    from raysim.recording.map_picture import KEY_FILL as MAP_KEY

    assert np.all(world_map[10:100, 670:990] == MAP_KEY, axis=-1).mean() > 0.5  # the key, top right

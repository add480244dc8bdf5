"""raysim.second_process: the LiDAR rendered in a second process gives the same recording, and its failures
reach the parent."""

from __future__ import annotations

import copy
import hashlib
import os
import time

import pytest

from raysim import render as render_module
from raysim.scenario import load_scenario, with_overrides
from raysim import second_process
from tests.conftest import BASE, REPO

pytestmark = pytest.mark.skipif(not second_process.can_start(1e9), reason="this process may not have children")


@pytest.fixture(autouse=True)
def short_renders_too(monkeypatch):
    """Second processes for these short test scenarios as well (a render asks for 30 s or more)."""
    monkeypatch.setattr(second_process, "MIN_SCENARIO_S", 0.0)


def _digests(root) -> dict[str, str]:
    return {str(p.relative_to(root)): hashlib.md5(p.read_bytes()).hexdigest()
            for p in sorted(root.rglob("*")) if p.is_file() and p.name != "manifest.json"}


def test_a_second_process_for_the_lidar_makes_the_same_recording(tmp_path):
    scenario = with_overrides(load_scenario(REPO / "scenarios" / "near_shore.yaml"), duration_s=2.6)
    one = render_module.render(scenario, tmp_path / "one", progress=False, derived=False)
    two = render_module.render(scenario, tmp_path / "two", progress=False, derived=False, processes=2)
    digests = _digests(tmp_path / "one")
    assert any(k.startswith("lidar/") for k in digests) and any(k.startswith("radar/") for k in digests)
    assert digests == _digests(tmp_path / "two")
    a, b = one.manifest, two.manifest
    assert list(a.pop("wall_time_s")) == list(b.pop("wall_time_s"))  # the same stages, in the same order
    assert a == b


def test_the_bag_written_beside_the_evaluation_is_the_same_bag(tmp_path, capsys):
    """The derived files with the bag in a second process while ``beside_derived`` runs: the same bytes; the
    stages in a second process say so, start when it starts and end when its files are there."""
    scenario = with_overrides(load_scenario(REPO / "scenarios" / "busy_open_sea.yaml"), duration_s=2.6)
    calls = []
    one = render_module.render(scenario, tmp_path / "one", progress=False)
    capsys.readouterr()
    two = render_module.render(scenario, tmp_path / "two", progress=None, processes=2,
                               beside_derived=lambda staged: calls.append(sorted(p.name for p in staged.iterdir())))
    lines = [line for line in capsys.readouterr().err.splitlines() if line.startswith("raysim: ")]
    starts = [line.split(": ")[1] for line in lines if line.endswith(" ...")]
    assert starts.index("lidar") < starts.index("radar") and starts[-2:] == ["rosbag", "pictures"]
    assert "raysim: lidar: 26 revolutions of the HDL-32E, in a second process ..." in lines
    assert any(line.startswith("raysim: rosbag: ") and " messages ... done in " in line for line in lines)
    assert lines.index("raysim: rosbag: ROS 2 bag (MCAP), in a second process ...") < len(lines) - 1
    digests = _digests(tmp_path / "one")
    assert any(k.startswith("rosbag/") for k in digests) and digests == _digests(tmp_path / "two")
    assert len(calls) == 1
    assert list(one.manifest["wall_time_s"]) == [k for k in two.manifest["wall_time_s"] if k != "tdm"]
    assert two.manifest["counts"] == one.manifest["counts"]


def _broken_bag(ctx):
    raise OSError("no space left for the bag")


def test_an_error_writing_the_bag_in_the_second_process_leaves_nothing(write_scenario, tmp_path, monkeypatch):
    monkeypatch.setattr(render_module, "write_bag", _broken_bag)
    with pytest.raises(OSError, match="no space left"):
        render_module.render(load_scenario(write_scenario(BASE)), tmp_path / "rec", progress=False, processes=2)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scenario.yaml"]


def _lidar_scenario(write_scenario):
    data = copy.deepcopy(BASE)
    data["sensors"]["lidar"]["enabled"] = True
    return load_scenario(write_scenario(data))


# renderers for the child, module-level: the spawned child gets them by name


def _broken(ctx):
    (ctx.out_dir / "lidar").mkdir()
    (ctx.out_dir / "lidar" / "half.npz").write_bytes(b"half")
    raise ValueError("sensor crashed in the child")


def _dies(ctx):
    os._exit(3)


def _slow(ctx):
    time.sleep(2.0)
    (ctx.out_dir.parent.parent / "child_finished").write_text("done")


def _broken_ais(ctx):
    raise RuntimeError("the parent's sensor crashed")


def test_an_error_in_the_second_process_is_raised_and_leaves_nothing(write_scenario, tmp_path, monkeypatch):
    monkeypatch.setitem(render_module.SENSOR_RENDERERS, "lidar", _broken)
    with pytest.raises(ValueError, match="crashed in the child"):
        render_module.render(_lidar_scenario(write_scenario), tmp_path / "rec", progress=False, processes=2)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scenario.yaml"]


def test_a_second_process_that_dies_is_an_error(write_scenario, tmp_path, monkeypatch):
    monkeypatch.setitem(render_module.SENSOR_RENDERERS, "lidar", _dies)
    with pytest.raises(RuntimeError, match="exit code 3"):
        render_module.render(_lidar_scenario(write_scenario), tmp_path / "rec", progress=False, processes=2)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scenario.yaml"]


def test_the_parents_failure_stops_the_second_process(write_scenario, tmp_path, monkeypatch):
    monkeypatch.setitem(render_module.SENSOR_RENDERERS, "lidar", _slow)
    monkeypatch.setitem(render_module.SENSOR_RENDERERS, "ais", _broken_ais)
    out = tmp_path / "runs" / "rec"
    out.parent.mkdir()
    with pytest.raises(RuntimeError, match="parent's sensor"):
        render_module.render(_lidar_scenario(write_scenario), out, progress=False, processes=2)
    time.sleep(6.0)  # an unstopped child would have written by now: its start (1-3 s) and its 2 s
    assert not (tmp_path / "child_finished").exists()
    assert list(out.parent.iterdir()) == []

"""raysim.sensor_process: the LiDAR rendered in a second process gives the same recording, and its failures
reach the parent."""

from __future__ import annotations

import copy
import hashlib
import os
import time

import pytest

from raysim import render as render_module
from raysim.scenario import load_scenario, with_overrides
from raysim.sensor_process import can_start
from tests.conftest import BASE, REPO

pytestmark = pytest.mark.skipif(not can_start(), reason="this process may not have children")


def _digests(root) -> dict[str, str]:
    return {str(p.relative_to(root)): hashlib.md5(p.read_bytes()).hexdigest()
            for p in sorted(root.rglob("*")) if p.is_file() and p.name != "manifest.json"}


def test_a_second_process_for_the_lidar_makes_the_same_recording(tmp_path):
    scenario = with_overrides(load_scenario(REPO / "scenarios" / "near_shore.yaml"), duration_s=2.6)
    one = render_module.render(scenario, tmp_path / "one", progress=False, derived=False)
    two = render_module.render(scenario, tmp_path / "two", progress=False, derived=False, sensor_processes=2)
    digests = _digests(tmp_path / "one")
    assert any(k.startswith("lidar/") for k in digests) and any(k.startswith("radar/") for k in digests)
    assert digests == _digests(tmp_path / "two")
    a, b = one.manifest, two.manifest
    assert list(a.pop("wall_time_s")) == list(b.pop("wall_time_s"))  # the same stages, in the same order
    assert a == b


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
    time.sleep(8.0)
    (ctx.out_dir.parent.parent / "child_finished").write_text("done")


def _broken_ais(ctx):
    raise RuntimeError("the parent's sensor crashed")


def test_an_error_in_the_second_process_is_raised_and_leaves_nothing(write_scenario, tmp_path, monkeypatch):
    monkeypatch.setitem(render_module.SENSOR_RENDERERS, "lidar", _broken)
    with pytest.raises(ValueError, match="crashed in the child"):
        render_module.render(_lidar_scenario(write_scenario), tmp_path / "rec", progress=False, sensor_processes=2)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scenario.yaml"]


def test_a_second_process_that_dies_is_an_error(write_scenario, tmp_path, monkeypatch):
    monkeypatch.setitem(render_module.SENSOR_RENDERERS, "lidar", _dies)
    with pytest.raises(RuntimeError, match="exit code 3"):
        render_module.render(_lidar_scenario(write_scenario), tmp_path / "rec", progress=False, sensor_processes=2)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scenario.yaml"]


def test_the_parents_failure_stops_the_second_process(write_scenario, tmp_path, monkeypatch):
    monkeypatch.setitem(render_module.SENSOR_RENDERERS, "lidar", _slow)
    monkeypatch.setitem(render_module.SENSOR_RENDERERS, "ais", _broken_ais)
    out = tmp_path / "runs" / "rec"
    out.parent.mkdir()
    with pytest.raises(RuntimeError, match="parent's sensor"):
        render_module.render(_lidar_scenario(write_scenario), out, progress=False, sensor_processes=2)
    time.sleep(10.0)
    assert not (tmp_path / "child_finished").exists()
    assert list(out.parent.iterdir()) == []

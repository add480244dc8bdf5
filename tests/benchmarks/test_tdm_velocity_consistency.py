"""benchmarks/tdm_velocity_consistency.py: velocity NEES per sensor as the fusion weighs it, on a rendered
recording (busy_open_sea, 40 s)."""

from __future__ import annotations

import importlib.util
import math

from tests.conftest import REPO


def _benchmark_module():
    """benchmarks/tdm_velocity_consistency.py loaded by path (benchmarks/ is a folder of scripts, not a package)."""
    spec = importlib.util.spec_from_file_location("bench_velocity", REPO / "benchmarks" / "tdm_velocity_consistency.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_velocity_nees_per_sensor_on_a_rendered_recording(bos_recording, tmp_path):
    bench = _benchmark_module()
    apart = bench.velocity_nees(bos_recording)
    whole = bench.velocity_nees(bos_recording, whole=True)
    # the AIS tracker's velocity is Gaussian in course and speed about the GNSS truth: its NEES is of the order of
    # its ideal, 2 (a wrong frame or a wrong truth match would put it in the hundreds)
    assert 0.1 < apart["ais"]["nees_mean"] < 6.0
    assert apart["fused"]["rms_error_mps"] < 1.0 and apart["fused"]["n"] > 100
    # the tracks are the same whichever way the fusion takes them; only the fused velocity differs
    for sensor in ("ais", "lidar", "radar"):
        if sensor in apart:
            assert apart[sensor] == whole[sensor]
    assert apart["fused"] != whole["fused"]
    assert all(math.isfinite(v) for m in apart.values() for v in m.values())
    # still and moving objects split each sensor's states; under, in and over the interval split them again
    for sensor in ("ais", "lidar", "radar", "fused"):
        if sensor in apart:
            parts = [apart[k]["n"] for k in (f"{sensor}, still objects", f"{sensor}, moving objects") if k in apart]
            assert sum(parts) == apart[sensor]["n"]
            m = apart[sensor]
            assert math.isclose(m["under_95"] + m["in_95"] + m["over_95"], 1.0)
    assert "fused, still objects" in apart and "fused, moving objects" in apart  # busy_open_sea: bergs and ships
    out = tmp_path / "page.md"
    assert bench.main([str(bos_recording), "--out", str(out)]) == 0
    assert "| rec | fused |" in out.read_text()

"""benchmarks/ray_engine.py: its measurements run, its report and command line (tiny real measurements)."""

from __future__ import annotations

import pytest


def _ray_engine_bench():
    """benchmarks/ray_engine.py loaded by path (benchmarks/ is a folder of scripts, not a package)."""
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[2] / "benchmarks" / "ray_engine.py"
    spec = importlib.util.spec_from_file_location("bench_ray_engine", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.bench
def test_benchmark_functions_run():
    benchmarking = _ray_engine_bench()

    st = benchmarking.bench_static(n_firings=200, reps=1, with_embreex=True)
    assert st["rays"] == 6400 and st["raw_o3d_rays_per_s"] > 0 and st["fraction_of_raw"] > 0
    rows = benchmarking.bench_moving(counts=(1, 3), n_firings=200, reps=1)
    assert [r["moving_objects"] for r in rows] == [1, 3]


def test_benchmark_report_and_main(tmp_path, monkeypatch, capsys):
    """The report formatter and ``run`` of benchmarks/ray_engine.py on a tiny real measurement (fast, not a benchmark)."""
    import json

    benchmarking = _ray_engine_bench()

    rows = benchmarking.bench_moving(counts=(1, 2), n_firings=40, reps=1)
    res = {
        "machine": benchmarking.machine_info(),
        "quick": True,
        "moving_one_revolution": rows,
        "own_ship": {"rays": 1280, "own_ship_hit_fraction": 0.07, "ns_per_ray_without": 25.0,
                     "ns_per_ray_with": 200.0, "ns_per_ray_with_carrier": 40.0},
    }
    figures = benchmarking.key_figures(res)
    assert figures["own ship: ns/ray with it, CarrierScene"] == 40.0 and len(figures) == 4
    text = benchmarking.to_markdown(dict(res, runs=[figures, figures]))
    assert "| 2 | " in text and "| with own ship, `CarrierScene.cast(...)`" in text
    assert "| figure | run 1 | run 2 | median |" in text and "| 40.00 | 40.00 | 40.00 |" in text
    monkeypatch.setattr(benchmarking, "run_all", lambda quick=False: res)
    out, js = tmp_path / "r" / "ray_engine.md", tmp_path / "r.json"
    assert benchmarking.run(quick=True, json_path=js, out_path=out, runs=2) == 0
    assert capsys.readouterr().out == out.read_text(encoding="utf-8") + "\n"  # printed and written
    assert json.loads(js.read_text())["runs"] == [figures, figures]
    assert not list(tmp_path.rglob("*.tmp"))

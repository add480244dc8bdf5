"""raysim batch: Monte-Carlo runs on a Dask LocalCluster (issue 8)."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest
import yaml

from raysim.cli import main
from tests.raysim.helpers import BATCH_SEEDS, tiny_scenario

SEEDS = BATCH_SEEDS


def summary(batch: Path) -> list[dict]:
    with open(batch / "summary.csv", newline="", encoding="utf-8") as f:
        return list(csv.DictReader(f))


@pytest.fixture(scope="module")
def batch(tmp_path_factory):
    """Two sea states x two seeds on a LocalCluster of 2 workers."""
    folder = tmp_path_factory.mktemp("batch")
    scenario = tiny_scenario(folder / "scenario")
    out = folder / "out"
    argv = ["batch", str(scenario), "-o", str(out), "--seeds", "2", "--vary", "environment.sea_state=1,3",
            "--workers", "2", "--no-progress"]
    assert main(argv) == 0
    return scenario, out, argv


def test_every_run_has_its_recording_and_one_summary_row(batch):
    _, out, _ = batch
    rows = summary(out)
    assert len(rows) == 4 and all(r["status"] == "ok" for r in rows)
    assert {(r["environment.sea_state"], int(r["seed"])) for r in rows} == {(s, k) for s in ("1", "3") for k in SEEDS}
    for row in rows:
        rec = out / "runs" / row["run"]
        manifest = json.loads((rec / "manifest.json").read_text())
        assert manifest["seed"] == int(row["seed"])
        resolved = yaml.safe_load((rec / "scenario.yaml").read_text())
        assert str(resolved["environment"]["sea_state"]) == row["environment.sea_state"]
        metrics = json.loads((rec / "tdm" / "metrics.json").read_text())
        assert float(row["gospa_m"]) == pytest.approx(metrics["gospa_m"], rel=1e-5)
        assert (rec / "tdm" / "detected_targets.jsonl").stat().st_size > 0
    assert (out / "summary.png").stat().st_size > 10_000
    assert sorted(p.name for p in (out / "results").iterdir()) == sorted(f"{r['run']}.json" for r in rows)


def test_seeds_give_distinct_results_and_a_run_is_the_same_as_raysim_run(batch, tmp_path):
    scenario, out, _ = batch
    rows = {(r["environment.sea_state"], int(r["seed"])): r for r in summary(out)}
    for sea_state in ("1", "3"):
        a, b = rows[(sea_state, SEEDS[0])], rows[(sea_state, SEEDS[1])]
        assert a["gospa_m"] != b["gospa_m"] or a["position_rmse_m"] != b["position_rmse_m"]
        own = [(out / "runs" / r["run"] / "ownship.jsonl").read_bytes() for r in (a, b)]
        assert own[0] != own[1]  # navigation noise drawn from different seeds
    # the batch's run of (sea state 1, seed 12) is byte for byte `raysim run --seed 12`
    single = tmp_path / "single"
    assert main(["run", str(scenario), "-o", str(single), "--seed", str(SEEDS[1]), "--no-progress"]) == 0
    ran = out / "runs" / rows[("1", SEEDS[1])]["run"]
    for rel in ("ownship.jsonl", "ais/ais.nmea", "radar/sweeps/000000.npz", "lidar/hdl32e.pcap",
                "tdm/detected_targets.jsonl"):
        assert (ran / rel).read_bytes() == (single / rel).read_bytes(), rel


def test_a_second_run_of_the_batch_skips_the_finished_runs(batch, capsys):
    _, out, argv = batch
    before = {p: p.stat().st_mtime_ns for p in (out / "runs").glob("*/manifest.json")}
    rows_before = summary(out)
    argv = [a for a in argv if a != "--no-progress"]
    assert main(argv) == 0
    assert "4 finished before (skipped)" in capsys.readouterr().err
    assert {p: p.stat().st_mtime_ns for p in (out / "runs").glob("*/manifest.json")} == before
    assert summary(out) == rows_before


def test_a_failing_variant_is_recorded_and_the_batch_goes_on(tmp_path, capsys):
    from distributed import LocalCluster

    scenario = tiny_scenario(tmp_path / "scenario")
    out = tmp_path / "out"
    argv = ["batch", str(scenario), "-o", str(out), "--vary", "obstacles.1.mesh=buoy.stl,broken.obj"]
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        argv += ["--scheduler", cluster.scheduler_address]
        assert main(argv) == 1  # a run failed
        rows = {r["obstacles.1.mesh"]: r for r in summary(out)}
        assert rows["buoy.stl"]["status"] == "ok" and rows["buoy.stl"]["error"] == ""
        failed = rows["broken.obj"]
        assert failed["status"] == "failed" and "no triangles" in failed["error"] and failed["gospa_m"] == ""
        assert "\n" not in failed["error"]
        assert not (out / "runs" / failed["run"]).exists()  # nothing partial
        assert "Traceback" in (out / "results" / f"{failed['run']}.log").read_text()
        assert (out / "runs" / rows["buoy.stl"]["run"] / "manifest.json").is_file()
        captured = capsys.readouterr()
        assert f"failed: {failed['run']}" in captured.out
        # again: the finished run is skipped, the failed one tried again (and fails again); what an
        # interrupted batch left half-written of it goes
        stale = out / "runs" / f".{failed['run']}.partial-99999"
        (stale / "lidar").mkdir(parents=True)
        assert main(argv) == 1
        assert not stale.exists()
        assert "1 finished before (skipped), 1 to run" in capsys.readouterr().err
    assert [r["status"] for r in summary(out)] == ["ok", "failed"]


@pytest.mark.parametrize("extra, expect", [
    (["--vary", "environment.sea_stat=1,2"], "environment.sea_stat: unknown key"),
    (["--vary", "environment.sea_state=2,9"], "environment.sea_state"),
    (["--vary", "seed=1,2"], "--vary: seeds are set with --seeds"),
    (["--vary", "environment.sea_state"], "--vary: expected key=value1,value2"),
    (["--seeds", "0"], "--seeds: must be >= 1"),
    (["--scheduler", "tcp://127.0.0.1:9"], "--scheduler: cannot connect"),
])
def test_bad_batches_give_one_line_and_exit_2_with_nothing_on_disk(tmp_path, capsys, monkeypatch, extra, expect):
    import raysim.batch

    monkeypatch.setattr(raysim.batch, "SCHEDULER_TIMEOUT_S", 1.0)  # nothing listens on port 9: no need to wait 10 s
    scenario = tiny_scenario(tmp_path / "scenario")
    out = tmp_path / "out"
    assert main(["batch", str(scenario), "-o", str(out), *extra]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and err.count("\n") == 1 and expect in err, err
    assert not out.exists()


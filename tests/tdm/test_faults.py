"""tdm under faults: a full disk, SIGTERM, the staging directories of killed runs (issue 17).

``tdm run`` and ``tdm evaluate`` write into ``.DIR.partial-PID/DIR/`` and move their files into
``DIR`` together (tdm.staging): a fault leaves ``DIR`` as it was, one line on stderr.
"""

from __future__ import annotations

import os
import shutil
import signal

import pytest

from tdm.cli import main
from tests.faults import dead_pid, left_in, small_disk
from tests.tdm.conftest import REPO, render_recording


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    """busy_open_sea's first 10 s, AIS and navigation only (about 0.8 MB), without tdm/."""
    return render_recording(REPO / "scenarios" / "busy_open_sea.yaml", tmp_path_factory.mktemp("faults") / "rec",
                            10.0, sensors=("ais", "nav"))


def snapshot(folder):
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir())}


def test_a_full_disk_during_tdm_run_gives_one_line_exit_2_and_leaves_nothing(recording, tmp_path):
    with small_disk(tmp_path / "disk", 1_000_000) as disk:
        disk.fill()
        out = disk.path / "tdm"
        done = disk.run("tdm.cli", ["run", str(recording), "-o", str(out), "--workers", "0"])
        assert done.returncode == 2, done.stderr
        assert done.stderr.splitlines() == [f"error: {out}: writing: {disk.what}"] and done.stdout == ""
        assert left_in(disk.path) == []  # no tdm/, no .tdm.partial-PID


def test_a_full_disk_during_tdm_evaluate_leaves_the_earlier_outputs_as_they_were(recording, tmp_path):
    with small_disk(tmp_path / "disk", 2_000_000) as disk:
        rec = disk.path / "rec"
        shutil.copytree(recording, rec)
        assert main(["run", str(rec), "--workers", "0"]) == 0
        before = snapshot(rec / "tdm")
        assert sorted(before) == ["detected_targets.jsonl", "sensor_tracks.jsonl"]
        disk.fill()
        done = disk.run("tdm.cli", ["evaluate", str(rec)])
        assert done.returncode == 2, done.stderr
        assert done.stderr.splitlines() == [f"error: {rec / 'tdm'}: writing: {disk.what}"] and done.stdout == ""
        assert snapshot(rec / "tdm") == before  # no metrics.json, no plots, the run's files untouched
        assert not [p for p in left_in(rec) if ".partial-" in p]


def test_sigterm_during_tdm_run_removes_its_staging_and_exits_143(recording, tmp_path, monkeypatch, capsys):
    """The signal really arrives (os.kill of this process) once the files are written, before they move."""
    import tdm.pipeline

    real = tdm.pipeline.run_tdm
    staged = []

    def run_then_terminated(rec, out_dir, config, progress=False):
        result = real(rec, out_dir, config, progress=progress)
        staged.extend(sorted(p.name for p in out_dir.iterdir()))
        os.kill(os.getpid(), signal.SIGTERM)
        raise AssertionError("SIGTERM did not stop the command")

    monkeypatch.setattr(tdm.pipeline, "run_tdm", run_then_terminated)
    rec = tmp_path / "rec"
    shutil.copytree(recording, rec)
    previous = signal.getsignal(signal.SIGTERM)
    assert main(["run", str(rec), "--workers", "0"]) == 143
    assert signal.getsignal(signal.SIGTERM) == previous  # the handler is the command's only
    captured = capsys.readouterr()
    assert captured.err.splitlines() == ["error: terminated; nothing was written"] and captured.out == ""
    assert staged == ["detected_targets.jsonl", "sensor_tracks.jsonl"]
    assert sorted(p.name for p in rec.iterdir()) == sorted(p.name for p in recording.iterdir())  # no tdm/, no staging


def test_tdm_run_removes_the_staging_of_a_killed_run_and_writes_its_files_together(recording, tmp_path, capsys):
    rec = tmp_path / "rec"
    shutil.copytree(recording, rec)
    dead, alive = rec / f".tdm.partial-{dead_pid()}", rec / f".tdm.partial-{os.getppid()}"
    for folder in (dead, alive):
        (folder / "tdm").mkdir(parents=True)
        (folder / "tdm" / "detected_targets.jsonl").write_text("", encoding="utf-8")
    (rec / "tdm").mkdir()
    (rec / "tdm" / "notes.txt").write_text("kept\n", encoding="utf-8")  # not the TDM's: stays
    assert main(["run", str(rec), "--workers", "0"]) == 0
    assert main(["evaluate", str(rec), "--no-plots"]) == 0
    capsys.readouterr()
    assert not dead.exists() and alive.is_dir()
    assert sorted(p.name for p in (rec / "tdm").iterdir()) == ["detected_targets.jsonl", "metrics.json", "notes.txt",
                                                                "sensor_tracks.jsonl"]


def test_sigterm_that_an_extension_turns_into_another_exception_still_exits_143(recording, monkeypatch, capsys):
    import tdm.pipeline

    def run_hit_in_an_import(*args, **kwargs):
        try:
            os.kill(os.getpid(), signal.SIGTERM)
        except KeyboardInterrupt as exc:
            raise ImportError("initialization failed") from exc
        raise AssertionError("SIGTERM did not arrive")

    monkeypatch.setattr(tdm.pipeline, "run_tdm", run_hit_in_an_import)
    assert main(["run", str(recording), "--workers", "0"]) == 143
    captured = capsys.readouterr()
    assert captured.err.splitlines() == ["error: terminated; nothing was written"] and captured.out == ""
    assert not (recording / "tdm").exists() and not list(recording.glob(".tdm.partial-*"))

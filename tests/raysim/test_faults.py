"""raysim under faults: a full disk, SIGTERM, the staging directories of killed runs (issue 17).

docs/contracts.md "Command line": an output that cannot be written gives one line
``error: <directory>: writing: <what>`` and exit code 2; SIGTERM exits with 143 after the same
cleanup as Ctrl-C; in every case no ``.NAME.partial-PID`` is left behind.
"""

from __future__ import annotations

import errno
import os
import signal
import socket
import subprocess
import sys
import time

import pytest
import yaml

from raysim.cli import main
from tests.conftest import REPO
from tests.faults import dead_pid, left_in, small_disk

BUSY = REPO / "scenarios" / "busy_open_sea.yaml"


@pytest.mark.parametrize("kind", ["tmpfs", "fsize"])
def test_a_full_disk_during_render_gives_one_line_exit_2_and_leaves_nothing(tmp_path, kind):
    # 2 s of HDL-32E packets are 4.6 MB: the disk of 2 MB fills in the LiDAR stage
    with small_disk(tmp_path / "disk", 2_000_000, kind) as disk:
        out = disk.path / "rec"
        done = disk.run("raysim.cli", ["render", str(BUSY), "-o", str(out), "--duration", "2", "--sensors", "lidar",
                                       "--no-progress"])
        assert done.returncode == 2, done.stderr
        assert done.stderr.splitlines() == [f"error: {out}: writing: {disk.what}"]
        assert left_in(disk.path) == []  # no recording, no .rec.partial-PID


def ais_only(tmp_path, duration_s: float = 10.0):
    """busy_open_sea with only its AIS and navigation sensors: a quick ``raysim run``."""
    data = yaml.safe_load(BUSY.read_text(encoding="utf-8"))
    data["duration_s"] = duration_s
    for name in ("lidar", "radar"):
        data.setdefault("sensors", {}).setdefault(name, {})["enabled"] = False
    path = tmp_path / "ais_only.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    return path


def test_a_full_disk_in_the_tdm_of_raysim_run_names_the_recording(tmp_path, monkeypatch, capsys):
    """``raysim run`` writes the TDM's files inside its staging directory: the line names the recording."""
    import tdm.evaluate

    def no_room(recording, metrics):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(tdm.evaluate, "write_metrics", no_room)
    out = tmp_path / "runs" / "rec"
    assert main(["run", str(ais_only(tmp_path)), "-o", str(out), "--no-progress"]) == 2
    captured = capsys.readouterr()
    assert captured.err.splitlines() == [f"error: {out}: writing: no space left on device"]
    assert captured.out == ""
    assert left_in(tmp_path / "runs") == []


def test_a_full_disk_stops_a_batch_with_one_line(tmp_path):
    from tests.raysim.helpers import tiny_scenario

    scenario = tiny_scenario(tmp_path / "scenario")  # 6 s with the LiDAR: far more than 2 MB
    with small_disk(tmp_path / "disk", 2_000_000) as disk:
        out = disk.path / "batch"
        done = disk.run("raysim.cli", ["batch", str(scenario), "-o", str(out), "--seeds", "2", "--workers", "1",
                                       "--no-progress"])
        assert done.returncode == 2, done.stderr
        assert done.stderr.splitlines() == [f"error: {out}: writing: {disk.what}"]
        assert not [p for p in left_in(disk.path) if ".partial-" in p]


def test_sigterm_removes_the_staging_directory_and_exits_143(tmp_path):
    out = tmp_path / "rec"
    env = {**os.environ, "PYTHONDONTWRITEBYTECODE": "1"}
    proc = subprocess.Popen([sys.executable, "-m", "raysim.cli", "render", str(BUSY), "-o", str(out),
                             "--duration", "120", "--sensors", "lidar,radar", "--no-progress"],
                            cwd=REPO, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 120
        while not list(tmp_path.glob(".rec.partial-*")) and proc.poll() is None and time.monotonic() < deadline:
            time.sleep(0.05)
        assert [p.name for p in tmp_path.glob(".rec.partial-*")] == [f".rec.partial-{proc.pid}"]
        time.sleep(1.0)  # well into the sensors
        proc.send_signal(signal.SIGTERM)
        stdout, stderr = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 143, stderr
    assert stderr.splitlines() == ["error: terminated; nothing was written"] and stdout == ""
    assert sorted(p.name for p in tmp_path.iterdir()) == []


def test_the_next_run_removes_staging_directories_of_dead_processes_only(tmp_path, capsys):
    import yaml as _yaml

    data = _yaml.safe_load(BUSY.read_text(encoding="utf-8"))
    data["duration_s"] = 2.0
    for name in ("lidar", "radar", "ais"):
        data.setdefault("sensors", {}).setdefault(name, {})["enabled"] = False
    scenario = tmp_path / "tiny.yaml"
    scenario.write_text(_yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    runs = tmp_path / "runs"
    dead = dead_pid()
    stale = [runs / f".rec.partial-{dead}", runs / f".other.old-{dead}"]
    kept = [runs / f".other.partial-{os.getpid()}",  # alive: this test
            runs / f".another.partial-{os.getppid()}",  # alive, another program
            runs / f".remote.partial-{dead}"]  # made on another host of a shared file system
    for folder in stale + kept:
        folder.mkdir(parents=True)
        (folder / "truth.jsonl").write_text("{}\n", encoding="utf-8")
    (runs / f".remote.partial-{dead}" / ".staging-host").write_text(f"not-{socket.gethostname()}\n")
    (runs / f".file.partial-{dead}").write_text("a file, not a staging directory\n")
    assert main(["render", str(scenario), "-o", str(runs / "rec"), "--no-progress"]) == 0
    capsys.readouterr()
    assert all(not p.exists() for p in stale)
    assert all(p.is_dir() for p in kept) and (runs / f".file.partial-{dead}").is_file()
    assert not (runs / "rec" / ".staging-host").exists()  # the marker never reaches the recording


def test_sigterm_that_an_extension_turns_into_another_exception_still_exits_143(tmp_path, monkeypatch, capsys):
    """SIGTERM landing in a C extension's module initialisation comes out as ImportError (open3d's does)."""
    import raysim.render

    def render_hit_in_an_import(*args, **kwargs):
        try:
            os.kill(os.getpid(), signal.SIGTERM)
        except KeyboardInterrupt as exc:
            raise ImportError("initialization failed") from exc
        raise AssertionError("SIGTERM did not arrive")

    monkeypatch.setattr(raysim.render, "render", render_hit_in_an_import)
    previous = signal.getsignal(signal.SIGTERM)
    assert main(["render", str(BUSY), "-o", str(tmp_path / "rec"), "--no-progress"]) == 143
    assert signal.getsignal(signal.SIGTERM) == previous
    captured = capsys.readouterr()
    assert captured.err.splitlines() == ["error: terminated; nothing was written"] and captured.out == ""


def test_ctrl_c_that_an_extension_turns_into_another_exception_still_exits_130(tmp_path, monkeypatch, capsys):
    """Ctrl-C landing in open3d's module initialisation comes out as ImportError from KeyboardInterrupt (seen
    when a terminal's Ctrl-C arrived as the radar renderer imported Open3D): still one line and code 130."""
    import raysim.render

    def render_hit_in_an_import(*args, **kwargs):
        try:
            raise KeyboardInterrupt
        except KeyboardInterrupt as exc:
            raise ImportError("initialization failed") from exc

    monkeypatch.setattr(raysim.render, "render", render_hit_in_an_import)
    assert main(["render", str(BUSY), "-o", str(tmp_path / "rec"), "--no-progress"]) == 130
    captured = capsys.readouterr()
    assert captured.err.splitlines() == ["error: interrupted; nothing was written"] and captured.out == ""


def test_an_interrupt_just_after_the_staging_directory_is_made_leaves_nothing(tmp_path, monkeypatch):
    """Ctrl-C between the staging directory's creation and its host marker (seen when a signal followed the
    directory's appearance at once): the directory goes, as for any interrupt later."""
    from pathlib import Path

    from groundfloor.staging import HOST_MARKER, Staging

    written = Path.write_text

    def interrupted(self, *args, **kwargs):
        if self.name == HOST_MARKER:
            raise KeyboardInterrupt
        return written(self, *args, **kwargs)

    monkeypatch.setattr(Path, "write_text", interrupted)
    with pytest.raises(KeyboardInterrupt):
        with Staging(tmp_path / "out"):
            pass
    assert list(tmp_path.iterdir()) == []

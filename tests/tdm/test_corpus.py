"""Every broken recording of the corpus (tests/tdm/corpus) through ``tdm info``, ``tdm run`` and ``tdm evaluate``.

One valid recording (busy_open_sea, 6 s, every sensor) is rendered once; each case is a copy of
hard links with one corruption (tests/tdm/corpus/cases.py). Each command runs in this process
(``tdm run --workers 0``) and must give the case's outcome: an error is exit code 2 and exactly
one stderr line ``error: <file>: <place>: <what>`` (no traceback) with nothing written (no
``tdm/``, no staging directory, no ``metrics.json``); a success is exit code 0 with exactly the
expected warning counts (``tdm info``, ``tdm run``). ``tdm evaluate`` runs on the run's outputs,
or on the valid recording's when the run refused the copy.
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest

from tdm.cli import main as tdm_main
from tests.tdm.corpus.cases import CASES
from tests.tdm.corpus.corrupt import Case, Outcome, materialise
from tests.tdm.corpus.make_recordings import index_markdown, render_base

INDEX = Path(__file__).parent / "corpus" / "INDEX.md"


@pytest.fixture(scope="session")
def corpus_base(tmp_path_factory) -> tuple[Path, Path]:
    """The valid recording and its ``tdm run`` outputs (outside it)."""
    folder = tmp_path_factory.mktemp("corpus")
    base = render_base(folder / "base")
    outputs = folder / "base_tdm"
    assert tdm_main(["run", str(base), "--workers", "0", "-o", str(outputs)]) == 0
    return base, outputs


def warnings_of(stderr: str) -> dict[str, int]:
    """``warning: <key>: <count>`` lines as a dict."""
    lines = [line[len("warning: "):].rsplit(": ", 1) for line in stderr.splitlines() if line.startswith("warning: ")]
    return {key: int(count) for key, count in lines}


def check(capsys, argv: list[str], expected: Outcome, rec: Path, written: Path | None,
          exact_warnings: bool = True) -> None:
    """Run ``tdm argv`` and compare with ``expected`` (module docstring)."""
    capsys.readouterr()
    code = tdm_main(argv)
    stderr = capsys.readouterr().err
    assert "Traceback" not in stderr
    assert code == expected.code, f"tdm {argv[0]}: exit {code}, expected {expected.code}; stderr: {stderr!r}"
    if expected.code:
        lines = stderr.splitlines()
        assert len(lines) == 1 and stderr.endswith("\n"), stderr
        prefix = f"error: {rec / expected.file if expected.file else rec}: "
        prefix += f"{expected.place}: " if expected.place else ""  # no place: only the file is promised
        assert lines[0].startswith(prefix), f"{lines[0]!r} does not start with {prefix!r}"
        assert expected.what in lines[0][len(prefix):], lines[0]
        if written is not None:
            assert not written.exists(), f"tdm {argv[0]} wrote {written}"
        if rec.is_dir():
            assert not [p.name for p in rec.iterdir() if p.name.startswith(".tdm.")], "staging left behind"
    else:
        assert not [line for line in stderr.splitlines() if not line.startswith("warning: ")], stderr
        if exact_warnings:
            assert warnings_of(stderr) == dict(expected.warnings)


@pytest.mark.parametrize("case", CASES, ids=[c.name for c in CASES])
def test_a_broken_recording_gives_its_outcome(corpus_base, case: Case, tmp_path, capsys):
    if case.as_user and os.geteuid() == 0:
        pytest.skip("root reads any file whatever its permissions")
    base, base_outputs = corpus_base
    rec = materialise(base, tmp_path / case.name)
    case.corrupt(rec)
    check(capsys, ["info", str(rec)], case.info, rec, None)
    check(capsys, ["run", str(rec), "--workers", "0", *case.run_args], case.run, rec, rec / "tdm")
    if case.run.code and rec.is_dir():  # evaluate what the valid recording's run found
        shutil.copytree(base_outputs, rec / "tdm")
    if case.outputs is not None:
        case.outputs(rec)
    metrics = rec / "tdm" / "metrics.json"
    check(capsys, ["evaluate", str(rec), "--no-plots"], case.evaluate, rec, metrics, exact_warnings=False)
    if case.evaluate.code == 0:
        assert metrics.is_file()


@pytest.mark.parametrize("name", ["lidar_x_nan", "radar_echo_16", "lidar_swapped", "lidar_cut_head"])
def test_worker_processes_give_the_same_outcome(corpus_base, name, tmp_path, capsys):
    """A sweep checked in a worker process: the error crosses back as the same one line, warnings as counts."""
    case = next(c for c in CASES if c.name == name)
    rec = materialise(corpus_base[0], tmp_path / name)
    case.corrupt(rec)
    check(capsys, ["run", str(rec), "--workers", "2"], case.run, rec, rec / "tdm")


def test_the_corpus_is_large_and_its_index_up_to_date():
    assert len(CASES) >= 60
    assert INDEX.read_text(encoding="utf-8") == index_markdown(), \
        "regenerate: python tests/tdm/corpus/make_recordings.py --index > tests/tdm/corpus/INDEX.md"

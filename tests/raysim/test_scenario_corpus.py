"""Every malformed scenario of the corpus: one line ``error: <file>: <place>: <what>``, exit 2, nothing lost.

The corpus (tests/raysim/corpus/make_scenarios.py) holds the issue-17 cases made from
scenarios/busy_open_sea.yaml; each runs through ``raysim.cli.main`` in-process like
``raysim render CASE -o TMP --duration 1``.
"""

from __future__ import annotations

import datetime as dt
import json
import re
from pathlib import Path

import pytest
import yaml

import raysim.render  # noqa: F401 (imported once here, so no case pays for it)
from raysim import limits
from raysim.cli import main
from raysim.errors import InputError
from raysim.yaml_loader import parse_yaml
from tests.conftest import REPO
from tests.raysim.corpus import make_scenarios as corpus

#: Cases refused at a bound of the YAML reader: the line named must lie in the first part of the file, proof that
#: reading stopped at the bound instead of composing (or expanding) the whole document first. (A wall-clock bound
#: stood here and failed CI on a slow machine, 3.2 s against 3.0 s: speed belongs in benchmarks/, not in tests.)
STOPPED_BEFORE_FRACTION = 0.8


def _tree(folder: Path) -> dict[str, int]:
    """Every entry under ``folder`` (hidden ones included) and its size, symlinks not followed."""
    return {str(p.relative_to(folder)): p.lstat().st_size for p in folder.rglob("*")}


def _run(scenario: Path, out: Path, capsys) -> tuple[int, str, str]:
    code = main(["render", str(scenario), "-o", str(out), "--duration", "1", "--no-progress"])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def _stopped_early(case, scenario: Path, stderr: str) -> None:
    """Assert a case refused at a YAML bound names a line well before the file's end."""
    if not (case.place == "line #" and case.what.startswith("more than")):
        return
    line = int(re.search(r": line (\d+)", stderr).group(1))
    with open(scenario, "rb") as handle:
        n_lines = sum(1 for _ in handle)
    assert line < STOPPED_BEFORE_FRACTION * n_lines, f"{case.name}: refused at line {line} of {n_lines}"


def test_corpus_is_large_and_indexed():
    assert len(corpus.CASES) >= 60
    assert len({c.name for c in corpus.CASES}) == len(corpus.CASES)
    committed = json.loads(corpus.INDEX.read_text(encoding="utf-8"))
    assert committed == corpus.index(), "expected.json is stale: run python tests/raysim/corpus/make_scenarios.py"
    size = sum(p.lstat().st_size for p in corpus.CORPUS.iterdir())
    assert size < 1_000_000


def test_committed_cases_are_what_the_script_makes(tmp_path):
    """The committed files are the script's output (regenerating changes nothing)."""
    for case in corpus.CASES:
        if not case.generated:
            corpus.write_case(case, tmp_path)
    made = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    committed = {p.name: p.read_bytes() for p in corpus.CORPUS.iterdir() if p.name != corpus.INDEX.name}
    assert made == committed, "the corpus is stale: run python tests/raysim/corpus/make_scenarios.py"


@pytest.mark.parametrize("case", corpus.CASES, ids=[c.name for c in corpus.CASES])
def test_case_is_one_line_exit_2_nothing_written(case, tmp_path, capsys):
    if case.generated:
        folder = tmp_path / "in"
        folder.mkdir()
        scenario = corpus.write_case(case, folder)
    else:
        folder = corpus.CORPUS
        scenario = folder / f"{case.name}.yaml"
    before = _tree(folder)
    out = tmp_path / "out"
    code, stdout, stderr = _run(scenario, out, capsys)
    file, place, what = corpus.expected_line(case, folder, scenario)
    pattern = re.escape(f"error: {file}: ") + re.escape(place).replace("\\#", "#").replace("#", r"\d+") \
        + re.escape(f": {what}")
    assert code == 2, stderr
    assert re.match(pattern, stderr), f"expected {file}: {place}: {what}\ngot      {stderr}"
    assert stderr.endswith("\n") and stderr.count("\n") == 1, stderr
    assert "Traceback" not in stderr and stdout == ""
    assert not out.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == (["in"] if case.generated else [])  # no staging left
    assert _tree(folder) == before  # nothing written next to the scenario
    _stopped_early(case, scenario, stderr)


def test_a_duration_from_the_command_line_is_held_to_the_time_limits(tmp_path, capsys):
    path = tmp_path / "late.yaml"
    path.write_text(corpus.edit(("start_time: '2017-06-01T12:00:00Z'", "start_time: '2038-01-19T03:00:00Z'"),
                                ("duration_s: 300.0", "duration_s: 60")), encoding="utf-8")
    code = main(["render", str(path), "-o", str(tmp_path / "out"), "--duration", "86400"])
    err = capsys.readouterr().err
    assert code == 2
    assert err.startswith(f"error: {path}: start_time: the run (--duration 86400 s from 2038-01-19T03:00:00Z) ends after")
    assert not (tmp_path / "out").exists()


def test_the_first_and_last_seconds_the_outputs_hold_are_accepted():
    last_start = limits.LATEST_END - dt.timedelta(seconds=1)
    assert limits.time_span_problem(last_start, 1.0) is None
    assert "ends after 2038-01-19T03:14:07Z" in limits.time_span_problem(last_start, 1.5)
    assert limits.time_span_problem(limits.EARLIEST_START, 1.0) is None
    assert limits.LATEST_END.timestamp() == 2**31 - 1 and limits.PCAP_LATEST_END.timestamp() == 2**32 - 1


def test_too_many_triangles_are_refused_before_rendering(tmp_path, capsys, monkeypatch):
    """Mesh files count against MAX_TRIANGLES once per object (lowered here: the pier has 492)."""
    monkeypatch.setattr(limits, "MAX_TRIANGLES", 1_000)
    pier = REPO / "meshes" / "pier.glb"
    piers = "".join(f"- name: Pier_{i}\n  kind: mesh\n  position: [59.4388, 10.47{i}]\n  mesh: {pier}\n" for i in range(3))
    path = tmp_path / "piers.yaml"
    path.write_text(corpus.edit(("ships:\n", piers + "ships:\n")), encoding="utf-8")
    code = main(["render", str(path), "-o", str(tmp_path / "out"), "--duration", "1", "--no-progress"])
    err = capsys.readouterr().err
    assert code == 2
    assert err.startswith(f"error: {path}: obstacles[0]: the scene has ")
    assert "at most 1,000" in err and "GB of meshes" in err and err.count("\n") == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["piers.yaml"]


@pytest.mark.parametrize("path", sorted((REPO / "scenarios").glob("*.yaml")), ids=lambda p: p.stem)
def test_valid_scenarios_parse_as_with_safe_load(path):
    text = path.read_text(encoding="utf-8")
    assert parse_yaml(text, str(path)) == yaml.safe_load(text)


def test_merge_keys_and_shared_anchors_still_work():
    text = "base: &b {x: 1, y: 2}\nz:\n  <<: *b\n  x: 3\nw: [*b, *b]\n"
    assert parse_yaml(text, "t") == yaml.safe_load(text)


def test_a_key_given_twice_names_both_lines():
    with pytest.raises(InputError) as info:
        parse_yaml("a:\n  b: 1\n  c: 2\n  b: 3\n", "f.yaml")
    assert str(info.value) == "f.yaml: line 4: key 'b' given twice (first at line 2)"

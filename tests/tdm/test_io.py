"""tdm reads recordings by their format only, and never imports raysim."""

from __future__ import annotations

import ast
import json

import numpy as np
import pytest

from raysim.cli import main as raysim_main
from tdm.cli import main as tdm_main
from tdm.errors import RecordingError
from tdm.io import read_manifest, read_ownship, read_truth
from tests.conftest import BASE, REPO


def _imported_packages(package: str) -> dict:
    """Path -> the top-level packages each module of ``package`` imports (absolute imports, parsed with ast)."""
    found = {}
    for path in (REPO / package).rglob("*.py"):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        names = set()
        for node in ast.walk(tree):
            if isinstance(node, ast.Import):
                names.update(a.name.split(".")[0] for a in node.names)
            elif isinstance(node, ast.ImportFrom) and node.level == 0:
                names.add((node.module or "").split(".")[0])
        found[path] = names
    return found


def test_tdm_never_imports_raysim():
    for path, names in _imported_packages("tdm").items():
        assert "raysim" not in names, path


def test_groundfloor_imports_neither_raysim_nor_tdm():
    """groundfloor is the floor under both wings (docs/architecture.md "Floors")."""
    found = _imported_packages("groundfloor")
    assert found
    for path, names in found.items():
        assert not names & {"raysim", "tdm", "benchmarks"}, path


@pytest.fixture
def recording(write_scenario, tmp_path):
    out = tmp_path / "rec"
    assert raysim_main(["render", str(write_scenario(BASE)), "-o", str(out), "--no-progress"]) == 0
    return out


def test_reads_a_rendered_recording(recording, capsys):
    manifest = read_manifest(recording)
    nav = read_ownship(recording)
    assert manifest["seed"] == 7
    assert nav["t"].shape == (251,) and np.allclose(np.diff(nav["t"]), 0.02)
    assert {r["kind"] for r in read_truth(recording)} == {"ownship", "iceberg", "buoy", "ship"}
    assert tdm_main(["info", str(recording)]) == 0
    assert "251 navigation samples" in capsys.readouterr().out


def test_bad_recordings_are_one_line_errors(recording, tmp_path, capsys):
    lines = (recording / "ownship.jsonl").read_text().splitlines()
    lines[3] = lines[3][:20]
    (recording / "ownship.jsonl").write_text("\n".join(lines) + "\n")
    with pytest.raises(RecordingError) as info:
        read_ownship(recording)
    assert info.value.where == "line 4"
    assert tdm_main(["info", str(recording)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"error: {recording / 'ownship.jsonl'}: line 4: ") and err.count("\n") == 1
    assert tdm_main(["info", str(tmp_path / "nowhere")]) == 2
    empty = tmp_path / "empty"
    empty.mkdir()
    with pytest.raises(RecordingError, match="not a recording"):
        read_manifest(empty)
    (empty / "manifest.json").write_text("{")
    with pytest.raises(RecordingError, match="not valid JSON"):
        read_manifest(empty)
    assert json.loads((recording / "manifest.json").read_text())["format"] == "raysim-recording"

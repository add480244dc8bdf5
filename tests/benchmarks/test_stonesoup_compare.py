"""Our trackers against the tuned Stone Soup trackers (benchmarks/stonesoup_compare.py), on held-out data.

Marked ``bench`` (not run by the default test command; renders 120 s of crossing_silent_ship, then
runs ``tdm run`` and six Stone Soup trackers: 3.3 min in all on 2 cores). The Stone Soup
settings are the ones the benchmark chose on busy_open_sea (read from
benchmarks/results/stonesoup_compare.md, unchanged); the test scores ours and them on the held-out
crossing with ``tdm.evaluate.evaluate`` and asserts the ordering the benchmark's held-out table shows.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

pytest.importorskip("stonesoup")

from benchmarks.common import ensure_recording  # noqa: E402
from benchmarks.stonesoup_compare import read_events, run_ours  # noqa: E402
from benchmarks.stonesoup_report import CHOSEN_MARKER  # noqa: E402
from benchmarks.stonesoup_trackers import Context, Setting  # noqa: E402
from benchmarks.stonesoup_tuning import Runner  # noqa: E402
from tdm.pipeline import TdmConfig  # noqa: E402

pytestmark = pytest.mark.bench

ROOT = Path(__file__).resolve().parents[2]
RESULTS = ROOT / "benchmarks" / "results" / "stonesoup_compare.md"


@pytest.fixture(scope="module")
def crossing_120s(tmp_path_factory) -> Path:
    """crossing_silent_ship, 120 s, every sensor (the benchmark's held-out recording)."""
    out = tmp_path_factory.mktemp("ss_css") / "rec"
    return ensure_recording(ROOT / "scenarios" / "crossing_silent_ship.yaml", out, 120.0)[0]


def chosen_settings() -> tuple[dict[str, dict[str, Setting]], Context]:
    """The settings the benchmark chose on the tuning recording and its fixed inputs, from the results file."""
    line = next(line for line in RESULTS.read_text(encoding="utf-8").splitlines() if CHOSEN_MARKER in line)
    data = json.loads(line.split(CHOSEN_MARKER, 1)[1].rsplit("-->", 1)[0])
    chosen = {a: {n: Setting(**s) for n, s in c.items()} for a, c in data["chosen"].items()}
    return chosen, Context(**data["context"])


def compare_chosen(recording: Path, workdir: Path, names: tuple[str, ...]) -> tuple[dict, dict]:
    """Ours and every Stone Soup tracker of ``names`` (both algorithms) at its chosen setting.

    Returns
    -------
    ours : dict
        {fused, lidar, radar: metrics}.
    stonesoup : dict
        {(algorithm, name): metrics}.
    """
    chosen, ctx = chosen_settings()
    config = TdmConfig.for_recording(recording)
    ours, _ = run_ours(recording, workdir, config)
    events, stream, counts = read_events(recording, config)
    assert counts.get("radar", 0) > 0
    runner = Runner(recording, events, stream.ownship.frame, ctx, config.update_rate_hz, workdir)
    return ours, {(a, n): runner.metrics(n, chosen[a][n]) for a in chosen for n in names}


def best_gospa(stonesoup: dict, names: tuple[str, ...]) -> float:
    """Lowest GOSPA (c = 50 m) of the Stone Soup trackers named (either algorithm), m."""
    values = [m["gospa_m"] for (_, n), m in stonesoup.items() if n in names and m.get("gospa_m") is not None]
    assert values, f"Stone Soup {names} output no tracks"
    return min(values)




def test_crossing_fused_beats_tuned_stonesoup_central_but_jpda_radar_beats_ours(crossing_120s, tmp_path):
    """Held-out crossing, 120 s (benchmark: ours fused 16.9 m against Stone Soup's best central 19.7 m, JPDA
    LiDAR+radar; ours radar 26.5 m against Stone Soup's JPDA radar 18.4 m and GNN radar 26.7 m)."""
    ours, ss = compare_chosen(crossing_120s, tmp_path, ("radar", "central", "central_ais"))
    assert ours["fused"]["gospa_m"] < best_gospa(ss, ("central", "central_ais"))
    assert ss[("jpda", "radar")]["gospa_m"] < ours["radar"]["gospa_m"]

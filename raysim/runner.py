"""The main job as a function: render a scenario, run the TDM on the staged recording, evaluate it.

``raysim run`` and each run of ``raysim batch`` call :func:`render_detect_evaluate`; the TDM runs
inside the staged directory (:func:`raysim.render.render`'s ``after_sensors``), so its targets
join the bag and the recording still appears whole or not at all; its evaluation runs while the bag
is written (``beside_derived``).
"""

from __future__ import annotations

import contextlib
from pathlib import Path

from raysim.render import RenderResult, render
from raysim.scenario import Scenario

__all__ = ["render_detect_evaluate"]


def render_detect_evaluate(scenario: Scenario, out_dir: Path, progress: bool | None = None, formats: tuple[str, ...] = (),
                           tdm_workers: int = 2, processes: int = 1) -> tuple[RenderResult, dict]:
    """Render ``scenario`` into ``out_dir``, then ``tdm run`` and ``tdm evaluate`` on it.

    Parameters
    ----------
    scenario : Scenario
        Resolved, overrides applied.
    out_dir : Path
        Recording directory.
    progress : bool, optional
        Progress of every stage, the TDM's ``tdm run`` and ``tdm evaluate`` too (:mod:`raysim.progress`):
        default bars when stderr is a terminal, lines otherwise; ``False`` nothing.
    formats : tuple of str
        Extra point-cloud files (:func:`raysim.render.render`).
    tdm_workers : int
        Front-end worker processes of the TDM (0: in this process, as inside a Dask task).
    processes : int
        Processes the sensors render in (:func:`raysim.render.render`; 1 inside a Dask task).

    Returns
    -------
    result : RenderResult
    metrics : dict
        ``tdm/metrics.json``'s content.
    """
    from raysim.progress import bars, stage
    from tdm.cli import evaluate_command, run_command

    metrics: dict = {}

    def detect(staged: Path) -> dict[str, int]:
        with _fresh_recording():
            with stage("tdm run", progress, "detect and track targets", bar=True) as step:
                result = run_command(staged, workers=tdm_workers, progress=bars(progress))
                step.done = f"{result.n_targets} targets over {result.n_epochs} epochs"
        counts = {"tdm/detected_targets.jsonl": result.n_target_lines, "tdm/targets": result.n_targets}
        counts.update({f"tdm/warnings/{k}": v for k, v in result.warnings.items()})
        return counts

    def evaluate(staged: Path) -> None:
        with _fresh_recording():
            with stage("tdm evaluate", progress, "metrics against truth, plots"):
                metrics.update(evaluate_command(staged))

    result = render(scenario, out_dir, progress=progress, formats=formats, after_sensors=detect,
                    beside_derived=evaluate, processes=processes)
    return result, metrics


@contextlib.contextmanager
def _fresh_recording():
    """The TDM on the recording just written: a RecordingError there is a bug, not bad input."""
    from tdm.errors import RecordingError

    try:
        yield
    except RecordingError as exc:
        raise RuntimeError(f"tdm failed on the fresh recording: {exc}") from exc

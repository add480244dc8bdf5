"""The corpus of broken recordings (issue 17): corrupted copies of one short valid recording.

Each :class:`Case` names one corruption and what ``tdm info``, ``tdm run`` and ``tdm evaluate``
must do with it: an :class:`Outcome` that is either an error (exit code 2, one line
``error: <file>: <place>: <what>``, nothing written) or a success with the warning counts of the
run (docs/formats.md, "Reading a recording: warnings and errors"). ``tests/tdm/test_corpus.py``
runs every case; ``INDEX.md`` beside this file lists them (kept equal to :func:`index_markdown`).

Copies are hard links to the valid recording; a corruption never writes into a linked file, it
replaces it (:func:`replace`), so the original stays intact.

As a script::

    python tests/tdm/corpus/make_recordings.py OUT [--index]

renders busy_open_sea for 6 s into ``OUT/base`` (6 s: two radar revolutions, so radar sweeps can
be out of order) and writes every case into ``OUT/<case>``; ``--index`` prints the index instead.
"""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[3]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from tests.tdm.corpus.cases import CASES  # noqa: E402
from tests.tdm.corpus.corrupt import materialise  # noqa: E402

DURATION_S = "6"

__all__ = ["CASES", "index_markdown", "render_base", "DURATION_S"]


# ----------------------------------------------------------------------------- the base and the index


def render_base(out: Path) -> Path:
    """busy_open_sea for DURATION_S seconds, every sensor, into ``out``."""
    from raysim.cli import main as raysim_main

    code = raysim_main(["render", str(REPO / "scenarios" / "busy_open_sea.yaml"), "-o", str(out), "--duration",
                        DURATION_S, "--no-progress"])
    if code != 0:
        raise RuntimeError(f"raysim render failed with {code}")
    return out


def index_markdown() -> str:
    """The corpus index: every case, its corruption and each command's expected outcome."""
    rows = ["# Corpus of broken recordings", "",
            f"Made by `make_recordings.py` from busy_open_sea rendered for {DURATION_S} s; run by "
            "`tests/tdm/test_corpus.py`. Outcomes: `ok` (with the run's warnings, `key: count`) or the start of "
            "the one error line (`<file>: <place>: ...<what>...`, exit code 2, nothing written). "
            "Rules: docs/formats.md, \"Reading a recording: warnings and errors\".", "",
            f"{len(CASES)} cases.", "",
            "| case | corruption | tdm info | tdm run | tdm evaluate |", "|---|---|---|---|---|"]
    for case in CASES:
        extra = f" (`tdm run {' '.join(case.run_args)}`)" if case.run_args else ""
        extra += " (not as root)" if case.as_user else ""
        rows.append(f"| `{case.name}` | {case.description}{extra} | {case.info.text()} | {case.run.text()} | "
                    f"{case.evaluate.text()} |")
    return "\n".join(rows) + "\n"


def main(argv: list[str]) -> int:
    if "--index" in argv:
        sys.stdout.write(index_markdown())
        return 0
    out = Path(argv[0])
    base = render_base(out / "base")
    for case in CASES:
        dest = out / case.name
        if dest.exists():
            shutil.rmtree(dest)
        case.corrupt(materialise(base, dest))
    print(f"{len(CASES)} cases in {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

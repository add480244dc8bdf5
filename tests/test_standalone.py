"""The repository stands alone: no tracked file points at a path outside it.

A user's clone holds nothing beside the checkout, so docs, code comments, tests, scenarios and
benchmarks cite the repository's own docs (docs/reference.md for sensor facts and their sources,
docs/contracts.md for the contracts), never design notes kept next to the checkout or a path on
a developer's machine. Every ``docs/<name>.md`` that a tracked file mentions must exist.

The forbidden patterns are assembled from pieces so that this file does not match them itself
(it is scanned like every other tracked file).
"""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]

#: Bytes read to decide whether a file is binary (a NUL byte among them), as git does.
BINARY_SNIFF_BYTES = 8000

_UP = ".." + "/"
_NOTES = ("DESIGN", "REFERENCE")
#: Pattern -> why it is forbidden. Case-sensitive: docs/reference.md (lower case) is ours.
FORBIDDEN = {
    re.compile(re.escape(_UP + "shared")): "the design notes' folder beside the checkout",
    re.compile("shared/(?:" + "|".join(_NOTES) + ")"): "design notes outside the repository",
    re.compile(r"(?<![\w/.-])(?:" + "|".join(_NOTES) + r")\.md"): "a design note that is not in the repository",
    re.compile(r"(?<![\w.~-])/(?:" + "|".join(("work", "home", "root")) + ")/"): "an absolute path on a developer's machine",
}
#: A relative path that climbs out of its file's folder, e.g. a scenario's mesh path.
RELATIVE_UP = re.compile(r"(?<![\w.])(?:\.\./)+[\w.-]+(?:/[\w.-]+)*")
#: A mention of a page of the docs folder.
DOCS_PAGE = re.compile(r"(?<![\w/.-])docs/([\w-]+)\.md\b")


def _tracked_text_files() -> list[tuple[str, str]]:
    """(path relative to the repository, text) of every tracked, existing, non-binary file."""
    try:
        out = subprocess.run(["git", "ls-files", "-z"], cwd=REPO, capture_output=True, check=True, timeout=60)
    except (OSError, subprocess.SubprocessError):
        pytest.skip("not a git checkout (or git is missing): nothing to check")
    files = []
    for name in out.stdout.decode("utf-8", errors="surrogateescape").split("\0"):
        path = REPO / name
        if not name or not path.is_file():  # deleted in the working tree, or a submodule
            continue
        data = path.read_bytes()
        if b"\0" in data[:BINARY_SNIFF_BYTES]:
            continue
        files.append((name, data.decode("utf-8", errors="replace")))
    if not files:
        pytest.skip("git lists no files here: not a checkout of this repository")
    return files


@pytest.fixture(scope="module")
def tracked():
    return _tracked_text_files()


def _hits(text: str, pattern: re.Pattern) -> list[tuple[int, str]]:
    """(line number, matched text) of every match of ``pattern`` in ``text``."""
    return [(text.count("\n", 0, m.start()) + 1, m.group(0)) for m in pattern.finditer(text)]


def test_no_reference_to_paths_outside_the_repository(tracked):
    problems = [f"{name}:{line}: {found!r} ({why})"
                for name, text in tracked
                for pattern, why in FORBIDDEN.items()
                for line, found in _hits(text, pattern)]
    assert not problems, ("tracked files point outside the repository; cite docs/reference.md or "
                          "docs/contracts.md instead:\n" + "\n".join(problems))


def test_relative_paths_stay_inside_the_repository(tracked):
    root = REPO.resolve()
    problems = []
    for name, text in tracked:
        folder = (REPO / name).parent
        for line, found in _hits(text, RELATIVE_UP):
            target = (folder / found).resolve()
            if target != root and root not in target.parents:
                problems.append(f"{name}:{line}: {found!r} resolves to {target}, outside the repository")
    assert not problems, "\n".join(problems)


def test_every_docs_page_mentioned_exists(tracked):
    missing = [f"{name}:{line}: {found}"
               for name, text in tracked
               for line, found in _hits(text, DOCS_PAGE)
               if not (REPO / found).is_file()]
    assert not missing, "docs pages mentioned but missing:\n" + "\n".join(missing)


def test_the_patterns_catch_what_they_should():
    """The checks above would see the citations they exist to keep out (and not our own docs)."""
    bad = [_UP + "shared/" + _NOTES[0] + ".md", "see " + _NOTES[1] + ".md section 2",
           "/" + "work" + "/main/x.py", "/" + "home" + "/user/data", "/" + "root" + "/.cache"]
    for text in bad:
        assert any(p.search(text) for p in FORBIDDEN), text
    good = ["docs/reference.md section 2", "docs/contracts.md", "https://example.org/home/page",
            "-o /shared/batches/ss", "mesh: ../meshes/odin.glb"]
    for text in good:
        assert not any(p.search(text) for p in FORBIDDEN), text
    assert [m.group(1) for m in DOCS_PAGE.finditer("see docs/reference.md and ./docs/x.md")] == ["reference"]

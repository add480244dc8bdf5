"""Output directories that appear whole or not at all.

A run writes into a hidden staging directory next to the requested one
(``.NAME.partial-PID``); :meth:`StagedDirectory.commit` swaps it into place at
the end. On any error or interrupt the staging directory is removed, so bad
input or a failed run leaves nothing behind. Inside the staging directory each
file is itself written under a temporary name and renamed (:func:`atomic_path`).
"""

from __future__ import annotations

import os
import shutil
from contextlib import contextmanager
from pathlib import Path
from typing import Iterator

from raysim.errors import InputError

MANIFEST = "manifest.json"


def check_output_dir(path: Path) -> None:
    """Refuse an output directory that exists and is neither empty nor a raysim recording."""
    if path.exists() and not path.is_dir():
        raise InputError("command line", "-o", f"{path} exists and is not a directory")
    if path.is_dir() and any(path.iterdir()) and not (path / MANIFEST).is_file():
        raise InputError("command line", "-o", f"{path} is not empty and holds no raysim recording (no {MANIFEST}); choose another directory")


class StagedDirectory:
    """A directory built under a temporary name and moved into place by :meth:`commit`.

    Use as a context manager: leaving it by an exception removes everything.
    """

    def __init__(self, final: Path):
        self.final = Path(final).absolute()
        self.path = self.final.parent / f".{self.final.name}.partial-{os.getpid()}"
        self._committed = False

    def __enter__(self) -> "StagedDirectory":
        check_output_dir(self.final)
        self.final.parent.mkdir(parents=True, exist_ok=True)
        shutil.rmtree(self.path, ignore_errors=True)
        self.path.mkdir()
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        if not self._committed:
            shutil.rmtree(self.path, ignore_errors=True)

    def commit(self) -> None:
        """Replace the final directory (an older recording, or nothing) by the staged one."""
        old = None
        if self.final.exists():
            old = self.final.parent / f".{self.final.name}.old-{os.getpid()}"
            self.final.rename(old)
        self.path.rename(self.final)
        self._committed = True
        if old is not None:
            shutil.rmtree(old, ignore_errors=True)


@contextmanager
def atomic_path(path: Path) -> Iterator[Path]:
    """Yield a temporary sibling path to write; rename it to ``path`` on success, delete it on failure."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.tmp")
    try:
        yield tmp
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise

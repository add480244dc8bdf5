"""raysim's output directories: a recording appears whole or not at all.

A run writes into a hidden staging directory next to the requested one
(``.NAME.partial-PID``); :meth:`StagedDirectory.commit` swaps it into place at
the end. On any error or interrupt the staging directory is removed, so bad
input or a failed run leaves nothing behind. Inside the staging directory each
file is itself written under a temporary name and renamed (:func:`atomic_path`).

The machinery (write faults, SIGTERM as an interrupt, stale staging directories of killed runs)
is :mod:`groundfloor.staging`, shared with the TDM; it is re-exported here.
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path

from groundfloor.recording import MANIFEST
from groundfloor.staging import (EXIT_INTERRUPTED, EXIT_TERMINATED, HOST_MARKER, WRITE_ERRNOS, OutputWriteError,  # noqa: F401
                                 Sigterm, Staging, Terminated, atomic_path, is_write_fault, remove_stale,
                                 report_fault, sigterm_as_interrupt, write_fault)
from raysim.errors import InputError


def check_output_dir(path: Path, option: str = "-o") -> None:
    """Refuse an output directory (given by the command-line ``option``) that exists and is neither empty nor a
    raysim recording."""
    if path.exists() and not path.is_dir():
        raise InputError("command line", option, f"{path} exists and is not a directory")
    if path.is_dir() and any(path.iterdir()) and not (path / MANIFEST).is_file():
        raise InputError("command line", option, f"{path} is not empty and holds no raysim recording (no {MANIFEST}); choose another directory")


class StagedDirectory(Staging):
    """A directory built under a temporary name and moved into place by :meth:`commit`.

    Use as a context manager: leaving it by an exception removes everything; a write fault
    (:data:`WRITE_ERRNOS`) leaves it as :class:`OutputWriteError` naming ``final``. Entering refuses
    an output directory that is neither empty nor a recording (:func:`check_output_dir`) and removes
    the stale staging directories of killed runs beside ``final`` (:func:`remove_stale`).
    """

    def __enter__(self) -> "StagedDirectory":
        check_output_dir(self.final)
        return super().__enter__()

    def commit(self) -> None:
        """Replace the final directory (an older recording, or nothing) by the staged one."""
        (self.path / HOST_MARKER).unlink(missing_ok=True)
        old = None
        if self.final.exists():
            old = self.final.parent / f".{self.final.name}.old-{os.getpid()}"
            self.final.rename(old)
        self.path.rename(self.final)
        self._committed = True
        if old is not None:
            shutil.rmtree(old, ignore_errors=True)

"""The TDM's outputs appear whole or not at all; faults and interrupts end a command cleanly.

``tdm run`` and ``tdm evaluate`` write their files (``detected_targets.jsonl``,
``sensor_tracks.jsonl``; ``metrics.json``, ``tracks.png``, ``errors.png``) into a staging
directory beside the output directory ``DIR`` (default ``RECORDING/tdm``), as
``.DIR.partial-PID/DIR/``, and :meth:`StagedOutputs.commit` moves them into ``DIR`` at the end
(the whole directory by one rename when ``DIR`` does not exist yet, else file by file, replacing
files of the same name and keeping the others). On any error or interrupt the staging directory
is removed and ``DIR`` is left as it was.

Faults (docs/contracts.md "Command line"; the same rules as raysim's, both built on
:mod:`groundfloor.staging`, re-exported here):

- a full disk, an exceeded quota, a read-only file system or an I/O error while writing
  (:data:`WRITE_ERRNOS`) leaves a :class:`StagedOutputs` as :class:`OutputWriteError`, an
  ``OSError`` naming ``DIR``; ``tdm`` prints ``error: <DIR>: writing: <what>`` and exits with 2;
- SIGTERM raises :class:`Terminated` (a ``KeyboardInterrupt``) while :func:`sigterm_as_interrupt`
  is active: exit code 143 (Ctrl-C: 130), after the same cleanup;
- staging directories of killed runs (``.NAME.partial-PID``, ``.NAME.old-PID``) beside ``DIR``
  are removed when process PID is gone (:func:`remove_stale`).
"""

from __future__ import annotations

import os
from pathlib import Path

from groundfloor.staging import (EXIT_INTERRUPTED, EXIT_TERMINATED, HOST_MARKER, WRITE_ERRNOS, OutputWriteError,  # noqa: F401
                                 Sigterm, Staging, Terminated, is_write_fault, remove_stale, report_fault,
                                 sigterm_as_interrupt, write_fault)

__all__ = ["EXIT_INTERRUPTED", "EXIT_TERMINATED", "OutputWriteError", "Sigterm", "StagedOutputs", "Terminated", "WRITE_ERRNOS",
           "is_write_fault", "remove_stale", "report_fault", "sigterm_as_interrupt", "write_fault"]


class StagedOutputs(Staging):
    """Files written under ``.DIR.partial-PID/DIR/`` and moved into ``DIR`` by :meth:`commit`.

    Parameters
    ----------
    final : Path
        The output directory ``DIR``.

    Attributes
    ----------
    root : Path
        The staging directory ``.DIR.partial-PID`` beside ``DIR``.
    path : Path
        Where to write: ``root / DIR.name`` (same name as ``DIR``, so a function that writes
        ``RECORDING/tdm/...`` writes into the staging when handed ``root`` as the recording).

    Use as a context manager: leaving it by an exception removes the staging directory; a write
    fault leaves it as :class:`OutputWriteError` naming ``DIR``.
    """

    def __init__(self, final: Path):
        super().__init__(final, nested=True)

    def commit(self) -> None:
        """Move the staged files into ``DIR`` (created when missing); files of other names stay."""
        if not self.final.exists():
            self.path.rename(self.final)
        else:
            for source in sorted(p for p in self.path.rglob("*") if p.is_file()):
                target = self.final / source.relative_to(self.path)
                target.parent.mkdir(parents=True, exist_ok=True)
                os.replace(source, target)
        self._committed = True

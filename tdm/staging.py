"""The TDM's outputs appear whole or not at all; faults and interrupts end a command cleanly.

``tdm run`` and ``tdm evaluate`` write their files (``detected_targets.jsonl``,
``sensor_tracks.jsonl``; ``metrics.json``, ``tracks.png``, ``errors.png``) into a staging
directory beside the output directory ``DIR`` (default ``RECORDING/tdm``), as
``.DIR.partial-PID/DIR/``, and :meth:`StagedOutputs.commit` moves them into ``DIR`` at the end
(the whole directory by one rename when ``DIR`` does not exist yet, else file by file, replacing
files of the same name and keeping the others). On any error or interrupt the staging directory
is removed and ``DIR`` is left as it was.

Faults (docs/contracts.md "Command line"; the same rules as raysim's, tdm never importing raysim):

- a full disk, an exceeded quota, a read-only file system or an I/O error while writing
  (:data:`WRITE_ERRNOS`) leaves a :class:`StagedOutputs` as :class:`OutputWriteError`, an
  ``OSError`` naming ``DIR``; ``tdm`` prints ``error: <DIR>: writing: <what>`` and exits with 2;
- SIGTERM raises :class:`Terminated` (a ``KeyboardInterrupt``) while :func:`sigterm_as_interrupt`
  is active: exit code 143 (Ctrl-C: 130), after the same cleanup;
- staging directories of killed runs (``.NAME.partial-PID``, ``.NAME.old-PID``) beside ``DIR``
  are removed when process PID is gone (:func:`remove_stale`).
"""

from __future__ import annotations

import errno
import os
import re
import shutil
import signal
import socket
import threading
from contextlib import contextmanager
from pathlib import Path
from typing import Iterator

__all__ = ["EXIT_INTERRUPTED", "EXIT_TERMINATED", "OutputWriteError", "Sigterm", "StagedOutputs", "Terminated", "WRITE_ERRNOS",
           "is_write_fault", "remove_stale", "sigterm_as_interrupt", "write_fault"]

#: ``errno`` values that mean "the output cannot be written": no space left on the device, disk
#: quota exceeded, read-only file system, I/O error, file too large (``ulimit -f``).
WRITE_ERRNOS = frozenset({errno.ENOSPC, errno.EDQUOT, errno.EROFS, errno.EIO, errno.EFBIG})

#: Exit codes of a command stopped by a signal: 128 + the signal's number, as a shell reports it.
EXIT_INTERRUPTED = 128 + signal.SIGINT  # 130, Ctrl-C
EXIT_TERMINATED = 128 + signal.SIGTERM  # 143

#: Inside a staging directory: the host that owns it. One made on another host sharing the file
#: system is never removed as stale (its PID cannot be checked from here).
HOST_MARKER = ".staging-host"

_STAGING_NAME = re.compile(r"^\..+\.(?:partial|old)-(\d+)$")


class OutputWriteError(OSError):
    """Writing the output directory ``filename`` failed with ``errno`` (one of :data:`WRITE_ERRNOS`).

    Built as ``OutputWriteError(errno, strerror, directory)``: it pickles, and stays an ``OSError``
    with the original ``errno`` for a caller that writes a larger whole (``raysim run``).
    """

    @property
    def directory(self) -> str:
        """The output directory that could not be written."""
        return str(self.filename)

    @property
    def what(self) -> str:
        """``no space left on device``, ``disk quota exceeded``, ...: the system's text, lower case."""
        text = self.strerror or os.strerror(self.errno)
        return text[:1].lower() + text[1:]


class Terminated(KeyboardInterrupt):
    """SIGTERM received: raised in the main thread like Ctrl-C's ``KeyboardInterrupt`` (same cleanup)."""


class Sigterm:
    """What :func:`sigterm_as_interrupt` yields: ``received`` is True once SIGTERM arrived.

    The :class:`Terminated` it raises can come out of a C extension as another exception (an
    ``ImportError`` when it lands in a module's initialisation): a command that fails after
    ``received`` was set was terminated, whatever the exception says.
    """

    def __init__(self) -> None:
        self.received = False


def is_write_fault(exc: BaseException) -> bool:
    """Whether ``exc`` is an ``OSError`` whose ``errno`` is in :data:`WRITE_ERRNOS`."""
    return isinstance(exc, OSError) and exc.errno in WRITE_ERRNOS


def write_fault(exc: OSError, directory: Path) -> OutputWriteError:
    """``exc`` as an :class:`OutputWriteError` naming ``directory``."""
    return OutputWriteError(exc.errno, exc.strerror or os.strerror(exc.errno), str(directory))


@contextmanager
def sigterm_as_interrupt() -> Iterator[Sigterm]:
    """While inside, SIGTERM raises :class:`Terminated` in this process's main thread.

    A second SIGTERM is ignored so that the cleanup runs to its end (SIGKILL still stops the
    process). Front-end workers forked meanwhile inherit the handler; in them SIGTERM keeps its
    default action. Outside the main thread nothing changes.
    """
    state = Sigterm()
    if threading.current_thread() is not threading.main_thread():
        yield state
        return
    owner = os.getpid()

    def handler(signum, frame):
        if os.getpid() != owner:  # a forked worker: end as SIGTERM ends it by default
            signal.signal(signum, signal.SIG_DFL)
            os.kill(os.getpid(), signum)
            return
        signal.signal(signum, signal.SIG_IGN)
        state.received = True
        raise Terminated()

    previous = signal.signal(signal.SIGTERM, handler)
    try:
        yield state
    finally:
        signal.signal(signal.SIGTERM, previous)


def _pid_alive(pid: int) -> bool:
    """Whether a process ``pid`` exists here (another user's or another program's counts as alive)."""
    if pid <= 0:
        return True  # 0 and negative numbers address process groups: never treat as gone
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError):
        return True
    return True


def remove_stale(parent: Path) -> list[Path]:
    """Remove the staging directories of killed runs in ``parent``; returns those removed.

    ``.NAME.partial-PID`` or ``.NAME.old-PID`` is stale when no process PID exists on this host
    (``os.kill(PID, 0)`` raises ``ProcessLookupError``); a live PID (whatever program it now is)
    and a directory whose :data:`HOST_MARKER` names another host are kept.
    """
    removed = []
    try:
        entries = list(Path(parent).iterdir())
    except OSError:
        return removed
    host = socket.gethostname()
    for entry in sorted(entries):
        match = _STAGING_NAME.match(entry.name)
        if match is None or entry.is_symlink() or not entry.is_dir():
            continue
        try:
            owner = (entry / HOST_MARKER).read_text(encoding="utf-8").strip()
        except (OSError, UnicodeDecodeError):
            owner = host
        if owner != host or _pid_alive(int(match.group(1))):
            continue
        shutil.rmtree(entry, ignore_errors=True)
        removed.append(entry)
    return removed


class StagedOutputs:
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
        self.final = Path(final).absolute()
        self.root = self.final.parent / f".{self.final.name}.partial-{os.getpid()}"
        self.path = self.root / self.final.name
        self._committed = False

    def __enter__(self) -> "StagedOutputs":
        try:
            self.final.parent.mkdir(parents=True, exist_ok=True)
            remove_stale(self.final.parent)
            shutil.rmtree(self.root, ignore_errors=True)
            self.path.mkdir(parents=True)
            (self.root / HOST_MARKER).write_text(socket.gethostname() + "\n", encoding="utf-8")
        except OSError as exc:
            shutil.rmtree(self.root, ignore_errors=True)
            if is_write_fault(exc):
                raise write_fault(exc, self.final) from exc
            raise
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        shutil.rmtree(self.root, ignore_errors=True)
        if exc is not None and is_write_fault(exc):
            raise write_fault(exc, self.final) from exc

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

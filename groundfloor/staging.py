"""Output directories that appear whole or not at all; write faults; SIGTERM as an interrupt.

A command writes into a hidden staging directory next to the requested one
(``.NAME.partial-PID``) and moves it (or its files) into place at the end
(:class:`Staging`); on any error or interrupt the staging directory is removed, so bad
input or a failed run leaves nothing behind. A single file is written under a temporary
name and renamed (:func:`atomic_path`). raysim (``raysim.recording.staging``: a recording
replaced whole) and tdm (``tdm.staging``: its files moved into ``RECORDING/tdm``) build on this.

Faults (docs/contracts.md "Command line"):

- a full disk, an exceeded quota, a read-only file system or an I/O error while writing
  (:data:`WRITE_ERRNOS`) leaves the staging directory as :class:`OutputWriteError`, an ``OSError``
  that names the output directory; the CLI prints ``error: <directory>: writing: <what>``;
- SIGTERM raises :class:`Terminated` (a ``KeyboardInterrupt``) while :func:`sigterm_as_interrupt`
  is active, so a terminated run cleans up exactly as one interrupted by Ctrl-C (exit code 143;
  Ctrl-C: 130);
- the staging directories of killed runs (``.NAME.partial-PID``, and ``.NAME.old-PID`` of a
  replacement cut short) are removed by the next run into the same parent directory, but only
  when process PID is gone (:func:`remove_stale`).
"""

from __future__ import annotations

import errno
import os
import re
import shutil
import signal
import socket
import sys
import threading
from contextlib import contextmanager
from pathlib import Path
from typing import Iterator

__all__ = ["EXIT_INTERRUPTED", "EXIT_TERMINATED", "HOST_MARKER", "OutputWriteError", "Sigterm", "Staging", "Terminated",
           "WRITE_ERRNOS", "atomic_path", "is_write_fault", "remove_stale", "report_fault", "sigterm_as_interrupt",
           "write_fault"]

#: ``errno`` values that mean "the output cannot be written" (not a bug, not bad input): no space
#: left on the device, disk quota exceeded, read-only file system, I/O error, file too large (a
#: file-size limit, ``ulimit -f``).
WRITE_ERRNOS = frozenset({errno.ENOSPC, errno.EDQUOT, errno.EROFS, errno.EIO, errno.EFBIG})

#: Inside a staging directory: the host that owns it (removed before the directory is committed).
#: A stale-looking directory made on another host sharing the file system (``raysim batch`` on a
#: Dask cluster) is never removed: its PID cannot be checked from here.
HOST_MARKER = ".staging-host"

_STAGING_NAME = re.compile(r"^\..+\.(?:partial|old)-(\d+)$")


class OutputWriteError(OSError):
    """Writing the output directory ``filename`` failed with ``errno`` (one of :data:`WRITE_ERRNOS`).

    Built as ``OutputWriteError(errno, strerror, directory)`` so that it pickles (Dask) and stays an
    ``OSError`` with the original ``errno`` for the layers above.
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


def is_write_fault(exc: BaseException) -> bool:
    """Whether ``exc`` is an ``OSError`` whose ``errno`` is in :data:`WRITE_ERRNOS`."""
    return isinstance(exc, OSError) and exc.errno in WRITE_ERRNOS


def write_fault(exc: OSError, directory: Path) -> OutputWriteError:
    """``exc`` as an :class:`OutputWriteError` naming ``directory`` (the outermost output directory wins)."""
    return OutputWriteError(exc.errno, exc.strerror or os.strerror(exc.errno), str(directory))


#: Exit codes of a command stopped by a signal: 128 + the signal's number, as a shell reports it.
EXIT_INTERRUPTED = 128 + signal.SIGINT  # 130, Ctrl-C
EXIT_TERMINATED = 128 + signal.SIGTERM  # 143


def report_fault(exc: BaseException, out=None, nothing_written: str = "nothing was written",
                 bad_input: type | tuple = ()) -> int | None:
    """A command's one line on stderr for bad input, an output fault or an interrupt, and its exit code.

    Bad input (an instance of ``bad_input``, the wing's one-line error): ``error: <exc>``, exit code 2.

    A write fault (:func:`is_write_fault`): ``error: <directory>: writing: <what>``, exit code 2 (the
    directory: the :class:`OutputWriteError`'s, else ``out``, else the file's name); Ctrl-C or
    SIGTERM: ``error: interrupted; <nothing_written>`` (or ``terminated``), 130 or 143. Any other
    exception: None, printed nothing (the caller re-raises it).
    """
    if bad_input and isinstance(exc, bad_input):
        print(f"error: {exc}", file=sys.stderr)
        return 2
    if isinstance(exc, KeyboardInterrupt):
        how = "terminated" if isinstance(exc, Terminated) else "interrupted"
        print(f"error: {how}; {nothing_written}", file=sys.stderr)
        return EXIT_TERMINATED if isinstance(exc, Terminated) else EXIT_INTERRUPTED
    if not is_write_fault(exc):
        return None
    where = exc.directory if isinstance(exc, OutputWriteError) else out or exc.filename
    text = exc.strerror or os.strerror(exc.errno)
    print(f"error: {where}: writing: {text[:1].lower() + text[1:]}", file=sys.stderr)
    return 2


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


@contextmanager
def sigterm_as_interrupt() -> Iterator[Sigterm]:
    """While inside, SIGTERM raises :class:`Terminated` in this process's main thread.

    A second SIGTERM is ignored, so the cleanup the first one started runs to its end (SIGKILL
    still stops the process). Worker processes forked meanwhile inherit the handler; in them
    SIGTERM keeps its default action (the process ends). Outside the main thread nothing changes.
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
    """Whether a process ``pid`` exists here (another user's, or another program's, counts as alive)."""
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

    A directory named ``.NAME.partial-PID`` or ``.NAME.old-PID`` is stale when no process PID
    exists on this host (``os.kill(PID, 0)`` raises ``ProcessLookupError``). Kept: a live PID (even
    if it now belongs to another program: conservative), and a directory whose
    :data:`HOST_MARKER` names another host.
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
            owner = host  # no marker: an .old directory, or one made before markers
        if owner != host or _pid_alive(int(match.group(1))):
            continue
        shutil.rmtree(entry, ignore_errors=True)
        removed.append(entry)
    return removed


class Staging:
    """A staging directory ``.NAME.partial-PID`` beside the output directory ``final``.

    Use as a context manager: entering removes the stale staging directories of killed runs beside
    ``final`` (:func:`remove_stale`) and makes the staging directory; leaving removes it (after
    :meth:`commit` moved what it holds into place, or on an exception); a write fault
    (:data:`WRITE_ERRNOS`) leaves it as :class:`OutputWriteError` naming ``final``.

    Attributes
    ----------
    final : Path
        The output directory.
    root : Path
        The staging directory ``.NAME.partial-PID``.
    path : Path
        Where to write: ``root`` itself, or ``root / NAME`` when ``nested``.
    """

    def __init__(self, final: Path, nested: bool = False):
        self.final = Path(final).absolute()
        self.root = self.final.parent / f".{self.final.name}.partial-{os.getpid()}"
        self.path = self.root / self.final.name if nested else self.root
        self._committed = False

    def __enter__(self):
        try:
            self.final.parent.mkdir(parents=True, exist_ok=True)
            remove_stale(self.final.parent)
            shutil.rmtree(self.root, ignore_errors=True)
            self.path.mkdir(parents=True)
            (self.root / HOST_MARKER).write_text(socket.gethostname() + "\n", encoding="utf-8")
        except BaseException as exc:  # a write fault, or Ctrl-C / SIGTERM just after the directory was made
            shutil.rmtree(self.root, ignore_errors=True)
            if isinstance(exc, OSError) and is_write_fault(exc):
                raise write_fault(exc, self.final) from exc
            raise
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        shutil.rmtree(self.root, ignore_errors=True)
        if exc is not None and is_write_fault(exc):
            raise write_fault(exc, self.final) from exc

    def commit(self) -> None:
        """Move what was staged into place (each kind of staging decides how)."""
        raise NotImplementedError


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

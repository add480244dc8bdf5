"""A small disk for the write-fault tests, and the commands run on it as a user runs them.

:func:`small_disk` mounts a tmpfs of the size asked for (root with CAP_SYS_ADMIN, as on the
developers' machines and CI): writes beyond it fail with ENOSPC, "no space left on device".
Where mounting is refused it falls back to a file-size limit on the command's process
(``RLIMIT_FSIZE``, SIGXFSZ ignored): writes beyond it fail with EFBIG, "file too large". Either way
the command really runs out of room; :attr:`Disk.what` is the text its error line must end with.
``SMALL_DISK=fsize`` in the environment takes the fallback everywhere (to check it where mounting works).
"""

from __future__ import annotations

import errno
import os
import resource
import signal
import subprocess
import sys
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Iterator

REPO = Path(__file__).resolve().parents[1]


@dataclass
class Disk:
    """A directory that holds at most ``size_bytes`` (tmpfs) or a per-file limit for the command."""

    path: Path
    size_bytes: int
    kind: str  # "tmpfs" or "fsize"

    @property
    def what(self) -> str:
        return os.strerror(errno.ENOSPC if self.kind == "tmpfs" else errno.EFBIG).lower()

    def fill(self) -> None:
        """Leave no room: fill the tmpfs with a file, or cut the file-size limit to 0."""
        if self.kind == "fsize":
            self.size_bytes = 0
            return
        try:
            with open(self.path / "filler", "wb") as handle:
                while True:
                    handle.write(b"\0" * 65536)
                    handle.flush()
        except OSError as exc:
            assert exc.errno == errno.ENOSPC
        try:  # the last partial block too
            with open(self.path / "filler", "ab") as handle:
                while True:
                    handle.write(b"\0")
                    handle.flush()
        except OSError as exc:
            assert exc.errno == errno.ENOSPC

    def run(self, module: str, argv: list[str], timeout_s: float = 300.0) -> subprocess.CompletedProcess:
        """``python -m module argv`` (``raysim.cli`` or ``tdm.cli``) with this disk's limit."""
        limit = self.size_bytes

        def limited() -> None:
            signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
            resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

        env = {**os.environ, "PYTHONDONTWRITEBYTECODE": "1"}
        return subprocess.run([sys.executable, "-m", module, *argv], cwd=REPO, env=env, capture_output=True,
                              text=True, timeout=timeout_s, preexec_fn=limited if self.kind == "fsize" else None)


@contextmanager
def small_disk(path: Path, size_bytes: int, kind: str = "tmpfs") -> Iterator[Disk]:
    """A :class:`Disk` at ``path`` (created): a tmpfs when ``kind`` is "tmpfs" and mounting works, else
    a file-size limit of ``size_bytes`` on the commands it runs."""
    path.mkdir(parents=True, exist_ok=True)
    mounted = False
    if kind == "tmpfs" and os.environ.get("SMALL_DISK") != "fsize":
        done = subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={size_bytes}", "tmpfs", str(path)],
                              capture_output=True, text=True)
        mounted = done.returncode == 0
    try:
        yield Disk(path, size_bytes, "tmpfs" if mounted else "fsize")
    finally:
        if mounted and subprocess.run(["umount", str(path)], capture_output=True).returncode != 0:
            subprocess.run(["umount", "-l", str(path)], capture_output=True)


def left_in(path: Path) -> list[str]:
    """Every entry under ``path`` (hidden ones too) but the filler, relative, sorted."""
    return sorted(str(p.relative_to(path)) for p in path.rglob("*") if p.name != "filler")


def dead_pid() -> int:
    """The PID of a process that has ended and been reaped."""
    for _ in range(10):
        child = subprocess.Popen([sys.executable, "-c", "pass"])
        child.wait()
        try:
            os.kill(child.pid, 0)
        except ProcessLookupError:
            return child.pid
    raise AssertionError("no dead PID found")

"""Opening a recording's files: what is there instead of a readable file is said in one line.

A recording arrives copied, unpacked and edited by hand, so a path the contract names can be
missing, a directory, a broken or looping symbolic link, unreadable for its permissions, or hold
bytes that are not UTF-8. Each case raises :class:`tdm.errors.RecordingError` with the place
``(file)`` (or ``line N`` for a decoding error) instead of a traceback.
"""

from __future__ import annotations

import errno
import os
import stat
from pathlib import Path

from tdm.errors import RecordingError

__all__ = ["file_problem", "regular_file", "is_present", "directory_present", "read_bytes", "decode_utf8"]

_REASONS = {errno.ENOENT: "missing", errno.EISDIR: "is a directory, not a file", errno.ELOOP: "a symbolic link loop",
            errno.EACCES: "not readable (permission denied)", errno.EPERM: "not readable (permission denied)",
            errno.ENOTDIR: "missing (a parent is not a directory)", errno.ENAMETOOLONG: "name too long"}


def file_problem(path: Path) -> str | None:
    """Why ``path`` is not a readable regular file (None when it is one)."""
    try:
        info = os.stat(path)
    except OSError as exc:
        if exc.errno == errno.ENOENT and os.path.islink(path):
            return "a broken symbolic link"
        return _REASONS.get(exc.errno, f"unreadable ({exc.strerror})")
    if stat.S_ISDIR(info.st_mode):
        return "is a directory, not a file"
    if not stat.S_ISREG(info.st_mode):
        return "not a regular file"
    if not os.access(path, os.R_OK):
        return "not readable (permission denied)"
    return None


def regular_file(path: Path, missing: str = "missing") -> Path:
    """``path`` if it is a readable regular file; else a RecordingError ``<path>: (file): <why>``.

    Parameters
    ----------
    path : Path
    missing : str
        The message for a missing file (callers add what a missing file means).
    """
    why = file_problem(path)
    if why is not None:
        raise RecordingError(str(path), "(file)", missing if why == "missing" else why)
    return Path(path)


def is_present(path: Path) -> bool:
    """Whether anything is at ``path`` (a file, a directory, or a link, even a broken one)."""
    return os.path.lexists(path)


def directory_present(path: Path) -> bool:
    """True for a directory, False when nothing is there; a file (or a loop) where a directory belongs is an error."""
    if not is_present(path):
        return False
    try:
        if stat.S_ISDIR(os.stat(path).st_mode):
            return True
    except OSError as exc:
        why = _REASONS.get(exc.errno, f"unreadable ({exc.strerror})")
        raise RecordingError(str(path), "(directory)", why) from None
    raise RecordingError(str(path), "(directory)", "not a directory")


def read_bytes(path: Path, missing: str = "missing", max_bytes: int | None = None) -> bytes:
    """The bytes of a regular file (errors as :func:`regular_file`), refusing one over ``max_bytes``."""
    regular_file(path, missing)
    try:
        size = os.stat(path).st_size
        if max_bytes is not None and size > max_bytes:
            raise RecordingError(str(path), "(file)", f"{size} bytes, more than the {max_bytes} such a file can hold")
        return Path(path).read_bytes()
    except OSError as exc:  # it changed under us, or the disk failed
        raise RecordingError(str(path), "(file)", _REASONS.get(exc.errno, f"unreadable ({exc.strerror})")) from None


def decode_utf8(data: bytes, path: Path) -> str:
    """``data`` as text; bytes that are not UTF-8 are an error naming their line and byte."""
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        raise RecordingError(str(path), f"line {line}",
                             f"not UTF-8 text (byte 0x{data[exc.start]:02x} at offset {exc.start})") from None

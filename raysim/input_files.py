"""Opening the files a scenario names, without ever hanging or crashing.

A path given by hand may be anything: a FIFO (opening it waits for a writer forever), a socket,
a device (``/dev/zero`` never ends), a directory, a symlink that leads back to itself, or a file
too large to hold. :func:`file_problem` says what is wrong with a path without opening it, and
:func:`read_file_bytes` opens with ``O_NONBLOCK`` (so a FIFO swapped in after the check cannot
block either), checks the type of what it opened with ``fstat`` and reads at most a bound.
Messages are one line; the callers raise :class:`raysim.errors.InputError` with them.
"""

from __future__ import annotations

import errno
import os
import stat
from pathlib import Path
from typing import BinaryIO

from raysim.errors import InputError

__all__ = ["MAX_CSV_FILE_BYTES", "MAX_MESH_FILE_BYTES", "file_problem", "path_check", "read_file_bytes",
           "read_text_file", "size_text"]

#: Largest mesh file read, bytes (trimesh holds it whole; 1 GB is some 20 million triangles).
MAX_MESH_FILE_BYTES = 1_000_000_000
#: Largest trajectory CSV read, bytes (a day at 100 Hz is about 500 MB).
MAX_CSV_FILE_BYTES = 500_000_000
#: Largest GeoJSON land file read, bytes (json holds it whole; OpenStreetMap's coast of Norway
#: clipped to a 50 km scene is a few MB).
MAX_LAND_FILE_BYTES = 200_000_000


def size_text(n_bytes: int) -> str:
    """``2.4 MB``, ``16 MB``, ``512 B``: decimal units, for messages."""
    for unit, size in (("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if n_bytes >= size:
            return f"{n_bytes / size:.3g} {unit}"
    return f"{n_bytes} B"


def _os_error_text(exc: OSError, path: Path) -> str:
    """What an ``OSError`` from stat or open means for the user, in one line."""
    if exc.errno == errno.ELOOP:
        return "symlink loop: the path's links lead back to themselves (too many levels of symbolic links)"
    if exc.errno == errno.ENOENT:
        if os.path.islink(path):
            return f"broken symlink: its target {os.readlink(path)} does not exist"
        return "file not found"
    if exc.errno == errno.ENOTDIR:
        return "file not found (a part of the path is a file, not a folder)"
    if exc.errno == errno.EACCES:
        return "permission denied"
    return f"cannot read: {exc.strerror or exc}"


def _mode_problem(mode: int, kind: str) -> str | None:
    """None for a regular file, else what the path is instead."""
    if stat.S_ISREG(mode):
        return None
    if stat.S_ISDIR(mode):
        return f"is a directory, not a {kind}"
    if stat.S_ISFIFO(mode):
        return f"is a FIFO (named pipe), not a {kind}: raysim reads whole files and would wait for a writer"
    if stat.S_ISSOCK(mode):
        return f"is a socket, not a {kind}"
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return f"is a device, not a {kind}"
    return f"is not a regular file, so not a {kind}"


def _open(path: Path, kind: str) -> tuple[BinaryIO | None, str | None]:
    """``(handle, None)`` for a regular file opened without blocking, else ``(None, what it is)``."""
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    except ValueError:  # a NUL byte in the path
        return None, "not a valid path"
    except OSError as exc:
        try:  # a socket (ENXIO) or a device without permission: say what the path is
            problem = _mode_problem(os.stat(path).st_mode, kind)
        except (OSError, ValueError):
            problem = None
        return None, problem or _os_error_text(exc, path)
    problem = _mode_problem(os.fstat(fd).st_mode, kind)
    if problem is not None:
        os.close(fd)
        return None, problem
    return os.fdopen(fd, "rb"), None


def file_problem(path: str | os.PathLike, kind: str = "file", max_bytes: int | None = None) -> str | None:
    """What keeps ``path`` from being read as a regular file, or None when nothing does.

    The path is opened without blocking (a FIFO is reported, not waited on), symlinks are followed
    (a loop is reported) and one byte is read (a file without read permission is reported).

    Parameters
    ----------
    path : str or os.PathLike
    kind : str
        What the file should be, for messages (``"mesh file"``).
    max_bytes : int, optional
        A larger file is reported too.
    """
    handle, problem = _open(Path(path), kind)
    if handle is None:
        return problem
    with handle:
        size = os.fstat(handle.fileno()).st_size
        if max_bytes is not None and size > max_bytes:
            return f"is {size_text(size)}; a {kind} may be at most {size_text(max_bytes)}"
        try:
            handle.read(1)
        except OSError as exc:
            return f"cannot read: {exc.strerror or exc}"
    return None


def read_file_bytes(path: str | os.PathLike, file: str, where: str, max_bytes: int, kind: str = "file") -> bytes:
    """The bytes of a regular file of at most ``max_bytes``, or an :class:`InputError`.

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    file, where : str
        File and place for the error (the file itself and ``"(file)"``, or the scenario and a key).
    max_bytes : int
        Larger files are refused before they are read.
    kind : str
        What the file should be, for messages.
    """
    handle, problem = _open(Path(path), kind)
    if handle is None:
        raise InputError(file, where, problem)
    with handle:
        size = os.fstat(handle.fileno()).st_size
        if size > max_bytes:
            raise InputError(file, where, f"is {size_text(size)}; a {kind} may be at most {size_text(max_bytes)}")
        try:
            data = handle.read(max_bytes + 1)
        except OSError as exc:
            raise InputError(file, where, f"cannot read: {exc.strerror or exc}") from None
    if len(data) > max_bytes:  # grew while being read
        raise InputError(file, where, f"a {kind} may be at most {size_text(max_bytes)}")
    return data


def read_text_file(path: str | os.PathLike, file: str, where: str, max_bytes: int, kind: str = "file") -> str:
    """:func:`read_file_bytes` decoded as UTF-8, line ends as ``Path.read_text`` gives them (``\\n``).

    Raises
    ------
    InputError
        Also ``(file, "byte N", "not a UTF-8 text file")`` for bytes that are not UTF-8.
    """
    data = read_file_bytes(path, file, where, max_bytes, kind)
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise InputError(file, f"byte {exc.start}", "not a UTF-8 text file") from None
    return text.replace("\r\n", "\n").replace("\r", "\n")


def path_check(kind: str, max_bytes: int):
    """A schema ``check`` for a path key: a regular, readable file of at most ``max_bytes``.

    Parameters
    ----------
    kind : str
        What the file should be, for messages (``"mesh file"``).
    max_bytes : int
        Largest file accepted.

    Returns
    -------
    callable
        ``check(path) -> message or None`` (:func:`raysim.schema.param`).
    """

    def check(value: Path) -> str | None:
        problem = file_problem(value, kind, max_bytes)
        if problem == "file not found":
            return f"file not found: {value}"
        return f"{value}: {problem}" if problem else None

    return check

"""Plain zip archives of stored members, read (in memory) and written without :mod:`zipfile`'s per-file machinery.

Sweep files are ``.npz`` archives whose members are all stored (uncompressed): how ``np.savez`` and
raysim write them. For such an archive, held whole in memory, :func:`stored_members` gives each
member's name, size, CRC-32 and where its data starts, from the end-of-central-directory record,
the central directory and each member's local header (PKWARE, APPNOTE.TXT 6.3.10, sections 4.3.7,
4.3.12 and 4.3.16). An archive of any other kind (compressed or encrypted members, zip64 records,
an archive comment, data before the archive, a directory or a local header that does not add up)
gives None, and the caller reads it with :mod:`zipfile`, which also says what is wrong with a
damaged one: the errors stay :mod:`zipfile`'s.

:func:`stored_archive` gives the bytes of such an archive as a list of buffers to write one after
another: the bytes :class:`zipfile.ZipFile` writes for the same members stored with ``writestr`` of a
:class:`zipfile.ZipInfo` (version 2.0 made and needed, made on Unix, the members' time, no extra
fields, no comments), with one CRC-32 pass over each member's data and no seeking back.
"""

from __future__ import annotations

import struct
import zlib
from dataclasses import dataclass
from typing import Sequence

__all__ = ["StoredMember", "stored_archive", "stored_members"]

#: End of central directory record (no comment): signature, disk numbers, entry counts, size and offset.
_END = struct.Struct("<4s4H2LH")
_END_SIGNATURE = b"PK\x05\x06"
#: Central directory file header (fixed part), and a local file header (fixed part).
_CENTRAL = struct.Struct("<4s4B4HL2L5H2L")
_CENTRAL_SIGNATURE = b"PK\x01\x02"
_LOCAL = struct.Struct("<4s2B4HL2L2H")
_LOCAL_SIGNATURE = b"PK\x03\x04"
#: General purpose flags that change how a member is read: encrypted (bit 0), sizes in a data descriptor (bit 3).
_FLAGS_NOT_PLAIN = 0x0001 | 0x0008
_STORED = 0
#: A 2- or 4-byte field at its maximum marks a zip64 value kept elsewhere.
_ZIP64_MARKS = (0xFFFF, 0xFFFFFFFF)
#: Version made by and needed to extract (2.0, as zipfile writes for stored members), and the system made on (Unix).
_VERSION = 20
_UNIX = 3
#: Largest member or archive written without zip64 records (zipfile's own threshold: 1.05 x size over 2 GiB - 1).
_PLAIN_MAX_BYTES = int((2**31 - 1) / 1.05)


@dataclass(frozen=True)
class StoredMember:
    """A stored member of an archive in memory.

    Attributes
    ----------
    filename : str
    file_size : int
        Bytes of its data (stored: as in the archive).
    CRC : int
        CRC-32 of its data, from the central directory.
    data_start : int
        Offset of its data in the archive's bytes.
    """

    filename: str
    file_size: int
    CRC: int
    data_start: int


def _end_record(data: bytes) -> tuple[int, int, int] | None:
    """(entries, directory size, directory offset) of a plain archive's end record, or None."""
    if len(data) < _END.size:
        return None
    signature, disk, dir_disk, here, entries, size, offset, comment = _END.unpack_from(data, len(data) - _END.size)
    if signature != _END_SIGNATURE or disk or dir_disk or comment or here != entries:
        return None
    if entries in _ZIP64_MARKS or size in _ZIP64_MARKS or offset in _ZIP64_MARKS:
        return None
    if offset + size != len(data) - _END.size:  # data before the archive, or a zip64 record: zipfile's
        return None
    return entries, size, offset


def _member(data: bytes, at: int, directory_offset: int) -> tuple[StoredMember, int] | None:
    """The member whose central directory entry starts at ``at``, and where the next entry starts."""
    if at + _CENTRAL.size > len(data) - _END.size:
        return None
    (signature, _, _, _, _, flags, method, _, _, crc, packed, size, name_len, extra_len, comment_len, _, _, _,
     header_at) = _CENTRAL.unpack_from(data, at)
    if (signature != _CENTRAL_SIGNATURE or flags & _FLAGS_NOT_PLAIN or method != _STORED or packed != size
            or size in _ZIP64_MARKS or header_at in _ZIP64_MARKS):
        return None
    name = data[at + _CENTRAL.size:at + _CENTRAL.size + name_len]
    if len(name) != name_len or header_at + _LOCAL.size > directory_offset:
        return None
    local = _LOCAL.unpack_from(data, header_at)
    local_name_len, local_extra_len = local[-2], local[-1]
    if local[0] != _LOCAL_SIGNATURE or data[header_at + _LOCAL.size:header_at + _LOCAL.size + local_name_len] != name:
        return None
    start = header_at + _LOCAL.size + local_name_len + local_extra_len
    if start + size > directory_offset or not name.isascii():
        return None
    return StoredMember(name.decode("ascii"), size, crc, start), at + _CENTRAL.size + name_len + extra_len + comment_len


def stored_members(data: bytes) -> list[StoredMember] | None:
    """The members of a plain archive of stored members held in ``data`` (module docstring), in
    directory order; None for any other archive (read it with :mod:`zipfile`)."""
    end = _end_record(data)
    if end is None:
        return None
    entries, size, offset = end
    members, at = [], offset
    for _ in range(entries):  # loop over directory entries (a sweep file has about ten)
        found = _member(data, at, offset)
        if found is None:
            return None
        member, at = found
        members.append(member)
    return members if at == offset + size else None


def stored_archive(members: Sequence[tuple[str, Sequence[memoryview | bytes]]], date_time: tuple[int, ...],
                   external_attr: int) -> list[memoryview | bytes]:
    """The bytes of a plain archive of stored members, as buffers to be written in order.

    Parameters
    ----------
    members : sequence of (str, sequence of buffer)
        Each member's name (ASCII) and its data in pieces (concatenated in the archive), in order.
    date_time : tuple of 6 int
        Every member's modification time (year from 1980, month, day, hour, minute, second).
    external_attr : int
        Every member's external attributes (Unix mode in the upper 16 bits).

    Returns
    -------
    list of buffer
        Local headers, data and central directory; the pieces are the callers' buffers, not copies.

    Raises
    ------
    ValueError
        A name that is not ASCII, or an archive too large for plain records (zip64 is not written).
    """
    y, mo, d, h, mi, sec = date_time
    dosdate, dostime = (y - 1980) << 9 | mo << 5 | d, h << 11 | mi << 5 | sec // 2
    out: list[memoryview | bytes] = []
    directory: list[bytes] = []
    offset = 0
    for name, pieces in members:
        if not name.isascii():
            raise ValueError(f"zip member name {name!r} is not ASCII")
        encoded = name.encode("ascii")
        size, crc = 0, 0
        for piece in pieces:
            crc = zlib.crc32(piece, crc)
            size += memoryview(piece).nbytes
        if size > _PLAIN_MAX_BYTES or offset > _PLAIN_MAX_BYTES:
            raise ValueError(f"zip member {name!r} or its offset is too large for a plain archive")
        out.append(_LOCAL.pack(_LOCAL_SIGNATURE, _VERSION, 0, 0, _STORED, dostime, dosdate, crc, size, size,
                               len(encoded), 0) + encoded)
        out.extend(pieces)
        directory.append(_CENTRAL.pack(_CENTRAL_SIGNATURE, _VERSION, _UNIX, _VERSION, 0, 0, _STORED, dostime, dosdate,
                                       crc, size, size, len(encoded), 0, 0, 0, 0, external_attr, offset) + encoded)
        offset += _LOCAL.size + len(encoded) + size
    central = b"".join(directory)
    end = _END.pack(_END_SIGNATURE, 0, 0, len(directory), len(directory), len(central), offset, 0)
    return out + [central + end]

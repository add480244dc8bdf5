"""The directory of a plain zip archive in memory, read without :mod:`zipfile`'s per-file machinery.

Sweep files are ``.npz`` archives whose members are all stored (uncompressed): how ``np.savez`` and
raysim write them. For such an archive, held whole in memory, :func:`stored_members` gives each
member's name, size, CRC-32 and where its data starts, from the end-of-central-directory record,
the central directory and each member's local header (PKWARE, APPNOTE.TXT 6.3.10, sections 4.3.7,
4.3.12 and 4.3.16). An archive of any other kind (compressed or encrypted members, zip64 records,
an archive comment, data before the archive, a directory or a local header that does not add up)
gives None, and the caller reads it with :mod:`zipfile`, which also says what is wrong with a
damaged one: the errors stay :mod:`zipfile`'s.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass

__all__ = ["StoredMember", "stored_members"]

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

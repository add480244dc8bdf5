"""The bag's MCAP file: zstd-compressed chunks with CRCs, written by the mcap library.

rosbags writes the rosbag2 directory (``metadata.yaml`` version 8 for Humble, connections, QoS),
but its own MCAP storage writes every chunk CRC as 0 and cannot set the compression. This module
plugs Foxglove's reference writer (the ``mcap`` package) in as rosbags' MCAP storage: chunks of
up to :data:`CHUNK_BYTES` compressed with zstd, the CRC-32 of every chunk, of the data section
and of the summary, a message index, statistics and summary offsets (MCAP specification,
mcap.dev/spec; ros2 profile: channel metadata ``offered_qos_profiles``). The rosbag2 metadata is
also stored in the file as the ``rosbag2`` metadata record, as rosbag2's own MCAP plugin does.
"""

from __future__ import annotations

from pathlib import Path

from raysim import __version__

__all__ = ["bag_writer", "McapStorage", "CHUNK_BYTES", "ZSTD_LEVEL"]

#: Uncompressed chunk size. A LiDAR revolution is about 1.5 MB: about 3 per chunk.
CHUNK_BYTES = 4 * 1024 * 1024
#: zstd level of the chunks: 1, what the MCAP C++ library (rosbag2's MCAP storage plugin) writes at its
#: ``CompressionLevel::Default`` (foxglove/mcap cpp/mcap/include/mcap/writer.inl, ``ZStdCompressionLevel``).
#: The Python mcap writer compresses at zstd's own default, 3: on busy_open_sea's bag level 1 compresses about
#: 2.3 times faster, to a file about 13 % larger (benchmarks/results/rosbag.md).
ZSTD_LEVEL = 1


class _Zstd:
    """What ``mcap.writer`` calls of the ``zstandard`` module (``compress``), at :data:`ZSTD_LEVEL`.

    The Python mcap writer has no compression level setting: it calls ``zstandard.compress(chunk)``,
    the module's function at zstd's default level. This stand-in for that module, installed in
    ``mcap.writer`` by :class:`McapStorage`, compresses the same chunks at :data:`ZSTD_LEVEL`; every
    MCAP file this process writes uses it (this package's bags are its only MCAP files).
    """

    def __init__(self, zstandard):
        self._zstandard = zstandard

    def compress(self, data: bytes) -> bytes:
        """The chunk compressed at :data:`ZSTD_LEVEL` (a fresh compressor: safe across threads)."""
        return self._zstandard.ZstdCompressor(level=ZSTD_LEVEL).compress(data)


def _compress_at_our_level() -> None:
    """Install :class:`_Zstd` as ``mcap.writer``'s ``zstandard`` (once; idempotent)."""
    import mcap.writer

    if not isinstance(mcap.writer.zstandard, _Zstd):
        import zstandard

        mcap.writer.zstandard = _Zstd(zstandard)


class McapStorage:
    """rosbags' storage-writer protocol over :class:`mcap.writer.Writer` (zstd chunks, CRCs on)."""

    def __init__(self, path: Path, compression) -> None:
        from mcap.writer import CompressionType, Writer

        del compression  # chunk compression is this storage's own (rosbags' STORAGE mode is not used)
        _compress_at_our_level()
        self.path = Path(path) / f"{Path(path).name}.mcap"
        self._stream = self.path.open("xb")
        self._writer = Writer(self._stream, chunk_size=CHUNK_BYTES, compression=CompressionType.ZSTD,
                              enable_crcs=True, enable_data_crcs=True)
        self._writer.start(profile="ros2", library=f"raysim {__version__}")
        self._schemas: dict[str, int] = {}
        self._channels: dict[int, int] = {}

    def add_msgtype(self, connection) -> None:
        """Register the connection's message type as a schema (its full ``.msg`` text)."""
        encoding = "ros2msg" if connection.msgdef.format.name == "MSG" else "ros2idl"
        self._schemas[connection.msgtype] = self._writer.register_schema(
            name=connection.msgtype, encoding=encoding, data=connection.msgdef.data.encode("utf-8"))

    def add_connection(self, connection, offered_qos_profiles: str) -> None:
        """Register a channel for the connection, with its offered QoS (YAML text, rosbag2's form)."""
        self._channels[connection.id] = self._writer.register_channel(
            topic=connection.topic, message_encoding=connection.ext.serialization_format,
            schema_id=self._schemas[connection.msgtype], metadata={"offered_qos_profiles": offered_qos_profiles})

    def write(self, connection, timestamp: int, data) -> None:
        """Append one serialized message; log and publish time are both ``timestamp`` (ns)."""
        self._writer.add_message(channel_id=self._channels[connection.id], log_time=timestamp,
                                 publish_time=timestamp, data=bytes(data))

    def close(self, version: int, metadata: str) -> None:
        """Write the rosbag2 metadata record, the summary and the footer."""
        del version
        self._writer.add_metadata("rosbag2", {"serialized_metadata": metadata})
        self._writer.finish()
        self._stream.close()

    def abort(self) -> None:
        """Close the file without a summary (the staged recording is removed anyway)."""
        self._stream.close()


def bag_writer(path: Path):
    """A rosbags rosbag2 writer (version 8, MCAP) whose storage is :class:`McapStorage`."""
    from rosbags.rosbag2 import StoragePlugin, Writer

    class _Writer(Writer):
        STORAGE_PLUGINS = {**Writer.STORAGE_PLUGINS, StoragePlugin.MCAP: McapStorage}

    return _Writer(path, version=8, storage_plugin=StoragePlugin.MCAP)


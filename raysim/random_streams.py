"""Named random streams from the scenario's one seed.

``stream(seed, "lidar.range_noise")`` is the child of ``np.random.SeedSequence(seed)``
whose spawn key is the CRC-32 of the name: the same name always gives the same
stream, and adding a component (a new name) never changes another one's numbers.
"""

from __future__ import annotations

import zlib

import numpy as np


def seed_sequence(seed: int, name: str) -> np.random.SeedSequence:
    """The SeedSequence of the stream ``name`` under the scenario seed ``seed``."""
    return np.random.SeedSequence(entropy=int(seed), spawn_key=(zlib.crc32(name.encode("utf-8")),))


def stream(seed: int, name: str) -> np.random.Generator:
    """A fresh PCG64 generator for the stream ``name`` under ``seed``."""
    return np.random.Generator(np.random.PCG64(seed_sequence(seed, name)))


def chunk_stream(seed: int, name: str, index: int) -> np.random.Generator:
    """A fresh PCG64 generator for piece ``index`` of the stream ``name`` (spawn key: the name's CRC-32, index).

    A renderer that draws its numbers a piece (a LiDAR revolution-chunk) at a time from its own
    generator per piece can render any piece without the ones before it, and so in any process.
    """
    sequence = np.random.SeedSequence(entropy=int(seed), spawn_key=(zlib.crc32(name.encode("utf-8")), int(index)))
    return np.random.Generator(np.random.PCG64(sequence))

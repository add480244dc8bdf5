"""raysim.sensors.lidar_run: a LiDAR run rendered in two parts is the same recording as one rendered whole."""

from __future__ import annotations

import dataclasses
import hashlib
import multiprocessing
from pathlib import Path

import numpy as np
import pytest

from raysim.materials import material_index
from raysim.scenario import load_scenario, with_overrides
from raysim.sensors.carrier import CarrierScene
from raysim.sensors.lidar import LidarRenderer
from raysim.sensors.lidar_run import (CHUNKS_IN_FLIGHT, ChunkClaims, ChunkWriter, MIN_CHUNKS_TO_SHARE, join_pcap_parts,
                                     render_chunks)
from raysim.world import World

ROOT = Path(__file__).resolve().parents[2]


def _renderer(duration_s: float, **lidar) -> LidarRenderer:
    s = load_scenario(ROOT / "scenarios" / "busy_open_sea.yaml")
    if lidar:
        s = dataclasses.replace(s, sensors=dataclasses.replace(s.sensors, lidar=dataclasses.replace(s.sensors.lidar, **lidar)))
    s = with_overrides(s, duration_s=duration_s, sensors=("lidar",))
    world = World(s)
    return LidarRenderer(world, CarrierScene(world.scene_objects(), sea_material=material_index("sea")))


def _digests(root: Path) -> dict[str, str]:
    return {str(p.relative_to(root)): hashlib.md5(p.read_bytes()).hexdigest() for p in sorted(root.rglob("*")) if p.is_file()}


@pytest.fixture(scope="module")
def whole(tmp_path_factory):
    """busy_open_sea, 1.05 s (11 chunks, the last one short), rendered in one go."""
    out = tmp_path_factory.mktemp("whole")
    counts = render_chunks(_renderer(1.05), out)
    return out, counts


@pytest.mark.parametrize("split", [1, 5, 10])
def test_two_parts_are_the_whole_run(whole, tmp_path, split):
    out, counts = whole
    renderer = _renderer(1.05)
    assert renderer.n_chunks == 11
    early = render_chunks(renderer, tmp_path, end=split)
    late = render_chunks(_renderer(1.05), tmp_path, first=split)
    assert list((tmp_path / "lidar").glob(".hdl32e.pcap.part-*"))
    join_pcap_parts(tmp_path / "lidar")
    assert _digests(tmp_path) == _digests(out)  # every packet, position packet, sweep byte
    assert {k: early[k] + late[k] for k in counts} == counts
    assert counts["sweeps"] == 10 and counts["position_packets"] == 2


def test_a_chunk_does_not_depend_on_the_chunks_before_it():
    """Chunk 7 rendered alone is chunk 7 of the whole run (its noise is its own), and the noise is real."""
    all_chunks = list(_renderer(1.0).chunks())
    alone = next(_renderer(1.0).chunks(first=7))
    assert alone.payloads.tobytes() == all_chunks[7].payloads.tobytes()
    # two chunks' noise streams differ: the same geometry would give different millimetres
    assert not np.array_equal(all_chunks[6].firings.distance_units, all_chunks[7].firings.distance_units)


def test_dual_returns_in_two_parts(tmp_path):
    one, two = tmp_path / "one", tmp_path / "two"
    render_chunks(_renderer(0.6, return_mode="dual"), one)
    render_chunks(_renderer(0.6, return_mode="dual"), two, end=3)
    render_chunks(_renderer(0.6, return_mode="dual"), two, first=3)
    join_pcap_parts(two / "lidar")
    assert _digests(one) == _digests(two)


def test_claims_split_what_is_left():
    claims = ChunkClaims.make(multiprocessing.get_context("spawn"))
    assert all(claims.claim(i) for i in range(10))  # the second process has rendered chunks 0-9
    assert claims.take_later_half(30) == (20, 30)  # 20 left: this process takes the later 10
    assert claims.claim(19) and not claims.claim(20)  # and the second process stops before them
    late = ChunkClaims.make(multiprocessing.get_context("spawn"))
    for i in range(30 - MIN_CHUNKS_TO_SHARE + 1):
        late.claim(i)
    assert late.take_later_half(30) == (30, 30)  # too few left to share: all the second process's


# ------------------------------------------------------------------ the writer thread


def test_writer_takes_chunks_in_order_and_at_most_two_wait():
    import threading
    import time

    written, waiting = [], []
    gate = threading.Event()

    def write(chunk):
        gate.wait(5)
        written.append(chunk)

    writer = ChunkWriter(write)
    with writer:
        for i in range(CHUNKS_IN_FLIGHT):
            writer.put(i)
        waiting.append(len(writer._pending))
        blocked = threading.Thread(target=writer.put, args=(CHUNKS_IN_FLIGHT,))
        blocked.start()
        time.sleep(0.2)
        assert blocked.is_alive()  # a third chunk waits for the first to be written
        gate.set()
        blocked.join(5)
        for i in range(CHUNKS_IN_FLIGHT + 1, 10):
            writer.put(i)
    assert written == list(range(10))
    assert waiting == [CHUNKS_IN_FLIGHT]


def test_a_writer_fault_reaches_the_render():
    def write(chunk):
        if chunk == 3:
            raise OSError(28, "No space left on device")

    with pytest.raises(OSError, match="No space left"):
        with ChunkWriter(write) as writer:
            for i in range(10):
                writer.put(i)


def test_a_fault_while_rendering_stops_the_writer():
    written = []

    def write(chunk):
        written.append(chunk)

    with pytest.raises(KeyboardInterrupt):
        with ChunkWriter(write) as writer:
            for i in range(5):
                writer.put(i)
            raise KeyboardInterrupt
    assert written == list(range(len(written))) and len(written) <= 5
    assert writer._pool._shutdown


def test_the_writer_thread_changes_no_byte(whole, tmp_path, monkeypatch):
    """The same run with each chunk written at once, on the render's own thread, gives the same files and counts."""
    import raysim.sensors.lidar_run as lidar_run

    class AtOnce:
        def __init__(self, write):
            self.put = write

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            return None

    monkeypatch.setattr(lidar_run, "ChunkWriter", AtOnce)
    out, counts = whole
    assert render_chunks(_renderer(1.05), tmp_path) == counts
    assert _digests(tmp_path / "lidar") == _digests(out / "lidar")


# ------------------------------------------------------------------ the cast on a second thread


def test_chunks_cast_ahead_are_the_chunks_measured_one_by_one():
    """chunks() casts a chunk while it measures the one before: the same firings as measure() chunk by chunk."""
    from raysim.random_streams import chunk_stream

    piped, plain = _renderer(0.55), _renderer(0.55)
    seed = plain.world.scenario.seed
    chunks = list(piped.chunks())
    assert len(chunks) == plain.n_chunks == 6 and len(piped.chunk_wall_s) == 6
    for index, chunk in enumerate(chunks):
        t, block_az, firing_az = plain._chunk_firings(index)
        plain.noise_rng = chunk_stream(seed, "lidar.range_noise", index)
        plain.weather_rng = chunk_stream(seed, "lidar.weather", index)
        fire = plain.measure(t, block_az, firing_az)
        assert np.array_equal(chunk.time_s, t)
        for name in ("distance_units", "reflectivity", "object_id", "source"):
            assert np.array_equal(getattr(chunk.firings, name), getattr(fire, name)), name
        assert chunk.payloads.tobytes() == plain.packets(fire).tobytes()


def test_a_fault_in_the_cast_ahead_reaches_the_render(monkeypatch):
    renderer = _renderer(0.55)
    cast_stage = renderer._cast_stage
    calls = []

    def failing(t, firing_az):
        calls.append(t[0])
        if len(calls) == 3:
            raise MemoryError("cast 3")
        return cast_stage(t, firing_az)

    monkeypatch.setattr(renderer, "_cast_stage", failing)
    seen = []
    with pytest.raises(MemoryError, match="cast 3"):
        for chunk in renderer.chunks():
            seen.append(chunk)
    assert len(seen) == 2  # the chunks before the failed cast, and nothing after it


def test_chunks_without_the_cast_ahead_are_the_same_and_cast_only_when_due(monkeypatch):
    """cast_ahead=False (live mode with a fed own ship): the same chunks, and no chunk is cast before the one
    before it has been handed on."""
    piped, due = _renderer(0.35), _renderer(0.35)
    events = []
    cast_stage = due._cast_stage

    def logged(t, firing_az):
        events.append(("cast", round(float(t[0]), 6)))
        return cast_stage(t, firing_az)

    monkeypatch.setattr(due, "_cast_stage", logged)
    got = []
    for chunk in due.chunks(cast_ahead=False):
        events.append(("yield", round(float(chunk.time_s[0]), 6)))
        got.append(chunk)
    assert [e[0] for e in events] == ["cast", "yield"] * len(got) and len(got) == 4
    for a, b in zip(piped.chunks(), got):
        assert a.payloads.tobytes() == b.payloads.tobytes()


def test_after_a_writer_fault_the_chunks_behind_it_are_not_written():
    import threading

    written, gate = [], threading.Event()

    def write(chunk):
        gate.wait(5)
        if chunk == 1:
            raise OSError(28, "No space left on device")
        written.append(chunk)

    with pytest.raises(OSError):
        with ChunkWriter(write) as writer:
            writer.put(0)
            writer.put(1)
            gate.set()
            for i in range(2, 6):
                writer.put(i)
    assert written == [0]

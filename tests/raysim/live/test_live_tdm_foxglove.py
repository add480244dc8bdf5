"""raysim live --targets-port and --foxglove: the TDM on the live data, and the session on a Foxglove server."""

from __future__ import annotations

import asyncio
import json
import socket
import struct
import threading
import time

import pytest

from raysim.cli import main
from tests.raysim.helpers import tiny_scenario
from tests.raysim.live.receivers import Receiver

DURATION_S = 6.0


def free_tcp_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class FoxgloveClient(threading.Thread):
    """A Foxglove WebSocket client (subprotocol foxglove.sdk.v1, the SDK's): takes the server's channels, subscribes to all, counts messages."""

    def __init__(self, port: int):
        super().__init__(daemon=True)
        self.port = port
        self.channels: dict[int, str] = {}
        self.messages: dict[str, int] = {}
        self.stop = threading.Event()

    def run(self) -> None:
        asyncio.run(self._session())

    async def _session(self) -> None:
        from tornado.websocket import websocket_connect

        deadline = time.monotonic() + 60.0
        conn = None
        while conn is None and time.monotonic() < deadline and not self.stop.is_set():
            try:
                conn = await websocket_connect(f"ws://127.0.0.1:{self.port}", subprotocols=["foxglove.sdk.v1"])
            except OSError:
                await asyncio.sleep(0.1)
        subscribed = set()
        while conn is not None and not self.stop.is_set():
            try:
                msg = await asyncio.wait_for(conn.read_message(), timeout=0.2)
            except asyncio.TimeoutError:
                continue
            if msg is None:
                break
            if isinstance(msg, str):
                body = json.loads(msg)
                if body.get("op") == "advertise":
                    new = [c for c in body["channels"] if c["id"] not in subscribed]
                    self.channels.update({c["id"]: c["topic"] for c in new})
                    subscribed.update(c["id"] for c in new)
                    conn.write_message(json.dumps({"op": "subscribe", "subscriptions": [
                        {"id": c["id"], "channelId": c["id"]} for c in new]}))
            elif msg[0] == 0x01:  # message data: opcode, subscription id (= channel id here), time, payload
                topic = self.channels.get(struct.unpack_from("<I", msg, 1)[0], "?")
                self.messages[topic] = self.messages.get(topic, 0) + 1
        if conn is not None:
            conn.close()


def test_the_live_tdm_sends_targets_and_foxglove_shows_the_session(tmp_path):
    path = tiny_scenario(tmp_path / "tiny")
    targets = Receiver()
    fox_port = free_tcp_port()
    client = FoxgloveClient(fox_port)
    client.start()
    try:
        code = main(["live", str(path), "--duration", str(DURATION_S), "--lidar-port", "0", "--lidar-position-port", "0",
                     "--radar-port", "0", "--ais-port", "0", "--nav-port", "0", "--targets-port", str(targets.port),
                     "--foxglove", str(fox_port)])
    finally:
        targets.close()
        client.stop.set()
        client.join(timeout=5.0)
    assert code == 0
    records = [json.loads(p) for p in targets.payloads]
    assert records, "the live TDM sent no detected target"
    keys = {"t", "target_id", "object_descriptor", "longitude", "latitude", "cog_deg", "sog_mps", "sources"}
    assert all(keys <= set(r) for r in records)
    assert all(0.0 < r["t"] <= DURATION_S for r in records)
    assert {"lidar"} <= {s for r in records for s in r["sources"]}  # the berg at 60 m, from the live sweeps
    topics = set(client.channels.values())
    assert {"/lidar/points", "/radar/image/compressed", "/truth/objects", "/ownship/fix", "/tdm/markers", "/tf"} <= topics
    for topic in ("/lidar/points", "/ownship/fix", "/truth/objects", "/tdm/markers", "/tf"):
        assert client.messages.get(topic, 0) >= 1, topic


@pytest.mark.parametrize("flag, value", [("--targets-port", "70000"), ("--speed", "0"), ("--ownship-in", "x")])
def test_a_bad_argument_is_one_line_and_exit_2(tmp_path, capsys, flag, value):
    assert main(["live", str(tiny_scenario(tmp_path / "tiny")), flag, value]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and value in err[0]


def test_a_record_directory_that_is_no_recording_is_refused_before_the_session(tmp_path, capsys):
    other = tmp_path / "other"
    other.mkdir()
    (other / "notes.txt").write_text("mine\n")
    started = time.perf_counter()
    assert main(["live", str(tiny_scenario(tmp_path / "tiny")), "--duration", "120", "--record", str(other)]) == 2
    assert time.perf_counter() - started < 30.0  # no 120 s session first (a wide margin: machines differ in speed)
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--record" in err[0] and "no raysim recording" in err[0]
    assert sorted(p.name for p in other.iterdir()) == ["notes.txt"]

"""UDP receivers on 127.0.0.1 for the live tests: every datagram with its arrival time."""

from __future__ import annotations

import socket
import threading
import time


class Receiver:
    """Collects the datagrams sent to a free port of 127.0.0.1 until :meth:`close` (a bounded loop)."""

    def __init__(self):
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 24)
        self.sock.bind(("127.0.0.1", 0))
        self.sock.settimeout(0.1)
        self.port = self.sock.getsockname()[1]
        self.datagrams: list[tuple[float, bytes]] = []
        self._stop = threading.Event()
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _run(self) -> None:
        while not self._stop.is_set():
            try:
                data = self.sock.recv(65535)
            except socket.timeout:
                continue
            self.datagrams.append((time.perf_counter(), data))

    def close(self) -> None:
        time.sleep(0.2)  # the last datagrams in flight
        self._stop.set()
        self.thread.join(timeout=2.0)
        self.sock.close()

    @property
    def payloads(self) -> list[bytes]:
        return [d for _, d in self.datagrams]

    @property
    def times(self) -> list[float]:
        return [t for t, _ in self.datagrams]

"""Live mode's timing: every sensor of busy_open_sea on 127.0.0.1 for ten minutes (issue 21).

Usage::

    python benchmarks/live.py [--quick] [--duration-s 600] [--out benchmarks/results/live.md]

``raysim live``'s session (:func:`raysim.live.session.run_live`) sends the LiDAR's data and position
packets, the radar's Navico spoke frames, AIS and the own ship's NMEA to ports of 127.0.0.1 where
this script's receivers count them. Per stream: payloads sent and received (none may be lost), and
each payload's lateness against its schedule (wall time of sending minus its scenario time on the
session's clock): median, p99 and max. Asked: none lost, p99 under 5 ms the aim.
"""

from __future__ import annotations

import argparse
import os
import socket
import sys
import threading
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks.common import machine_line, publish  # noqa: E402
from raysim.live.session import LivePorts, run_live  # noqa: E402
from raysim.scenario import load_scenario, with_overrides  # noqa: E402

SCENARIO = ROOT / "scenarios" / "busy_open_sea.yaml"
STREAMS = ("lidar", "lidar_position", "radar", "ais", "nav")


class Counter:
    """Counts the datagrams arriving at a free port of 127.0.0.1 (a bounded loop: 0.1 s timeouts)."""

    def __init__(self):
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 24)
        self.sock.bind(("127.0.0.1", 0))
        self.sock.settimeout(0.1)
        self.port = self.sock.getsockname()[1]
        self.count = 0
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _run(self) -> None:
        while not self.stop.is_set():
            try:
                self.sock.recv(65535)
            except socket.timeout:
                continue
            self.count += 1

    def close(self) -> None:
        self.stop.set()
        self.thread.join(timeout=2.0)
        self.sock.close()


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="60 s instead of 600 s")
    parser.add_argument("--duration-s", type=float, default=600.0)
    parser.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results" / "live.md")
    parser.add_argument("--json", type=Path)
    args = parser.parse_args(argv)
    duration = 60.0 if args.quick else args.duration_s
    rx = {name: Counter() for name in STREAMS}
    ports = LivePorts("127.0.0.1", rx["lidar"].port, rx["lidar_position"].port, rx["radar"].port, rx["ais"].port,
                      rx["nav"].port)
    before = os.times()
    try:
        result, _ = run_live(with_overrides(load_scenario(SCENARIO), duration_s=duration), ports)
    finally:
        threading.Event().wait(0.5)  # the last datagrams in flight
        for r in rx.values():
            r.close()
    after = os.times()
    own_cpu_s = (after.user - before.user) + (after.system - before.system)  # renderers, readers, receivers
    child_cpu_s = (after.children_user - before.children_user) + (after.children_system - before.children_system)
    rows, figures = [("send process scheduling", result.scheduling)], {"duration_s": duration, "reached_s": result.reached_s,
                                                                       "scheduling": result.scheduling,
                                                                       "cpu_s_per_scenario_s": own_cpu_s / duration,
                                                                       "send_cpu_s_per_scenario_s": child_cpu_s / duration}
    rows.append(("CPU per scenario second: this process (renderers, receivers) / the send process, s",
                 f"{own_cpu_s / duration:.3f} / {child_cpu_s / duration:.3f}"))
    for name in STREAMS:
        s = result.streams.get(name, {"sent": 0, "late": 0, "median_ms": 0.0, "p99_ms": 0.0, "max_ms": 0.0})
        lost = s["sent"] - rx[name].count
        figures[name] = dict(s, received=rx[name].count, lost=lost)
        rows.append((f"{name}: sent / received / lost", f"{s['sent']:,} / {rx[name].count:,} / {lost}"))
        rows.append((f"{name}: lateness median / p99 / max, ms",
                     f"{s['median_ms']:.2f} / {s['p99_ms']:.2f} / {s['max_ms']:.2f}"))
        rows.append((f"{name}: late by over 10 ms", f"{s['late']:,}"))
    intro = [machine_line("live", args.quick), "",
             f"`raysim live scenarios/busy_open_sea.yaml` for {duration:g} s at 1x real time, every sensor on, to "
             "receivers on 127.0.0.1 in the same process; lateness = wall time of sending minus the payload's "
             "time on the session's clock. Asked (issue 21): none lost; p99 under 5 ms the aim. CPU per scenario "
             "second: user + system time over the session (`os.times`), this process's (the renderers and the "
             "receivers here) and the send process's; at 1x real time, under 1 s per second in this process means "
             "the renderers keep up with room to spare."]
    publish("Live mode timing", intro, rows, args.out, args.json, figures)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

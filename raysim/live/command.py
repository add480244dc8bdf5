"""``raysim live``: its arguments and what it prints (docs/live.md)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path


__all__ = ["add_live_parser", "cmd_live", "live_counts"]


def _bounded(kind, lo, hi, what: str):
    """An argparse type: ``kind(text)`` within [lo, hi], else an error naming ``what``."""
    def parse(text: str):
        try:
            value = kind(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"not a {what}: {text!r}") from None
        if not lo <= value <= hi:
            raise argparse.ArgumentTypeError(f"{what} {value:g} is outside {lo:g}..{hi:g}")
        return value
    return parse


_port = _bounded(int, 0, 65535, "port")
_speed = _bounded(float, 0.01, 100.0, "--speed value")


def add_live_parser(sub, duration_type, seed_type) -> None:
    """The ``live`` subcommand's arguments (the command contract of issue 21)."""
    p = sub.add_parser("live", help="send the sensors' packets on the network in real time (docs/live.md)")
    p.add_argument("scenario", type=Path, help="scenario YAML file")
    p.add_argument("--duration", type=duration_type, help="override duration_s")
    p.add_argument("--seed", type=seed_type, help="override the seed")
    p.add_argument("--speed", type=_speed, default=1.0, help="multiple of real time (default 1)")
    p.add_argument("--dest", default="127.0.0.1", help="destination host of the UDP streams (default 127.0.0.1)")
    for name, default, what in (("lidar-port", 2368, "HDL-32E data packets"),
                                ("lidar-position-port", 8308, "HDL-32E position packets"),
                                ("radar-port", 6678, "Navico Broadband spokes"),
                                ("ais-port", 10110, "!AIVDM lines"),
                                ("nav-port", 10111, "own-ship GGA, RMC, HDT, VTG, ZDA"),
                                ("targets-port", 0, "the live TDM's detected targets as JSON lines")):
        p.add_argument(f"--{name}", type=_port, default=default, help=f"{what}; 0 = off (default {default})")
    p.add_argument("--radar-multicast", action="store_true", help="spokes to 236.6.7.8:6678 as the real set sends")
    p.add_argument("--ownship-in", type=_port, help="listen on 127.0.0.1:PORT for the own ship's NMEA")
    p.add_argument("--foxglove", type=_port, help="serve the session to Foxglove on 127.0.0.1:PORT (WebSocket)")
    p.add_argument("--record", type=Path, help="write the usual recording directory of the session")
    p.add_argument("--no-progress", action="store_true", help="no progress while the record is written")


def live_counts(streams: dict) -> dict[str, int]:
    """Manifest counts of a session: per stream payloads sent, late ones, p99 and max lateness in microseconds."""
    out = {}
    for name, s in streams.items():
        out[f"live/{name}/sent"] = s["sent"]
        out[f"live/{name}/late"] = s["late"]
        out[f"live/{name}/p99_us"] = int(round(s["p99_ms"] * 1000))
        out[f"live/{name}/max_us"] = int(round(s["max_ms"] * 1000))
    return out


def cmd_live(args, load) -> int:
    """Run a live session; print what each stream sent and how late; write the record if asked."""
    from raysim.live.session import LivePorts, run_live
    from raysim.scenario import with_overrides

    scenario = load(args)
    if args.record is not None:  # refused before the session, not after it
        from raysim.recording.staging import check_output_dir

        check_output_dir(args.record, "--record")
    ports = LivePorts(args.dest, args.lidar_port, args.lidar_position_port, args.radar_port, args.ais_port,
                      args.nav_port, args.radar_multicast, args.targets_port, args.foxglove)
    print(f"live: {scenario.name}, {scenario.duration_s:g} s at {args.speed:g}x real time, to {args.dest}",
          file=sys.stderr)
    result, world = run_live(scenario, ports, args.speed, args.ownship_in)
    for name, s in result.streams.items():
        print(f"live: {name}: {s['sent']} sent, {s['late']} late (over 10 ms); lateness median {s['median_ms']:.2f} ms, "
              f"p99 {s['p99_ms']:.2f} ms, max {s['max_ms']:.2f} ms")
    print(f"live: send process scheduling: {result.scheduling}" + ("" if result.scheduling == "SCHED_RR" else
          " (real-time scheduling needs root or CAP_SYS_NICE; lateness is higher without it)"))
    ended = "interrupted" if result.interrupted else "done"
    print(f"live: {ended} at t = {result.reached_s:.1f} s" +
          (f"; own-ship feed went stale {result.stale_events} times" if result.stale_events else ""))
    if args.record is not None:
        from raysim.render import render

        duration = scenario.duration_s if not result.interrupted else max(0.1, round(result.reached_s, 1))
        fed = world.own_ship.motion if args.ownship_in is not None else None
        counts = live_counts(result.streams)
        render(with_overrides(scenario, duration_s=duration), args.record, progress=False if args.no_progress else None,
               own_ship_motion=fed, extra_counts=counts)
        print(f"live: recording in {args.record}")
    return 0

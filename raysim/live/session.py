"""One live session: the scenario's sensors on the network, paced by the wall clock (docs/live.md).

:func:`run_live` builds the world (the own ship fed from outside if asked), starts a producer per
stream, waits until every stream's first batch is rendered, then sends on the wall clock until the
duration is over, Ctrl-C or SIGTERM. It returns what was sent and how late, for the console and for
the recording's manifest (``--record``).
"""

from __future__ import annotations

import socket
import sys
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

from raysim.live.navico import RADAR_MULTICAST
from raysim.live.sender import LiveStream, Lateness, Producer, send_streams
from raysim.live.streams import ais_batches, lidar_data_batches, lidar_position_batches, nav_batches, radar_batches
from raysim.scenario import Scenario
from raysim.world import World

__all__ = ["LivePorts", "LiveResult", "run_live", "PREROLL_TIMEOUT_S"]

#: Longest wait for the first batch of every stream before the clock starts, s.
PREROLL_TIMEOUT_S = 120.0
#: A producer for a fed own ship renders no further than this ahead of the clock, s.
FED_LEAD_S = 0.5
#: The interpreter's thread switch interval during a session, s (default 5 ms): the send loop gets the
#: interpreter back from the rendering threads this soon.
SWITCH_INTERVAL_S = 0.0005
#: Multicast TTL of the radar's spokes (1: this network segment only).
MULTICAST_TTL = 1


@dataclass
class LivePorts:
    """UDP destination ports (0: stream off) and the destination host."""

    dest: str = "127.0.0.1"
    lidar: int = 2368
    lidar_position: int = 8308
    radar: int = 6678
    ais: int = 10110
    nav: int = 10111
    radar_multicast: bool = False


@dataclass
class LiveResult:
    """What a session sent: the scenario time reached, s, and each stream's lateness summary."""

    reached_s: float
    interrupted: bool
    streams: dict = field(default_factory=dict)
    stale_events: int = 0


def _streams(world: World, scene_factory, ports: LivePorts, stop: threading.Event, ready_before) -> list[LiveStream]:
    """A LiveStream per enabled sensor whose port is not 0."""
    s = world.scenario
    enabled = set(s.sensors.enabled_names())
    out: list[tuple[str, tuple[str, int], object]] = []
    if "lidar" in enabled and (ports.lidar or ports.lidar_position):
        from raysim.sensors.lidar import LidarRenderer

        lidar = LidarRenderer(world, scene_factory())  # the position packets only read the own ship's pose
        if ports.lidar:
            out.append(("lidar", (ports.dest, ports.lidar), lidar_data_batches(lidar)))
        if ports.lidar_position:
            out.append(("lidar_position", (ports.dest, ports.lidar_position), lidar_position_batches(lidar)))
    if "radar" in enabled and ports.radar:
        from raysim.sensors.radar import RadarRenderer

        address = RADAR_MULTICAST if ports.radar_multicast else (ports.dest, ports.radar)
        out.append(("radar", address, radar_batches(RadarRenderer(world, scene_factory()))))
    if "ais" in enabled and ports.ais:
        out.append(("ais", (ports.dest, ports.ais), ais_batches(world)))
    if "nav" in enabled and ports.nav:
        out.append(("nav", (ports.dest, ports.nav), nav_batches(world)))
    return [LiveStream(name, address, Producer(name, batches, stop, ready_before)) for name, address, batches in out]


def _scene_factory(world: World):
    cache = {}

    def scene():
        if "scene" not in cache:
            from raysim.materials import material_index
            from raysim.sensors.carrier import CarrierScene

            cache["scene"] = CarrierScene(world.scene_objects(), carrier_id=world.own_ship.object_id,
                                          sea_material=material_index("sea"))
        return cache["scene"]

    return scene


def run_live(scenario: Scenario, ports: LivePorts, speed: float = 1.0, ownship_port: int | None = None,
             log=sys.stderr) -> tuple[LiveResult, World]:
    """Run one live session (module docstring); returns its result and the world it rendered.

    Parameters
    ----------
    scenario : Scenario
        Resolved scenario (duration and seed overrides applied).
    ports : LivePorts
    speed : float
        Multiple of real time.
    ownship_port : int, optional
        Listen on 127.0.0.1:port for the own ship's NMEA (GGA, HDT, VTG, PSXN,23).
    """
    world = World(scenario)
    clock = {"start": None}

    def scenario_clock() -> float:
        return 0.0 if clock["start"] is None else (time.perf_counter() - clock["start"]) * speed

    feed = None
    ready_before = None
    stop = threading.Event()
    if ownship_port is not None:
        from raysim.live.ownship_in import FedMotion, OwnShipFeed

        feed = OwnShipFeed(ownship_port, world.frame, scenario_clock)
        world.drive_own_ship(FedMotion(feed, world.own_ship.motion))

        def ready_before(t_s: float) -> None:  # render no further ahead than the fed pose can be extrapolated
            while not stop.is_set() and scenario_clock() < t_s - FED_LEAD_S:
                time.sleep(0.01)

    streams = _streams(world, _scene_factory(world), ports, stop, ready_before)
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    if ports.radar_multicast:
        sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, MULTICAST_TTL)
    lateness = Lateness()
    interrupted = False
    reached = 0.0
    switch_interval = sys.getswitchinterval()
    sys.setswitchinterval(SWITCH_INTERVAL_S)
    try:
        for s in streams:
            s.producer.start()
        _preroll(streams, stop)
        clock["start"] = time.perf_counter()
        reached = send_streams(streams, sock, clock["start"], speed, scenario.duration_s, lateness, stop, log)
    except KeyboardInterrupt:
        interrupted = True
        reached = scenario_clock()
    finally:
        sys.setswitchinterval(switch_interval)
        stop.set()
        for s in streams:
            s.producer.join(timeout=5.0)
        sock.close()
        if feed is not None:
            feed.close()
    stale = getattr(feed, "stale_events", 0) if feed is not None else 0
    return LiveResult(reached, interrupted, lateness.summary(), stale), world


def _preroll(streams: list[LiveStream], stop: threading.Event) -> None:
    """Wait until every stream has its first batch (or is over): the clock starts with all of them ready."""
    deadline = time.perf_counter() + PREROLL_TIMEOUT_S
    while not stop.is_set() and time.perf_counter() < deadline:
        if all(s.next_time() is not None or s.finished for s in streams):
            return
        time.sleep(0.01)
    if not stop.is_set():
        raise RuntimeError(f"live: streams not ready after {PREROLL_TIMEOUT_S:g} s")

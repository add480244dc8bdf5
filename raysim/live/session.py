"""One live session: the scenario's sensors on the network, paced by the wall clock (docs/live.md).

:func:`run_live` builds the world (the own ship fed from outside if asked), starts a producer per
stream, waits until every stream's first batch is rendered, then sends on the wall clock until the
duration is over, Ctrl-C or SIGTERM. It returns what was sent and how late, for the console and for
the recording's manifest (``--record``).
"""

from __future__ import annotations

import json
import multiprocessing
import queue
import sys
import tempfile
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

from raysim.live.navico import BEACON_ADDRESS, RADAR_MULTICAST, REPORT_ADDRESS, beacon, status_report
from raysim.live.sender import QUEUE_DEPTH, Producer
from raysim.live.wire import summary, wire_main
from raysim.live.streams import (ais_batches, announcements, lidar_data_batches, lidar_position_batches, nav_batches,
                                 radar_batches)
from raysim.scenario import Scenario
from raysim.world import World

__all__ = ["LivePorts", "LiveResult", "run_live", "PREROLL_TIMEOUT_S"]

#: Longest wait for the send process to start the clock, s (its own preroll is 120 s).
PREROLL_TIMEOUT_S = 150.0
#: A producer for a fed own ship renders no further than this ahead of the clock, s (a radar sector renders
#: in about 0.15 s, a LiDAR chunk in a few tens of ms).
FED_LEAD_S = 0.3
#: Sectors of a radar revolution rendered anew for a fed own ship (24 rpm: 0.5 s each): a sector's last spoke
#: is then at most FED_LEAD_S + 0.5 s ahead of the clock, inside the fed pose's 1 s of extrapolation.
FED_RADAR_SECTORS = 5
#: Longest wait for the send process's results after the end, s.
RESULTS_TIMEOUT_S = 30.0


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
    targets: int = 0
    foxglove: int | None = None


@dataclass
class LiveResult:
    """What a session sent: the scenario time reached, s, and each stream's lateness summary."""

    reached_s: float
    interrupted: bool
    streams: dict = field(default_factory=dict)
    stale_events: int = 0
    scheduling: str = ""  # what the send process got from the scheduler (raysim.live.wire)


def _streams(world: World, scene_factory, ports: LivePorts, stop, working: Path | None,
             on_targets=None, fed=None) -> list[tuple[dict, object]]:
    """Per enabled sensor whose port is not 0 (and the TDM's, with a working recording): its wire
    description (:class:`raysim.live.wire.WireStream`'s fields) and its batch generator."""
    s = world.scenario
    enabled = set(s.sensors.enabled_names())
    out: list[tuple[str, tuple[str, int], object]] = []
    done: dict[str, threading.Event] = {}
    if "lidar" in enabled and (ports.lidar or ports.lidar_position or working is not None):
        from raysim.sensors.lidar import LidarRenderer

        lidar = LidarRenderer(world, scene_factory())  # the position packets only read the own ship's pose
        done["lidar"] = threading.Event()
        sweeps = working / "lidar" / "sweeps" if working is not None else None
        out.append(("lidar", (ports.dest, ports.lidar),
                    lidar_data_batches(lidar, sweeps, done["lidar"], cast_ahead=fed is None)))
        if ports.lidar_position:
            out.append(("lidar_position", (ports.dest, ports.lidar_position), lidar_position_batches(lidar)))
    if "radar" in enabled and (ports.radar or working is not None):
        from raysim.sensors.radar import RadarRenderer

        address = RADAR_MULTICAST if ports.radar_multicast else (ports.dest, ports.radar)
        if ports.radar_multicast:  # as the real set: its beacon (where its groups are) and status (transmitting)
            out.append(("radar_beacon", BEACON_ADDRESS, announcements(s.duration_s, beacon())))
            out.append(("radar_report", REPORT_ADDRESS, announcements(s.duration_s, status_report())))
        done["radar"] = threading.Event()
        sweeps = working / "radar" / "sweeps" if working is not None else None
        out.append(("radar", address, radar_batches(RadarRenderer(world, scene_factory()), sweeps_dir=sweeps,
                                                    done=done["radar"],
                                                    sectors=FED_RADAR_SECTORS if fed is not None else 1)))
    if "ais" in enabled and ports.ais:
        out.append(("ais", (ports.dest, ports.ais), ais_batches(world)))
    if "nav" in enabled and ports.nav:
        out.append(("nav", (ports.dest, ports.nav), nav_batches(world)))
    if working is not None:
        from raysim.live.targets import target_batches

        targets = target_batches(working, done, stop, fed, world.frame)
        out.append(("targets", (ports.dest, ports.targets), _tee(targets, on_targets) if on_targets else targets))
    # a sensor rendered only for the TDM or the Foxglove view (its port 0) sends nothing
    muted = {"lidar": not ports.lidar, "radar": not ports.radar, "targets": not ports.targets}
    return [(dict(name=name, address=address, muted=muted.get(name, False), report_behind=name != "targets",
                  preroll=name != "targets"), batches) for name, address, batches in out]


def _tee(batches, see):
    """The batches, each also shown to ``see(t_s, records)`` (the Foxglove view of the targets)."""
    for batch in batches:
        see(float(batch.times_s[0]), [json.loads(p) for p in batch.payloads])
        yield batch


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


class _Session:
    """A session's parts: the world, the fed own ship, the working recording, the Foxglove view, the streams,
    their producers (threads) and the send process."""

    def __init__(self, scenario: Scenario, ports: LivePorts, speed: float, ownship_port: int | None):
        self.scenario, self.ports, self.speed = scenario, ports, speed
        self.world = World(scenario)
        self.start_wall_s: float | None = None
        self.mp = multiprocessing.get_context("spawn")  # a fresh interpreter: no locks inherited from threads
        self.stop = self.mp.Event()
        self.feed = self.fed = self.view = self.working_dir = None
        ready_before = None
        if ownship_port is not None:
            from raysim.live.ownship_in import FedMotion, OwnShipFeed

            self.feed = OwnShipFeed(ownship_port, self.world.frame, self.clock)
            self.fed = FedMotion(self.feed, self.world.own_ship.motion,
                                 on_message=lambda text: print(f"live: {text}", file=sys.stderr))
            self.world.drive_own_ship(self.fed)
            ready_before = self._fed_lead
        working = self._working_recording()
        see = None
        if ports.foxglove is not None:
            from raysim.live.foxglove_view import FoxgloveView

            from groundfloor.frames import mount_transform

            mounts = {name: mount_transform(getattr(scenario.sensors, name).mount) for name in ("lidar", "radar")}
            self.view = FoxgloveView(ports.foxglove, working, self.clock, scenario.start_time.timestamp(),
                                     self.world.frame.to_local, self.stop, mounts)
            see = lambda t_s, records: self.view.targets.put((t_s, records))  # noqa: E731
        streams = _streams(self.world, _scene_factory(self.world), ports, self.stop, working, see, self.fed)
        self.specs = [spec for spec, _ in streams]
        self.queues = [self.mp.Queue(maxsize=QUEUE_DEPTH) for _ in streams]
        for q in self.queues:  # batches left when a session is interrupted are dropped, not waited for at exit
            q.cancel_join_thread()
        self.producers = [Producer(spec["name"], batches, q, self.stop, ready_before)
                          for (spec, batches), q in zip(streams, self.queues)]

    def clock(self) -> float:
        """Scenario time on the session's clock, s (0 until it starts)."""
        return 0.0 if self.start_wall_s is None else (time.perf_counter() - self.start_wall_s) * self.speed

    def _fed_lead(self, t_s: float) -> None:
        """Hold a producer until the clock is within FED_LEAD_S of ``t_s`` (the fed pose's extrapolation)."""
        while not self.stop.is_set() and self.clock() < t_s - FED_LEAD_S:
            time.sleep(0.01)

    def _working_recording(self) -> Path | None:
        """The live TDM's and the Foxglove view's working recording (None if neither is on)."""
        if not self.ports.targets and self.ports.foxglove is None:
            return None
        from raysim.live.targets import prepare_working_recording

        self.working_dir = tempfile.TemporaryDirectory(prefix="raysim-live-")
        working = Path(self.working_dir.name) / "rec"
        prepare_working_recording(self.scenario, working)
        return working

    def run(self) -> LiveResult:
        """Start the producers and the send process; wait for the end, Ctrl-C or SIGTERM; stop everything."""
        started, start_at, results = self.mp.Event(), self.mp.Value("d", 0.0), self.mp.Queue()
        wire = self.mp.Process(target=wire_main, name="raysim-live-wire", daemon=True,
                               args=(self.specs, self.queues, self.speed, self.scenario.duration_s,
                                     self.ports.radar_multicast, self.stop, started, start_at, results))
        interrupted, outcome = False, None
        try:
            for p in self.producers:
                p.start()
            wire.start()
            self._wait_for_start(wire, started, start_at)
            outcome = _results(results, wire)
        except KeyboardInterrupt:
            interrupted = True
            self.stop.set()
            outcome = _results(results, wire)
        finally:
            self.stop.set()
            self.close()
            wire.join(timeout=5.0)
        for p in self.producers:
            if p.error is not None:
                raise p.error
        arrays, behind, reached, scheduling = outcome if outcome is not None else ({}, {}, self.clock(), "?")
        stale = self.fed.stale_events if self.fed is not None else 0
        return LiveResult(reached, interrupted, summary(arrays, behind), stale, scheduling)

    def _wait_for_start(self, wire, started, start_at) -> None:
        """Until the send process starts the clock: then the fed own ship and the Foxglove view follow it."""
        deadline = time.perf_counter() + PREROLL_TIMEOUT_S
        while not started.wait(0.05):
            if not wire.is_alive() or self.stop.is_set() or time.perf_counter() > deadline:
                return
        self.start_wall_s = start_at.value
        if self.view is not None:
            self.view.start()

    def close(self) -> None:
        """Stop the producers, the own-ship feed and the Foxglove view; remove the working recording."""
        self.stop.set()
        for p in self.producers:
            p.join(timeout=5.0)
        if self.feed is not None:
            self.feed.close()
        if self.view is not None:
            if self.view.ident is not None:  # started
                self.view.join(timeout=2.0)
            self.view.close()
        if self.working_dir is not None:
            self.working_dir.cleanup()


def _results(results, wire):
    """The send process's ``(lateness arrays, behind reports, reached s, scheduling)`` once it ends (None if it
    died)."""
    deadline = time.perf_counter() + RESULTS_TIMEOUT_S
    while True:
        try:
            return results.get(timeout=0.2)
        except queue.Empty:
            if not wire.is_alive() and time.perf_counter() > deadline:
                return None


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
    session = _Session(scenario, ports, speed, ownship_port)
    return session.run(), session.world

"""raysim live --ownship-in: NMEA fed from outside moves the own ship, and the LiDAR sees it move."""

from __future__ import annotations

import datetime as dt
import json
import socket
import threading
import time

import numpy as np
import pytest
import yaml

from raysim.cli import main
from raysim.recording import nmea
from tests.raysim.helpers import FRAME, box_file, latlon, scenario
from tests.raysim.live.receivers import Receiver

WALL_NORTH_M = 30.0
MOVED_NORTH_M = 5.0


def free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def feed(port: int, lidar: Receiver, stop: threading.Event) -> None:
    """GGA + HDT + VTG at 10 Hz: at the origin for 2 s after the first LiDAR packet, then 5 m north."""
    deadline = time.perf_counter() + 30.0
    while not lidar.datagrams and time.perf_counter() < deadline and not stop.is_set():
        time.sleep(0.01)
    first = time.perf_counter()
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        while not stop.is_set() and time.perf_counter() < deadline:
            north = 0.0 if time.perf_counter() - first < 2.0 else MOVED_NORTH_M
            lat, lon = latlon(0.0, north)
            utc = dt.datetime.now(dt.timezone.utc)
            for line in (nmea.gpgga(utc, lat, lon, 0.0), nmea.hehdt(0.0), nmea.gpvtg(0.0, 0.0)):
                s.sendto((line + "\r\n").encode("ascii"), ("127.0.0.1", port))
            time.sleep(0.1)


def forward_ranges(packets: list[bytes]) -> list[float]:
    """Median range (m) of the points within 2 deg of dead ahead, per decoded revolution."""
    vd = pytest.importorskip("velodyne_decoder")
    decoder = vd.StreamDecoder(vd.Config(model=vd.Model.HDL32E, min_range=0.0, max_range=200.0))
    out = []
    for k, p in enumerate(packets):
        scan = decoder.decode(k * 1e-3, p, as_pcl_structs=True)
        if scan is None:
            continue
        cloud = scan[1]
        ahead = (np.abs(np.degrees(np.arctan2(cloud["y"], cloud["x"]))) < 2.0) & (cloud["x"] > 10.0)
        if np.count_nonzero(ahead) > 5:
            out.append(float(np.median(np.hypot(cloud["x"][ahead], cloud["y"][ahead]))))
    return out


def test_nmea_fed_to_ownship_in_moves_the_own_ship_and_the_wall_comes_nearer(tmp_path):
    wall = {"name": "wall", "kind": "mesh", "mesh": box_file(tmp_path, "wall", (40.0, 2.0, 10.0), (0.0, 0.0, 4.0)),
            "position": latlon(0.0, WALL_NORTH_M + 1.0), "heading_deg": 90.0}  # its 40 m face across the bow
    data = scenario(tmp_path, obstacles=[wall], duration=6.0)
    data["sensors"] = {"lidar": {"mount": {"x_m": 0.0, "z_m": 3.0}}, "radar": {"enabled": False},
                       "ais": {"enabled": False}}
    path = tmp_path / "wall.yaml"
    path.write_text(yaml.safe_dump(data))
    lidar, targets, port, stop = Receiver(), Receiver(), free_port(), threading.Event()
    feeder = threading.Thread(target=feed, args=(port, lidar, stop), daemon=True)
    feeder.start()
    try:
        code = main(["live", str(path), "--lidar-port", str(lidar.port), "--lidar-position-port", "0",
                     "--nav-port", "0", "--ais-port", "0", "--radar-port", "0", "--ownship-in", str(port),
                     "--targets-port", str(targets.port)])
    finally:
        stop.set()
        lidar.close()
        targets.close()
        feeder.join(timeout=2.0)
    assert code == 0
    ranges = forward_ranges(lidar.payloads)
    assert len(ranges) >= 40
    before, after = np.median(ranges[:10]), np.median(ranges[-10:])
    assert abs(before - WALL_NORTH_M) < 0.3  # the wall's face at 30 m from the origin
    assert abs((before - after) - MOVED_NORTH_M) < 0.1  # nearer by the distance the fed own ship moved
    # the live TDM places the wall with the fed own ship: where it is (its centre 31 m north, its 2 m thickness
    # behind its face; the TDM puts a long footprint a little behind the face seen), before and after the move; with
    # the scenario's still own ship it would jump 5 m south when the ship moved
    records = [json.loads(p) for p in targets.payloads]
    last_t = max(r["t"] for r in records)
    north = [FRAME.to_local(r["latitude"], r["longitude"])[1] for r in records if r["t"] == last_t]
    assert north and min(abs(float(n) - (WALL_NORTH_M + 1.0)) for n in north) < 2.0, north


def test_sigterm_ends_a_live_session_cleanly_with_its_summary(tmp_path):
    import signal
    import subprocess
    import sys

    from tests.raysim.helpers import tiny_scenario

    lidar = Receiver()
    proc = subprocess.Popen([sys.executable, "-m", "raysim.cli", "live", str(tiny_scenario(tmp_path / "tiny")),
                             "--duration", "60", "--lidar-port", str(lidar.port), "--lidar-position-port", "0",
                             "--radar-port", "0", "--ais-port", "0", "--nav-port", "0"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.perf_counter() + 60.0
        while len(lidar.datagrams) < 2000 and time.perf_counter() < deadline:
            time.sleep(0.05)
        proc.send_signal(signal.SIGTERM)
        out, err = proc.communicate(timeout=20)
    finally:
        proc.kill()
        lidar.close()
    assert proc.returncode == 0, err
    assert "live: interrupted at t = " in out
    assert "live: lidar: " in out and "Traceback" not in err


WEST_WALL_M = 60.0
CRAB_WEST_MPS = 4.0


def crab_west(port: int, radar: Receiver, stop: threading.Event, track: list) -> None:
    """Heading north, moving west at 4 m/s from 2.5 s after the first radar frame: GGA + HDT at 10 Hz."""
    deadline = time.perf_counter() + 40.0
    while not radar.datagrams and time.perf_counter() < deadline and not stop.is_set():
        time.sleep(0.01)
    first = time.perf_counter()
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        while not stop.is_set() and time.perf_counter() < deadline:
            now = time.perf_counter()
            west = CRAB_WEST_MPS * max(0.0, now - first - 2.5)
            track.append((now, west))
            lat, lon = latlon(-west, 0.0)
            utc = dt.datetime.now(dt.timezone.utc)
            for line in (nmea.gpgga(utc, lat, lon, 0.0), nmea.hehdt(0.0)):
                s.sendto((line + "\r\n").encode("ascii"), ("127.0.0.1", port))
            time.sleep(0.1)


def test_a_fed_own_ship_moves_the_radar_within_a_revolution(tmp_path):
    """The radar's spokes take the fed pose of their own time: the range to a wall abeam follows the own ship
    as it closes, on the late spokes of a revolution too (a revolution rendered at its start would extrapolate
    the pose over 2.5 s and hold it after 1 s: metres off at 4 m/s)."""
    from tests.raysim.live.test_live import navico_spokes

    wall = {"name": "wall", "kind": "mesh", "mesh": box_file(tmp_path, "wall", (200.0, 2.0, 10.0), (0.0, 0.0, 4.0)),
            "position": latlon(-WEST_WALL_M - 1.0, 0.0), "heading_deg": 0.0}  # 200 m north-south, its face 60 m west
    data = scenario(tmp_path, obstacles=[wall], duration=9.0)
    data["sensors"] = {"lidar": {"enabled": False}, "ais": {"enabled": False},
                       "radar": {"spokes": 512, "samples": 1024, "range_m": 463.0, "mount": {"z_m": 4.0}}}
    path = tmp_path / "west.yaml"
    path.write_text(yaml.safe_dump(data))
    radar, port, stop, track = Receiver(), free_port(), threading.Event(), []
    feeder = threading.Thread(target=crab_west, args=(port, radar, stop, track), daemon=True)
    feeder.start()
    try:
        code = main(["live", str(path), "--radar-port", str(radar.port), "--nav-port", "0", "--ais-port", "0",
                     "--lidar-port", "0", "--lidar-position-port", "0", "--ownship-in", str(port)])
    finally:
        stop.set()
        radar.close()
        feeder.join(timeout=2.0)
    assert code == 0
    fed_t, fed_west = np.array(track).T
    seen = []  # (moved m, wall range m) on the spoke abeam to port, once a revolution
    for arrival, frame in radar.datagrams:
        for spoke in navico_spokes(frame):
            lit = np.flatnonzero(spoke["samples"] >= 8)
            if spoke["angle"] == 3072 and lit.size:  # abeam to port (270 deg from the bow)
                # the frame (spokes 384-415) left with its last spoke, 31 spoke periods after this one
                seen.append((float(np.interp(arrival - 31 * 2.5 / 512, fed_t, fed_west)), lit[0] * 463.0 / 1023))
    still = [rng - WEST_WALL_M for moved, rng in seen if moved == 0.0]
    moving = [rng - (WEST_WALL_M - moved) for moved, rng in seen if moved > 4.0]
    assert still and len(moving) >= 2, seen  # at rest on the first revolution, closing in on two more
    bias = still[0]  # the echo's leading edge against the face (range response, saturation), measured at rest
    # within 2.5 m of where the fed track had the ship at each spoke's time (a revolution rendered at its start,
    # its pose held 1 s past the latest fix: 5-7 m off at 4 m/s)
    assert np.max(np.abs(np.array(moving) - bias)) < 2.5, (bias, seen)

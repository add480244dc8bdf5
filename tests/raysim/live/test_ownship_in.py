"""Own ship driven by NMEA 0183 over UDP: parsing, the feed, interpolation, extrapolation, staleness."""

from __future__ import annotations

import functools
import socket
import time

import numpy as np
import pytest

from raysim.geodesy import LocalFrame
from raysim.live.ownship_in import KNOTS_TO_MPS, FedMotion, OwnShipFeed, parse_fix
from raysim.motion import Motion, Stationary

ORIGIN = (59.4, 10.5)
SPEED_MPS = 10.0


def nmea(body: str) -> str:
    """``$body*hh`` with the XOR checksum of the characters between ``$`` and ``*``."""
    checksum = functools.reduce(lambda acc, ch: acc ^ ord(ch), body, 0)
    return f"${body}*{checksum:02X}"


def gga(lat_deg: float, lon_deg: float) -> str:
    lat_d, lon_d = int(abs(lat_deg)), int(abs(lon_deg))
    lat = f"{lat_d:02d}{(abs(lat_deg) - lat_d) * 60:09.6f},{'N' if lat_deg >= 0 else 'S'}"
    lon = f"{lon_d:03d}{(abs(lon_deg) - lon_d) * 60:09.6f},{'E' if lon_deg >= 0 else 'W'}"
    return nmea(f"GPGGA,120000.00,{lat},{lon},1,10,0.8,12.3,M,40.1,M,,")


def gga_at(frame: LocalFrame, east_m: float, north_m: float) -> str:
    lat, lon = frame.to_geodetic(east_m, north_m)
    return gga(float(lat), float(lon))


def test_parse_each_sentence_kind():
    fix = parse_fix(gga(59.5, -10.25))
    assert fix["kind"] == "GGA"
    assert fix["lat_deg"] == pytest.approx(59.5, abs=1e-9) and fix["lon_deg"] == pytest.approx(-10.25, abs=1e-9)
    assert parse_fix(nmea("HEHDT,274.07,T")) == {"kind": "HDT", "heading_deg": pytest.approx(274.07)}
    vtg = parse_fix(nmea("GPVTG,054.7,T,034.4,M,005.5,N,010.2,K"))
    assert vtg["cog_deg"] == pytest.approx(54.7) and vtg["sog_mps"] == pytest.approx(5.5 * 1852 / 3600)
    psxn = parse_fix("$PSXN,23,0.30,-0.97,298.57,0.13*1B\r\n")  # the sample of the Seapath documentation
    assert psxn["roll_deg"] == pytest.approx(0.30) and psxn["pitch_deg"] == pytest.approx(-0.97)
    assert psxn["heave_m"] == pytest.approx(-0.13)  # sentence: positive down; parse_fix: positive up
    assert psxn["heading_deg"] == pytest.approx(298.57)
    assert parse_fix(nmea("INGGA,120000.00,5924.000000,N,01030.000000,E,1,10,0.8,1.0,M,40.1,M,,"))["kind"] == "GGA"


def test_bad_checksum_garbage_and_no_fix_give_none():
    good = nmea("HEHDT,274.07,T")
    assert parse_fix(good[:-2] + ("00" if good[-2:] != "00" else "01")) is None
    for line in ("", "garbage", "$", "$GPGGA,,,,", "\x00\xff", "$PSXN,23,abc,def,1,2", nmea("GPZDA,1,2,3,4,,")):
        assert parse_fix(line) is None
    no_fix = nmea("GPGGA,120000.00,5924.000000,N,01030.000000,E,0,00,,,M,,M,,")
    assert parse_fix(no_fix) is None
    assert parse_fix(None) is None  # type: ignore[arg-type]


class Clock:
    """A scenario clock the test sets."""

    def __init__(self) -> None:
        self.now_s = 0.0

    def __call__(self) -> float:
        return self.now_s


def send(feed: OwnShipFeed, clock: Clock, t_s: float, *lines: str) -> None:
    """Send one datagram at scenario time ``t_s`` and wait until the feed took it."""
    clock.now_s = t_s
    before = feed.sentences_used + feed.sentences_ignored
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.sendto("\r\n".join(lines).encode("ascii") + b"\r\n", ("127.0.0.1", feed.port))
    deadline = time.monotonic() + 10.0
    while feed.sentences_used + feed.sentences_ignored < before + len(lines):
        assert time.monotonic() < deadline, "datagram not received"
        time.sleep(0.005)


@pytest.fixture
def rig():
    frame, clock = LocalFrame(*ORIGIN), Clock()
    feed = OwnShipFeed(0, frame, clock)
    fallback = Stationary([100.0, 200.0, 0.0], yaw_rad=0.3)
    messages: list[str] = []
    motion = FedMotion(feed, fallback, on_message=messages.append)
    yield frame, clock, feed, motion, messages
    feed.close()


def heading_north_at(frame: LocalFrame, north_m: float) -> list[str]:
    knots = SPEED_MPS / KNOTS_TO_MPS
    return [gga_at(frame, 0.0, north_m), nmea("HEHDT,0.00,T"), nmea(f"GPVTG,0.00,T,,M,{knots:.6f},N,,K")]


def test_fallback_before_any_fix(rig):
    frame, clock, feed, motion, _ = rig
    assert isinstance(motion, Motion)
    p = motion.poses(np.array([0.0, 5.0]))
    np.testing.assert_allclose(p.position_m, [[100.0, 200.0, 0.0]] * 2)
    np.testing.assert_allclose(p.yaw_rad, 0.3)
    assert not motion.stale and motion.stale_events == 0
    np.testing.assert_allclose(motion.velocity_mps(np.array([1.0])), 0.0)


def test_interpolation_extrapolation_and_staleness(rig):
    frame, clock, feed, motion, messages = rig
    send(feed, clock, 10.0, *heading_north_at(frame, 0.0))
    send(feed, clock, 11.0, *heading_north_at(frame, 10.0))
    assert feed.sentences_used == 6 and feed.last_fix_s == 11.0
    mid = motion.poses(np.array([10.5]))
    assert mid.position_m[0, 0] == pytest.approx(0.0, abs=0.01)
    assert mid.position_m[0, 1] == pytest.approx(5.0, abs=0.01)
    assert mid.heading_deg[0] == pytest.approx(0.0, abs=1e-9)
    np.testing.assert_allclose(mid.roll_rad, 0.0)  # a Stationary fallback: no waves
    clock.now_s = 11.5
    ahead = motion.poses(np.array([11.5]))
    assert ahead.position_m[0, 1] == pytest.approx(15.0, abs=0.01)  # VTG: 10 m/s north
    assert not motion.stale
    np.testing.assert_allclose(motion.velocity_mps(np.array([11.5]))[0], [0.0, SPEED_MPS, 0.0], atol=1e-4)
    clock.now_s = 14.0
    held = motion.poses(np.array([14.0]))
    assert held.position_m[0, 1] == pytest.approx(20.0, abs=0.01)  # held at the 1 s extrapolation
    assert motion.stale and motion.stale_events == 1
    motion.poses(np.array([14.2]))
    assert motion.stale_events == 1 and messages == ["own-ship feed stale: no fix for 3.0 s"]
    np.testing.assert_allclose(motion.velocity_mps(np.array([14.0])), 0.0)
    send(feed, clock, 15.0, *heading_north_at(frame, 40.0))
    assert not motion.stale and messages[-1] == "own-ship feed resumed after 4.0 s"
    clock.now_s = 17.0
    assert motion.stale and motion.stale_events == 2


def test_heading_unwraps_across_north(rig):
    frame, clock, feed, motion, _ = rig
    send(feed, clock, 1.0, gga_at(frame, 0.0, 0.0), nmea("HEHDT,350.00,T"))
    send(feed, clock, 2.0, gga_at(frame, 0.0, 0.0), nmea("HEHDT,10.00,T"))
    assert motion.poses(np.array([1.5])).heading_deg[0] == pytest.approx(0.0, abs=1e-9)
    assert motion.yaw_rate_rps(np.array([1.5]))[0] == pytest.approx(np.radians(-20.0))  # turning to starboard


def test_psxn_attitude_reaches_the_poses(rig):
    frame, clock, feed, motion, _ = rig
    send(feed, clock, 1.0, gga_at(frame, 3.0, 4.0), nmea("PSXN,23,2.00,-3.00,45.00,0.50"))
    p = motion.poses(np.array([1.0]))
    assert p.roll_rad[0] == pytest.approx(np.radians(2.0))  # port up = starboard down = FLU roll +
    assert p.pitch_rad[0] == pytest.approx(np.radians(3.0))  # bow down 3 deg = FLU pitch +3 deg
    assert p.position_m[0, 2] == pytest.approx(-0.5)  # heave 0.5 m down
    assert p.heading_deg[0] == pytest.approx(45.0)  # PSXN,23's heading while no HDT
    np.testing.assert_allclose(p.position_m[0, :2], [3.0, 4.0], atol=0.01)


def test_close_ends_the_thread():
    feed = OwnShipFeed(0, LocalFrame(*ORIGIN), Clock())
    assert feed.port > 0 and feed.thread.is_alive()
    feed.close()  # joins the thread for at most 2 x SOCKET_TIMEOUT_S + 0.1 s
    assert not feed.thread.is_alive()


def test_ring_keeps_the_latest_fixes_in_order_and_sentences_without_checksum():
    frame, clock = LocalFrame(*ORIGIN), Clock()
    with OwnShipFeed(0, frame, clock, capacity=4) as feed:
        for k in range(7):
            assert feed.feed_line(gga_at(frame, 0.0, 10.0 * k), t_s=float(k))
        assert feed.feed_line("$HEHDT,90.0,T", t_s=6.0)  # no checksum: accepted
        rows = feed.rows("position")
        np.testing.assert_allclose(rows[:, 0], [3.0, 4.0, 5.0, 6.0])
        np.testing.assert_allclose(rows[:, 2], [30.0, 40.0, 50.0, 60.0], atol=0.01)
        motion = FedMotion(feed, Stationary([0.0, 0.0, 0.0]))
        assert motion.poses(np.array([0.0])).position_m[0, 1] == pytest.approx(30.0, abs=0.01)  # oldest kept, held

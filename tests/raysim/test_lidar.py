"""HDL-32E rendering against analytic cases: geometry, timing, noise, occlusion, motion, packets."""

from __future__ import annotations

import glob
import struct

import numpy as np
import pytest
import trimesh

from groundfloor import hdl32e
from raysim.cli import main
from tests.raysim.helpers import ORIGIN, box_file, latlon, scenario

def render(write_scenario, tmp_path, data, name="rec"):
    import yaml

    path = tmp_path / f"{name}.yaml"
    path.write_text(yaml.safe_dump(data))
    out = tmp_path / name
    assert main(["render", str(path), "-o", str(out), "--sensors", "lidar", "--no-progress"]) == 0
    return out


def sweeps(rec):
    return [dict(np.load(f)) for f in sorted(glob.glob(str(rec / "lidar" / "sweeps" / "*.npz")))]


def wall(tmp_path, distance_m=20.0, name="wall"):
    """A 60 m wide, 30 m tall, 2 m thick wall whose near face is distance_m north of the sensor."""
    mesh = box_file(tmp_path, name, (2.0, 60.0, 30.0), (0.0, 0.0, 5.0))  # body x = thickness
    return {"name": name, "kind": "mesh", "mesh": mesh, "position": latlon(0, distance_m + 1.0), "heading_deg": 0.0}


def test_wall_at_known_distance_has_the_configured_noise_and_no_bias(write_scenario, tmp_path):
    rec = render(write_scenario, tmp_path, scenario(tmp_path, obstacles=[wall(tmp_path, 20.0)]))
    s = sweeps(rec)
    assert len(s) == 2
    on = [d["object_id"] == 1 for d in s]
    pts = np.concatenate([np.stack([d["x"], d["y"], d["z"]], 1)[m] for d, m in zip(s, on)]).astype(float)
    dsr = np.argsort(hdl32e.RING)[np.concatenate([d["ring"][m] for d, m in zip(s, on)])]
    assert pts.shape[0] > 1000
    # measured range from the beam's origin (0, 0, z_offset); the face is the plane x = 20 m
    beam = pts - np.stack([np.zeros(len(dsr)), np.zeros(len(dsr)), hdl32e.Z_OFFSET_M[dsr]], 1)
    measured = np.linalg.norm(beam, axis=1)
    true = 20.0 * measured / beam[:, 0]  # 20 m / (cos w cos a) along the same beam
    residual = measured - true
    assert abs(residual.mean()) < 0.0005  # no bias
    assert residual.std() == pytest.approx(np.hypot(0.008, 0.002 / np.sqrt(12)), rel=0.1)  # noise + 2 mm quantisation


def test_points_lie_on_their_rings_and_on_the_firing_time_grid(write_scenario, tmp_path):
    data = scenario(tmp_path, obstacles=[wall(tmp_path, 15.0)])
    rec = render(write_scenario, tmp_path, data)
    d = sweeps(rec)[0]
    # ring -> elevation: atan2(z - z_offset, horizontal) equals the table value of that ring's laser
    dsr_of_ring = np.argsort(hdl32e.RING)
    dsr = dsr_of_ring[d["ring"]]
    horizontal = np.hypot(d["x"].astype(float), d["y"].astype(float))
    elevation = np.degrees(np.arctan2(d["z"].astype(float) - hdl32e.Z_OFFSET_M[dsr], horizontal))
    assert np.max(np.abs(elevation - hdl32e.ELEVATION_DEG[dsr])) < 2e-3
    assert set(np.unique(d["ring"])) <= set(range(32))
    # time: cycle k at 46.08 us k, firing j 1.152 us later: a whole number of 1.152 us steps, and j = DSR
    steps = d["time"] / hdl32e.FIRING_DT_S
    assert np.max(np.abs(steps - np.round(steps))) < 1e-4
    assert np.array_equal(np.round(steps).astype(np.int64) % 40, dsr)
    assert np.all(np.diff(d["time"]) >= 0)


def test_geometry_behind_nearer_geometry_gets_no_points(write_scenario, tmp_path):
    front = wall(tmp_path, 15.0, "front")
    behind = {"name": "behind", "kind": "mesh", "mesh": box_file(tmp_path, "small", (3.0, 3.0, 3.0), (0, 0, 1.5)),
              "position": latlon(0, 30.0)}
    seen = render(write_scenario, tmp_path, scenario(tmp_path, obstacles=[behind]), "open")
    hidden = render(write_scenario, tmp_path, scenario(tmp_path, obstacles=[front, behind]), "hidden")
    ids_open = np.concatenate([d["object_id"] for d in sweeps(seen)])
    ids_hidden = np.concatenate([d["object_id"] for d in sweeps(hidden)])
    assert (ids_open == 1).sum() > 20  # the small box alone is seen (its id is 1 there)
    assert (ids_hidden == 2).sum() == 0  # behind the wall (id 2 there): nothing
    assert (ids_hidden == 1).sum() > 1000


def test_pcap_packet_rate_and_a_hand_computed_packet(write_scenario, tmp_path):
    data = scenario(tmp_path, obstacles=[wall(tmp_path, 20.0)], lidar={"range_noise_m": 0.0}, duration=1.0)
    data["own_ship"]["mesh"] = box_file(tmp_path, "buoyant_point", (0.2, 0.2, 0.2), (0, 0, -5))  # no deck in the way
    rec = render(write_scenario, tmp_path, data)
    raw = (rec / "lidar" / "hdl32e.pcap").read_bytes()
    assert struct.unpack_from("<IHHiIII", raw, 0) == (0xA1B2C3D4, 2, 4, 0, 0, 65535, 1)
    offset, data_frames, first = 24, 0, None
    while offset < len(raw):
        ts_sec, ts_usec, incl, orig = struct.unpack_from("<IIII", raw, offset)
        frame = raw[offset + 16 : offset + 16 + incl]
        port = struct.unpack_from(">H", frame, 36)[0]
        if port == 2368:
            data_frames += 1
            assert incl == orig == 1248
            first = first or (ts_sec + ts_usec * 1e-6, frame)
        offset += 16 + incl
    assert data_frames == 1808  # 1 s: 21 701 cycles / 12 = 1808 packets
    stamp, frame = first
    assert frame[12:14] == b"\x08\x00" and frame[23] == 17 and struct.unpack_from(">HH", frame, 34) == (2368, 2368)
    payload = frame[42:]
    # the same packet by hand: cycle k fires at 46.08 us k; the head starts at azimuth 0 and turns at 10 Hz
    expected = bytearray(1206)
    for block in range(12):
        t = block * 46.08e-6
        azimuth = round((360.0 * 10.0 * t) * 100) % 36000
        struct.pack_into("<HH", expected, 100 * block, 0xEEFF, azimuth)
        rate = ((round(360.0 * 10.0 * 11 * 46.08e-6 * 100)) % 36000) / (11 * 46.08e-6)
        for j in range(32):
            a = np.radians(round(azimuth + rate * j * 1.152e-6) * 0.01)
            w = np.radians(hdl32e.ELEVATION_DEG[j])
            direction = np.array([np.cos(w) * np.cos(a), -np.cos(w) * np.sin(a), np.sin(w)])
            origin_z = hdl32e.Z_OFFSET_M[j]
            rng = 20.0 / direction[0]  # the wall's face x = 20 m
            hit_z = 3.0 + origin_z + rng * direction[2]
            if 0.0 < hit_z < 20.0 and rng <= 100.0:  # below z = 0 the calm sea takes the beam first
                struct.pack_into("<HB", expected, 100 * block + 4 + 3 * j, round(rng / 0.002), 40)
    struct.pack_into("<IBB", expected, 1200, 0, 0x37, 0x21)
    got = bytearray(payload)
    # reflectivity: concrete 0.40 x cos(incidence): compare distances and headers exactly, bytes within 1
    for block in range(12):
        assert got[100 * block : 100 * block + 4] == expected[100 * block : 100 * block + 4]
        for j in range(32):
            g_d, g_r = struct.unpack_from("<HB", got, 100 * block + 4 + 3 * j)
            e_d, _ = struct.unpack_from("<HB", expected, 100 * block + 4 + 3 * j)
            assert g_d == e_d, (block, j)
            if e_d:
                a_cos = 20.0 / (e_d * 0.002)
                assert abs(g_r - round(40 * a_cos)) <= 1
    assert got[1200:] == expected[1200:]
    assert stamp == pytest.approx(1496318400.0 + 12 * 46.08e-6, abs=2e-6)


def test_a_real_decoder_reads_exactly_our_points(write_scenario, tmp_path):
    vd = pytest.importorskip("velodyne_decoder")
    data = scenario(tmp_path, obstacles=[wall(tmp_path, 12.0)], duration=0.35,
                    environment={"sea_state": 4, "wind_speed_mps": 12})
    rec = render(write_scenario, tmp_path, data)
    config = vd.Config(model=vd.Model.HDL32E, min_range=0.0, max_range=200.0)
    decoded = np.concatenate([cloud for _, cloud in vd.read_pcap(str(rec / "lidar" / "hdl32e.pcap"), config, as_pcl_structs=True)])
    ours = sweeps(rec)
    ours_xyz = np.concatenate([np.stack([d["x"], d["y"], d["z"]], 1) for d in ours])
    n = ours_xyz.shape[0]
    assert decoded.shape[0] >= n > 10000
    theirs = np.stack([decoded["x"], decoded["y"], decoded["z"]], 1)[:n]
    assert np.max(np.abs(theirs - ours_xyz)) < 1e-4
    assert np.array_equal(decoded["intensity"][:n].astype(np.uint8), np.concatenate([d["intensity"] for d in ours]))
    assert np.array_equal(decoded["ring"][:n] & 0xFF, np.concatenate([d["ring"] for d in ours]))


def test_yawing_own_ship_shears_a_straight_wall_by_the_yaw_rate(write_scenario, tmp_path):
    yaw_rate_deg_s = 90.0
    t = np.arange(0.0, 1.01, 0.01)
    lat, lon = latlon(0, 0)
    csv = tmp_path / "yaw.csv"
    csv.write_text("t_s,lat,lon,heading_deg,roll_deg,pitch_deg,heave_m\n"
                   + "".join(f"{ti:.2f},{lat},{lon},{(yaw_rate_deg_s * ti) % 360:.6f},0,0,0\n" for ti in t))
    data = scenario(tmp_path, obstacles=[wall(tmp_path, 25.0)], own={"trajectory_csv": "yaw.csv"}, duration=0.3,
                    lidar={"range_noise_m": 0.0})
    rec = render(write_scenario, tmp_path, data)
    d = sweeps(rec)[1]
    on = d["object_id"] == 1
    p = np.stack([d["x"], d["y"], d["z"]], 1)[on].astype(float)
    time = d["time"][on]
    # deskew with the heading at each point's own time: the wall's face is the straight line north = 25 m
    heading = np.radians(yaw_rate_deg_s * time)
    north = p[:, 0] * np.cos(heading) + p[:, 1] * np.sin(heading)
    east = p[:, 0] * np.sin(heading) - p[:, 1] * np.cos(heading)
    assert np.max(np.abs(north - 25.0)) < 0.01
    # with one pose for the whole sweep (its first instant) every point is rotated back by the yaw since then
    h0 = np.radians(yaw_rate_deg_s * d["time"].min())
    naive_north = p[:, 0] * np.cos(h0) + p[:, 1] * np.sin(h0)
    naive_east = p[:, 0] * np.sin(h0) - p[:, 1] * np.cos(h0)
    shear = np.arctan2(east, north) - np.arctan2(naive_east, naive_north)
    assert np.max(np.abs(naive_north - 25.0)) > 0.5
    assert np.max(np.abs(shear - (heading - h0))) < 1e-4


def test_a_moving_ship_is_hit_where_it_was_at_each_point_time(write_scenario, tmp_path):
    ship = {"name": "runner", "length_m": 30, "speed_kn": 19.44, "waypoints": [latlon(-60, 25), latlon(400, 25)]}
    rec = render(write_scenario, tmp_path, scenario(tmp_path, ships=[ship], duration=3.0, lidar={"range_noise_m": 0.0}))
    from raysim.scenario import load_scenario
    from raysim.world import World

    runner = World(load_scenario(rec / "scenario.yaml")).objects[1]
    mesh = runner.mesh.to_trimesh()
    errors_own, errors_frozen = [], []
    for d in sweeps(rec)[2:]:
        on = d["object_id"] == 1
        p = np.stack([d["x"], d["y"], d["z"]], 1)[on].astype(float)
        world_pts = np.stack([-p[:, 1], p[:, 0], p[:, 2] + 3.0], 1)  # heading north: x_fwd = north, y_left = west
        time = d["time"][on]
        own = runner.motion.poses(time).to_body(world_pts)
        frozen = runner.motion.poses(np.full_like(time, d["time"].min())).to_body(world_pts)
        errors_own.append(trimesh.proximity.closest_point(mesh, own)[1])
        errors_frozen.append(trimesh.proximity.closest_point(mesh, frozen)[1])
    own_err, frozen_err = np.concatenate(errors_own), np.concatenate(errors_frozen)
    assert own_err.size > 500
    assert np.percentile(own_err, 99) < 0.005  # on the hull where it was at each point's time
    assert np.percentile(frozen_err, 90) > 0.4  # 10 m/s x the time since the sweep began (up to 1 m)


def test_calm_water_returns_nothing_and_foam_grows_with_wind(write_scenario, tmp_path):
    calm = render(write_scenario, tmp_path, scenario(tmp_path, duration=0.5), "calm")
    assert sum((d["return_source"] == 1).sum() for d in sweeps(calm)) == 0
    counts = []
    for wind, name in ((8.0, "breeze"), (16.0, "gale")):
        rec = render(write_scenario, tmp_path, scenario(tmp_path, duration=0.5, environment={"sea_state": 0, "wind_speed_mps": wind}), name)
        counts.append(sum((d["return_source"] == 1).sum() for d in sweeps(rec)))
    assert 0 < counts[0] < counts[1]


def test_fog_shortens_range_and_adds_near_returns(write_scenario, tmp_path):
    far = {"name": "far", "kind": "mesh", "mesh": box_file(tmp_path, "far", (2.0, 60.0, 30.0), (0, 0, 5)),
           "position": latlon(0, 71.0)}
    clear = render(write_scenario, tmp_path, scenario(tmp_path, obstacles=[far]), "clear")
    foggy = render(write_scenario, tmp_path, scenario(tmp_path, obstacles=[far], environment={"sea_state": 0, "wind_speed_mps": 0, "fog_visibility_m": 150}), "fog")
    n_clear = sum((d["object_id"] == 1).sum() for d in sweeps(clear))
    n_fog = sum((d["object_id"] == 1).sum() for d in sweeps(foggy))
    near = np.concatenate([np.sqrt(d["x"] ** 2 + d["y"] ** 2 + d["z"] ** 2)[d["return_source"] == 2] for d in sweeps(foggy)])
    assert n_clear > 500 and n_fog < 0.5 * n_clear
    assert near.size > 100 and near.max() < 10.1  # within the 10 m backscatter window (plus noise)


def test_dual_returns_appear_on_edges(write_scenario, tmp_path):
    post = {"name": "post", "kind": "mesh", "mesh": box_file(tmp_path, "post", (1.0, 1.0, 20.0), (0, 0, 5)),
            "position": latlon(0, 10.0)}
    back = wall(tmp_path, 14.0, "back")
    data = scenario(tmp_path, obstacles=[post, back], lidar={"return_mode": "dual", "sub_rays": 7, "beam_divergence_mrad": 10.0})
    rec = render(write_scenario, tmp_path, data)
    d = sweeps(rec)[0]
    second = d["return_index"] == 1
    az_post = np.degrees(np.arctan2(0.5, 9.5))
    both = second & (np.abs(((d["azimuth_deg"] + 180) % 360) - 180) < az_post + 1.0)
    assert both.sum() > 5  # second returns at the post's edges
    assert not (second & (np.abs(((d["azimuth_deg"] + 180) % 360) - 180) > 30) & (d["object_id"] == 2)).any()


def test_same_seed_same_bytes(write_scenario, tmp_path):
    data = scenario(tmp_path, obstacles=[wall(tmp_path, 20.0)], environment={"sea_state": 4, "wind_speed_mps": 12, "rain_mm_per_h": 4})
    a = render(write_scenario, tmp_path, data, "a")
    b = render(write_scenario, tmp_path, data, "b")
    files = sorted(p.relative_to(a) for p in (a / "lidar").rglob("*") if p.is_file())
    assert len(files) == 4  # the PCAP, two sweeps and a bird's-eye picture
    for rel in files:
        assert (a / rel).read_bytes() == (b / rel).read_bytes(), rel
    data["seed"] = 4
    c = render(write_scenario, tmp_path, data, "c")
    assert (a / "lidar" / "hdl32e.pcap").read_bytes() != (c / "lidar" / "hdl32e.pcap").read_bytes()


def test_position_packets_carry_the_own_ship_gprmc(write_scenario, tmp_path):
    from raysim.recording.nmea import checksum

    data = scenario(tmp_path, duration=2.2)
    rec = render(write_scenario, tmp_path, data)
    raw = (rec / "lidar" / "hdl32e.pcap").read_bytes()
    offset, found = 24, []
    while offset < len(raw):
        ts_sec, ts_usec, incl, _ = struct.unpack_from("<IIII", raw, offset)
        frame = raw[offset + 16 : offset + 16 + incl]
        if struct.unpack_from(">H", frame, 36)[0] == 8308:
            payload = frame[42:]
            assert len(payload) == 512
            stamp_us = struct.unpack_from("<I", payload, 198)[0]
            text = payload[206:].split(b"\x00")[0].decode("ascii")
            found.append((ts_sec + ts_usec * 1e-6, stamp_us, text))
        offset += 16 + incl
    assert [round(t - 1496318400.0, 3) for t, _, _ in found] == [0.0, 1.0, 2.0]
    assert [s for _, s, _ in found] == [0, 1_000_000, 2_000_000]
    for _, _, text in found:
        body, cs = text[1:].split("*")
        assert text.startswith("$GPRMC,") and checksum(body) == cs
        fields = body.split(",")
        lat = int(fields[3][:2]) + float(fields[3][2:]) / 60
        lon = int(fields[5][:3]) + float(fields[5][3:]) / 60
        assert (lat, lon) == pytest.approx(tuple(ORIGIN), abs=1e-6) and fields[4] == "N" and fields[6] == "E"
        assert fields[9] == "010617"


def test_select_echoes_picks_the_second_strongest_when_the_strongest_is_last():
    """Two echoes along a ray, the farther one stronger (fog backscatter at 4 m, a wall at 20 m)."""
    from raysim.sensors import lidar_physics as phys

    threshold = phys.detection_threshold(0.1)
    rng = np.array([[4.0, 20.0], [4.0, 20.0], [20.0, np.inf], [20.0, 20.1]])
    power = np.array([[phys.echo_power(0.02, 4.0, 0.0), phys.echo_power(0.8, 20.0, 0.0)],  # 1.25e-3 < 2e-3
                      [phys.echo_power(0.10, 4.0, 0.0), phys.echo_power(0.8, 20.0, 0.0)],  # 6.25e-3 > 2e-3
                      [phys.echo_power(0.8, 20.0, 0.0), 0.0],  # one echo
                      [1e-3, 1e-3]])  # two sub-rays 0.1 m apart: one echo
    echoes = phys.select_echoes(rng, power, threshold)
    assert echoes.strongest.tolist() == [1, 0, 0, 0] and echoes.last.tolist() == [1, 1, 0, 1]
    assert echoes.second.tolist() == [0, 1, -1, -1]
    # the odd block: the second-strongest when the strongest is the last, else the strongest; one echo: itself
    odd = phys.dual_pick(echoes)
    assert odd.tolist() == [0, 0, 0, 0]
    assert echoes.group[3, odd[3]] == echoes.group[3, echoes.last[3]]


def test_dual_mode_reports_the_second_strongest_when_the_strongest_is_last(write_scenario, tmp_path):
    """A dark post (rubber, 0.05) 9.5 m ahead of a bright wall (snow, 0.80) at 12.5 m, 7 sub-rays.

    Wherever a beam meets both, the wall is the last echo and the stronger one (at least 1 sub-ray of
    7 on the wall: 0.8 cos / 12.6^2 / 7 > 5e-4; at most 6 on the post: 0.05 / 9.5^2 x 6/7 < 5e-4), so
    the odd block carries the second-strongest echo, the post (HDL-32E manual, dual return mode):
    the post is a second return (``return_index`` 1) and the wall never is. A beam meeting one echo
    only gives one point (both blocks carry it).
    """
    post = {"name": "post", "kind": "mesh", "mesh": box_file(tmp_path, "post", (1.0, 1.0, 20.0), (0, 0, 5)),
            "position": latlon(0, 10.0), "material": "rubber"}
    back = {**wall(tmp_path, 12.5, "back"), "material": "snow"}
    data = scenario(tmp_path, obstacles=[post, back], lidar={"return_mode": "dual", "sub_rays": 7,
                                                             "beam_divergence_mrad": 10.0})
    d = sweeps(render(write_scenario, tmp_path, data))[0]
    second = d["return_index"] == 1
    assert not (second & (d["object_id"] == 2)).any()  # the wall is always the last echo
    assert (second & (d["object_id"] == 1)).sum() > 20  # the post behind the stronger wall echo: reported
    # each such firing (time, ring) also has the wall as its last echo, in the even block
    firing = np.stack([np.round(d["time"] * 1e7), d["ring"]], 1)
    last_wall = {tuple(f) for f in firing[(~second) & (d["object_id"] == 2)]}
    pairs = [tuple(f) in last_wall for f in firing[second & (d["object_id"] == 1)]]
    assert sum(pairs) > 20 and np.mean(pairs) > 0.9
    # one echo per firing elsewhere: no firing has two points of the wall
    wall_firings = firing[d["object_id"] == 2]
    assert np.unique(wall_firings, axis=0).shape[0] == wall_firings.shape[0]

"""Synthetic recordings of the evaluation tests (tests/tdm/test_evaluate*.py): truth, targets, tracks, radar sweeps."""

from __future__ import annotations

import json

import numpy as np
import yaml

from tdm.frames import EnuFrame

LAT0, LON0 = 59.43, 10.47
DURATION_S = 20.0


def _objects(t):
    """Truth at time t: (id, name, kind, east, north, cog, sog, ais). The own ship moves north at 2 m/s."""
    return [
        (0, "odin", "ownship", 0.0, 2.0 * t, 0.0, 2.0, False),
        (1, "alpha", "ship", 100.0, 5.0 * t, 0.0, 5.0, True),            # moving north, AIS
        (2, "bravo", "iceberg", 0.0, 300.0, 0.0, 0.0, False),
        (3, "charlie", "ship", -400.0, 0.0, 0.0, 0.0, False),            # silent ship, found late
        (4, "delta", "iceberg", 5000.0, 0.0, 0.0, 0.0, False),           # out of every range
        (5, "echo", "ship", 0.0, -3000.0, 0.0, 0.0, True),               # beyond radar, within AIS range
    ]


def _line(frame, t, east, north, **fields):
    lat, lon = frame.to_geodetic(east, north)
    return json.dumps({"t": t, "longitude": float(lon), "latitude": float(lat), **fields})


def _target_lines(frame):
    """Targets at truth + 3 m east every second: an id switch (bravo), a late target (charlie),
    a false target (99) and a covariance that makes charlie's NEES 9."""
    lines = []
    cov_a = [[4.0, 0.0], [0.0, 9.0]]  # e = (3, 0): NEES 9/4
    for t in np.arange(0.0, DURATION_S + 0.5, 1.0):
        t = float(t)
        truth = {o[1]: o for o in _objects(t)}
        common = {"cross_section_m2": 10.0, "sources": ["radar"]}
        a = truth["alpha"]
        lines.append(_line(frame, t, a[3] + 3, a[4], target_id=1, object_descriptor="vessel", cog_deg=358.0,
                           sog_mps=5.5, position_cov_m2=cov_a, **common))
        b = truth["bravo"]
        lines.append(_line(frame, t, b[3] + 3, b[4], target_id=2 if t < 10 else 7, object_descriptor="iceberg",
                           cog_deg=0.0, sog_mps=0.0, position_cov_m2=cov_a, **common))
        if t >= 5:
            ch = truth["charlie"]
            lines.append(_line(frame, t, ch[3] + 3, ch[4], target_id=3, object_descriptor="unknown", cog_deg=None,
                               sog_mps=0.0, position_cov_m2=[[1.0, 0.0], [0.0, 1.0]], **common))
        e = truth["echo"]
        lines.append(_line(frame, t, e[3] + 3, e[4], target_id=5, object_descriptor="vessel", cog_deg=0.0,
                           sog_mps=0.0, position_cov_m2=cov_a, **common))
        lines.append(_line(frame, t, 0.0, -500.0, target_id=99, object_descriptor="unknown", cog_deg=0.0,
                           sog_mps=0.0, position_cov_m2=cov_a, **common))
    return lines


def _track_lines(frame):
    """Per-sensor tracks: AIS exactly on alpha and echo, radar on bravo + 1 m east."""
    lines = []
    for t in np.arange(0.0, DURATION_S + 0.5, 1.0):
        t = float(t)
        truth = {o[1]: o for o in _objects(t)}
        for name, tid in (("alpha", 1), ("echo", 5)):
            o = truth[name]
            lines.append(_line(frame, t, o[3], o[4], sensor="ais", target_id=tid, object_descriptor="vessel",
                               cog_deg=o[5], sog_mps=o[6], position_cov_m2=[[4.0, 0.0], [0.0, 4.0]]))
        o = truth["bravo"]
        lines.append(_line(frame, t, o[3] + 1, o[4], sensor="radar", target_id=11, object_descriptor="iceberg",
                           cog_deg=0.0, sog_mps=0.0, position_cov_m2=[[1.0, 0.0], [0.0, 1.0]]))
    return lines


def make_recording(root, sensors=("radar", "ais", "nav"), targets=True, tracks=True):
    """A recording directory with truth, scenario, manifest and the TDM's outputs (no LiDAR sweeps).

    ``targets``: True for :func:`_target_lines`, False for none, or a function of the frame giving lines.
    """
    frame = EnuFrame(LAT0, LON0)
    root.mkdir(parents=True)
    with open(root / "truth.jsonl", "w", encoding="utf-8") as f:
        for t in np.round(np.arange(0.0, DURATION_S + 0.05, 0.1), 1):
            for oid, name, kind, east, north, cog, sog, ais in _objects(float(t)):
                lat, lon = frame.to_geodetic(east, north)
                f.write(json.dumps({"t": float(t), "id": oid, "name": name, "kind": kind, "lat": float(lat),
                                    "lon": float(lon), "x": east, "y": north, "heading_deg": cog, "cog_deg": cog,
                                    "sog_mps": sog, "length_m": 20.0, "beam_m": 5.0, "height_m": 5.0, "ais": ais,
                                    "mmsi": 257000000 + oid if ais else None}) + "\n")
    scenario = {"name": "synthetic", "duration_s": DURATION_S, "tdm": {"update_rate_hz": 1.0},
                "sensors": {"lidar": {"enabled": True, "range_max_m": 200.0},
                            "radar": {"enabled": True, "range_m": 1000.0},
                            "ais": {"enabled": True, "range_m": 10000.0}}}
    (root / "scenario.yaml").write_text(yaml.safe_dump(scenario), encoding="utf-8")
    manifest = {"format": "raysim-recording", "format_version": 1, "scenario": "synthetic", "seed": 1,
                "start_time": "2017-06-01T12:00:00Z", "duration_s": DURATION_S, "sensors_rendered": list(sensors)}
    (root / "manifest.json").write_text(json.dumps(manifest), encoding="utf-8")
    (root / "tdm").mkdir()
    if targets:
        lines = (_target_lines if targets is True else targets)(frame)
        (root / "tdm" / "detected_targets.jsonl").write_text("".join(x + "\n" for x in lines), encoding="utf-8")
    if tracks:
        (root / "tdm" / "sensor_tracks.jsonl").write_text("\n".join(_track_lines(frame)) + "\n", encoding="utf-8")
    return root


def save_sweep(sweeps, rev, ids, spokes=8):
    """Revolution ``rev`` (2.5 s, ``spokes`` spokes clockwise from the bow, heading north) whose rays reach ``ids``."""
    np.savez(sweeps / f"{rev:06d}.npz", time=2.5 * rev + np.arange(spokes) * 2.5 / spokes,
             azimuth_deg=np.arange(spokes) * 360.0 / spokes, heading_deg=np.zeros(spokes),
             object_id=np.array(ids, np.int32), object_spokes=np.full(len(ids), 10, np.int32))

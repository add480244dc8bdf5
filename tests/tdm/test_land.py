"""The TDM's land (chart) mask (issue 20): the recording's land.geojson read and checked, detections on
land dropped, no target reported on land, and a target on land counted as false by the evaluation."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
import yaml

from tdm.cli import main as tdm_main
from tdm.detections import Detections
from tdm.evaluate import evaluate
from tdm.frames import EnuFrame
from tdm.frontend.radar_config import RadarFrontEndConfig
from tdm.land import DETECTION_MARGIN_M, LandMask, beam_margin_m, drop_on_land, on_chart_land
from tdm.recording.land import ChartLand, read_land

from .conftest import render_recording
from .eval_helpers import LAT0, LON0, make_recording

#: The island of the rendered scene: 80 m x 50 m, its south shore 60 m north of the own ship (x east, y north, m).
ISLAND_XY_M = [(-40.0, 60.0), (40.0, 60.0), (40.0, 110.0), (-40.0, 110.0)]
#: Truth of the synthetic evaluation (tests/tdm/eval_helpers.py): the iceberg "bravo" lies still at (0, 300) m.
BRAVO_XY_M = (0.0, 300.0)


def land_geojson(corners_xy_m, frame: EnuFrame) -> dict:
    """A FeatureCollection of one polygon (corners x east, y north of the frame's origin, m), as raysim writes it."""
    lat, lon = frame.to_geodetic(*np.array(corners_xy_m, dtype=float).T)
    ring = [[float(a), float(b)] for a, b in zip(lon, lat)]
    return {"type": "FeatureCollection", "features": [{
        "type": "Feature", "properties": {"id": 9, "name": "island", "height_m": 12.0, "material": "rock"},
        "geometry": {"type": "Polygon", "coordinates": [ring + [ring[0]]]}}]}


@pytest.fixture(scope="module")
def island(tmp_path_factory) -> Path:
    """3 s of an island 60 m ahead seen by LiDAR and a fast radar, a boat crossing 40 m astern."""
    from tests.raysim.helpers import land_file, latlon, scenario

    folder = tmp_path_factory.mktemp("island")
    data = scenario(folder, duration=3.0)
    data["land"] = [{"name": "island", "file": land_file(folder, "island", ISLAND_XY_M, 12.0)}]
    data["sensors"] = {"lidar": {"mount": {"x_m": 0.0, "z_m": 3.0}},
                       "radar": {"spokes": 512, "samples": 256, "range_m": 463.0, "rpm": 120.0, "mount": {"z_m": 4.0}}}
    data["ships"] = [{"name": "boat", "speed_kn": 6, "length_m": 10, "waypoints": [latlon(-20, -40), latlon(60, -40)]}]
    path = folder / "island.yaml"
    path.write_text(yaml.safe_dump(data), encoding="utf-8")
    rec = render_recording(path, folder / "rec", 3.0, sensors=("lidar", "radar"))
    shutil.rmtree(rec / "rosbag", ignore_errors=True)
    return rec


def targets_on_land(out: Path, land: ChartLand) -> tuple[int, int]:
    """(reports of detected_targets.jsonl on the land, reports) of a ``tdm run`` output directory."""
    rows = [json.loads(line) for line in (out / "detected_targets.jsonl").read_text().splitlines()]
    inside = on_chart_land(land, [r["latitude"] for r in rows], [r["longitude"] for r in rows])
    return int(inside.sum()), len(rows)


# ---- end to end on a rendered island --------------------------------------------------------------

def test_tdm_run_reports_nothing_on_land_and_still_the_boat_at_sea(island, tmp_path):
    land = read_land(island)
    assert land is not None and len(land.polygons) == 1
    out = tmp_path / "out"
    assert tdm_main(["run", str(island), "-o", str(out), "--workers", "2"]) == 0  # the mask goes to the workers
    on_land, n = targets_on_land(out, land)
    assert on_land == 0 and n > 0  # the boat at sea is reported
    tracks = [json.loads(line) for line in (out / "sensor_tracks.jsonl").read_text().splitlines()]
    assert not on_chart_land(land, [r["latitude"] for r in tracks], [r["longitude"] for r in tracks]).any()


def test_without_its_chart_the_same_recording_gives_a_target_on_the_coast(island, tmp_path):
    """The control: the scene does make coast detections, which only the chart removes."""
    land = read_land(island)
    bare = tmp_path / "bare"
    shutil.copytree(island, bare, ignore=shutil.ignore_patterns("tdm"))
    (bare / "land.geojson").unlink()
    assert tdm_main(["run", str(bare), "-o", str(tmp_path / "out"), "--workers", "0"]) == 0
    on_land, _ = targets_on_land(tmp_path / "out", land)
    assert on_land > 0


def test_evaluate_and_info_read_the_chart(island, tmp_path, capsys):
    rec = tmp_path / "rec"
    shutil.copytree(island, rec, ignore=shutil.ignore_patterns("tdm"))
    assert tdm_main(["run", str(rec), "--workers", "0"]) == 0
    assert tdm_main(["evaluate", str(rec), "--no-plots"]) == 0
    metrics = json.loads((rec / "tdm" / "metrics.json").read_text())
    assert metrics["targets_on_land"] == 0 and metrics["reports_on_land"] == 0
    assert metrics["parameters"]["land_polygons"] == 1
    assert "targets_on_land" in metrics["definitions"]
    assert tdm_main(["info", str(rec)]) == 0
    assert "land: 1 polygons" in capsys.readouterr().out


# ---- the mask on synthetic detections -------------------------------------------------------------

def detections_at(positions_m) -> Detections:
    pos = np.asarray(positions_m, dtype=float)
    n = pos.shape[0]
    ones = np.ones(n)
    return Detections("radar", 0.0, np.arange(n, dtype=float), pos, np.tile(np.eye(2), (n, 1, 1)), ones, ones, ones,
                      ones, np.full(n, np.nan), np.ones(n, dtype=np.int64), np.hypot(pos[:, 0], pos[:, 1]),
                      strength_db=np.arange(n, dtype=float), beam_fill=ones)


def test_the_mask_drops_a_plot_on_land_and_keeps_one_at_sea():
    frame = EnuFrame(LAT0, LON0)
    land = ChartLand(tuple(_polygons(land_geojson(ISLAND_XY_M, frame))), Path("land.geojson"))
    mask = LandMask(land, frame, DETECTION_MARGIN_M)
    # on land; at sea 20 m south of the shore; 1 m off the shore (inside the margin); beyond the margin
    dets = detections_at([(0.0, 80.0), (0.0, 40.0), (0.0, 59.0), (0.0, 60.0 - DETECTION_MARGIN_M - 0.5)])
    kept = drop_on_land(dets, mask)
    assert kept.position_m.tolist() == [[0.0, 40.0], [0.0, 60.0 - DETECTION_MARGIN_M - 0.5]]
    assert kept.strength_db.tolist() == [1.0, 3.0] and kept.position_cov_m2.shape == (2, 2, 2)
    assert kept.sensor == "radar" and len(kept) == 2
    chart = LandMask(land, frame, 0.0)  # the output's test: the land itself
    assert chart.contains([0.0, 0.0, 0.0], [59.0, 60.01, 61.0]).tolist() == [False, True, True]
    assert drop_on_land(dets, None) is dets


def test_radar_plots_within_half_a_beam_of_a_far_coast_are_dropped_and_near_ones_kept():
    """A coast face's echo smears over the beam: at 1 km half of a 5.2 deg beam is 45 m across, at 50 m 2.3 m."""
    frame = EnuFrame(LAT0, LON0)
    far_coast = [(-300.0, 1000.0), (300.0, 1000.0), (300.0, 1200.0), (-300.0, 1200.0)]
    land = ChartLand(tuple(_polygons(land_geojson(far_coast, frame)) + _polygons(land_geojson(ISLAND_XY_M, frame))),
                     Path("land.geojson"))
    mask = LandMask(land, frame, DETECTION_MARGIN_M)
    assert beam_margin_m(np.array([1000.0]), 0.5, 5.2)[0] == pytest.approx(1000.0 * np.sin(np.radians(2.6)))
    # 30 m off the far coast (inside 43.7 m + 2.5 m), 60 m off it (outside), 5 m off the near island's face at 55 m
    dets = detections_at([(0.0, 970.0), (0.0, 940.0), (0.0, 52.0)])
    kept = drop_on_land(dets, mask, beam_fraction=0.5, beam_az_deg=5.2)
    assert kept.position_m.tolist() == [[0.0, 940.0], [0.0, 52.0]]
    assert len(drop_on_land(dets, mask)) == 3  # without the beam: all three are at sea


def test_the_default_radar_land_margin_drops_plots_within_a_whole_beam_of_a_coast():
    """With the front end's default margin (as the workers apply it, tdm/workers.py), a plot 0.75 of a beam off a
    far coast is dropped and one 1.25 beams off kept.

    A coast 30 dB or more over the sea paints through the two-way beam until its pattern is that far down,
    24 (theta / theta3)^2 dB: past half a beam (6 dB) out to about a whole one (24 dB). On busy_port seed
    34 such a smear, a tail of level 1-3 video 4-5 deg past the quay's edge at 640 m, made plots 37-40 m off
    the chart's land, outside half a beam (29 m), that confirmed as radar-only false targets.
    """
    config = RadarFrontEndConfig()
    frame = EnuFrame(LAT0, LON0)
    far_coast = [(-300.0, 1000.0), (300.0, 1000.0), (300.0, 1200.0), (-300.0, 1200.0)]
    mask = LandMask(ChartLand(tuple(_polygons(land_geojson(far_coast, frame))), Path("land.geojson")), frame,
                    DETECTION_MARGIN_M)
    beam_m = 1000.0 * np.sin(np.radians(config.beam_az_deg))  # 90.6 m across at 1 km
    dets = detections_at([(0.0, 1000.0 - 0.75 * beam_m), (0.0, 1000.0 - 1.25 * beam_m)])
    kept = drop_on_land(dets, mask, config.land_beam_fraction, config.beam_az_deg)
    assert kept.position_m[:, 1].tolist() == [pytest.approx(1000.0 - 1.25 * beam_m)]
    assert len(drop_on_land(dets, mask, 0.5, config.beam_az_deg)) == 2  # half a beam keeps the smear's plot


def _polygons(collection: dict):
    from shapely.geometry import shape

    return [shape(f["geometry"]) for f in collection["features"]]


# ---- broken land.geojson: one line, exit 2, nothing on disk ---------------------------------------

def _island_feature(island: Path) -> dict:
    return json.loads((island / "land.geojson").read_text())


BROKEN = {
    "not JSON": (lambda fc: '{"type": "FeatureCollection", "features": [', "line 1", "not valid JSON"),
    "empty": (lambda fc: "", "(file)", "empty"),
    "a Feature, not a collection": (lambda fc: fc["features"][0], "type", "FeatureCollection"),
    "a point": (lambda fc: _with_geometry(fc, {"type": "Point", "coordinates": [10.47, 59.43]}),
                "features[0].geometry.type", "Polygon or MultiPolygon"),
    "longitude out of range": (lambda fc: _with_position(fc, [190.0, 59.43]),
                               "features[0].geometry.coordinates[0][1]", "outside lon"),
    "not finite": (lambda fc: _with_position(fc, "NaN"), "features[0].geometry.coordinates[0][1]", "non-finite"),
    "not closed": (lambda fc: _with_last(fc), "features[0].geometry.coordinates[0]", "not closed"),
    "self-intersecting": (lambda fc: _bowtie(fc), "features[0].geometry.coordinates", "invalid polygon"),
}


def _with_geometry(fc: dict, geometry: dict) -> dict:
    fc["features"][0]["geometry"] = geometry
    return fc


def _with_position(fc: dict, position) -> str:
    fc["features"][0]["geometry"]["coordinates"][0][1] = [0, 0] if position == "NaN" else position
    text = json.dumps(fc)
    return text.replace("[0, 0]", "[NaN, 59.43]") if position == "NaN" else text


def _with_last(fc: dict) -> dict:
    ring = fc["features"][0]["geometry"]["coordinates"][0]
    ring[-1] = [ring[-1][0] + 0.001, ring[-1][1]]
    return fc


def _bowtie(fc: dict) -> dict:
    ring = fc["features"][0]["geometry"]["coordinates"][0]
    ring[1], ring[2] = ring[2], ring[1]
    return fc


@pytest.mark.parametrize("case", sorted(BROKEN))
def test_a_broken_land_file_is_one_line_exit_2_and_nothing_on_disk(island, tmp_path, capsys, case):
    make, where, what = BROKEN[case]
    rec = tmp_path / "rec"
    shutil.copytree(island, rec, ignore=shutil.ignore_patterns("tdm", "lidar", "radar", "ais", "nav"))
    shutil.copytree(island / "radar", rec / "radar")
    content = make(_island_feature(island))
    (rec / "land.geojson").write_text(content if isinstance(content, str) else json.dumps(content), encoding="utf-8")
    out = tmp_path / "out"
    assert tdm_main(["run", str(rec), "-o", str(out), "--workers", "0"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0, err
    assert f"land.geojson: {where}:" in err and what in err, err
    assert not out.exists()
    assert tdm_main(["info", str(rec)]) == 2
    assert f"land.geojson: {where}:" in capsys.readouterr().err


def test_no_land_file_is_no_land_but_a_directory_in_its_place_is_an_error(tmp_path):
    rec = make_recording(tmp_path / "rec")
    assert read_land(rec) is None
    (rec / "land.geojson").mkdir()
    with pytest.raises(Exception, match=r"land.geojson: \(file\): is a directory"):
        read_land(rec)


# ---- evaluation: a target on land is false --------------------------------------------------------

def test_evaluation_counts_a_target_on_land_as_false_even_next_to_an_object(tmp_path):
    """bravo (an iceberg at (0, 300) m) is reported 3 m east of it all along: matched at sea, false on land."""
    plain = evaluate(make_recording(tmp_path / "plain"))
    assert plain["targets_on_land"] == 0 and "bravo" not in plain["missed_objects"]
    assert not {2, 7} & set(plain["false_target_ids"])

    rec = make_recording(tmp_path / "land")
    x0, y0 = BRAVO_XY_M
    shore = [(x0 + 2.0, y0 - 10.0), (x0 + 30.0, y0 - 10.0), (x0 + 30.0, y0 + 10.0), (x0 + 2.0, y0 + 10.0)]
    (rec / "land.geojson").write_text(json.dumps(land_geojson(shore, EnuFrame(LAT0, LON0))), encoding="utf-8")
    m = evaluate(rec)
    assert m["targets_on_land"] == 2 and m["target_ids_on_land"] == [2, 7]  # bravo's two ids (an id switch)
    assert m["reports_on_land"] == 21  # every epoch
    assert {2, 7} <= set(m["false_target_ids"])
    assert "bravo" in m["missed_objects"]
    assert m["false_reports"] == plain["false_reports"] + 21
    assert m["ignored_reports"] == plain["ignored_reports"]
    # the radar track on bravo 1 m east of it, at sea: still matched
    radar = m["per_sensor"]["radar"]
    assert radar["targets_on_land"] == 0 and "bravo" not in radar["missed_objects"]
    assert m["ospa_m"] > plain["ospa_m"]

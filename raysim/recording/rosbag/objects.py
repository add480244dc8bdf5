"""Bag streams of the world's objects: truth at 1 Hz and the TDM's detected targets per epoch.

Truth (``truth.jsonl``): ``/truth/objects`` (MarkerArray: a CUBE per object and its name as a
TEXT_VIEW_FACING marker, since RViz and Foxglove never draw a CUBE's text) and ``/truth/geojson``
(foxglove_msgs/GeoJSON for the Map panel).

Targets (``tdm/detected_targets.jsonl``): ``/tdm/detected_targets`` (the full custom message),
``/tdm/markers`` (a box per target sized from its footprint, and a label "id class SOG"),
``/tdm/detections`` (vision_msgs/Detection3DArray, the class as the hypothesis) and
``/tdm/geojson``. Every MarkerArray starts with a DELETEALL marker, so a target that ended
disappears at once. Boxes of targets: a vessel's footprint ``A`` as ``sqrt(3 A)`` long and
``sqrt(A / 3)`` wide along its course (length over beam 3, typical of ships), anything else a
square of ``sqrt(A)``; height half the width, at least 1 m each way.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Callable, Iterator

import numpy as np

from groundfloor.units import KNOTS_PER_MPS
from raysim.recording.jsonl import every, row_centre_lat_lon, row_centre_xy, truth_epochs
from raysim.recording.rosbag.msgs import BagMessage, duration, header, make, point, pose, yaw_quaternion

__all__ = ["truth_streams", "target_streams", "KIND_COLOURS", "target_box_m"]

#: marker colours (r, g, b) per truth kind
KIND_COLOURS = {"ownship": (0.2, 0.6, 1.0), "ship": (1.0, 0.4, 0.2), "iceberg": (0.85, 0.95, 1.0),
                "buoy": (1.0, 0.85, 0.0), "mesh": (0.6, 0.6, 0.6)}
TARGET_COLOUR = (0.1, 1.0, 0.3)
LABEL_HEIGHT_M = 4.0  # text size of the labels
_CUBE, _TEXT, _DELETEALL = 1, 9, 3  # visualization_msgs/Marker type and action codes

NsOf = Callable[[float], int]


def _colour(rgb, alpha: float):
    return make("std_msgs/msg/ColorRGBA", r=float(rgb[0]), g=float(rgb[1]), b=float(rgb[2]), a=float(alpha))


def _box_and_label(t_ns: int, ns: str, ident: int, centre, yaw_rad: float, size_m, rgb, text: str,
                   lifetime_s: float) -> list:
    """A CUBE at ``centre`` (x, y, z of its middle, m, frame map) and its TEXT_VIEW_FACING label above it."""
    x, y, z = centre
    vec = "geometry_msgs/msg/Vector3"
    box = make("visualization_msgs/msg/Marker", header=header(t_ns, "map"), ns=ns, id=int(ident), type=_CUBE,
               action=0, pose=pose(x, y, z, yaw_quaternion(yaw_rad)), scale=point(*size_m, msgtype=vec),
               color=_colour(rgb, 0.6), lifetime=duration(lifetime_s), text=text)
    label = make("visualization_msgs/msg/Marker", header=header(t_ns, "map"), ns=f"{ns}/label", id=int(ident),
                 type=_TEXT, action=0, pose=pose(x, y, z + size_m[2] / 2.0 + LABEL_HEIGHT_M, (0.0, 0.0, 0.0, 1.0)),
                 scale=point(0.0, 0.0, LABEL_HEIGHT_M, msgtype=vec), color=_colour((1.0, 1.0, 1.0), 1.0),
                 lifetime=duration(lifetime_s), text=text)
    return [box, label]


def _delete_all(t_ns: int):
    return make("visualization_msgs/msg/Marker", header=header(t_ns, "map"), action=_DELETEALL)


def _geojson(t_ns: int, topic: str, features: list[dict]) -> BagMessage:
    text = json.dumps({"type": "FeatureCollection", "features": features}, separators=(",", ":"))
    return BagMessage(t_ns, topic, "foxglove_msgs/msg/GeoJSON", make("foxglove_msgs/msg/GeoJSON", geojson=text))


def _point_feature(lon: float, lat: float, properties: dict) -> dict:
    return {"type": "Feature", "geometry": {"type": "Point", "coordinates": [round(lon, 9), round(lat, 9)]},
            "properties": properties}


def truth_streams(recording: Path, ns_of: NsOf) -> Iterator[BagMessage]:
    """``/truth/objects`` and ``/truth/geojson`` at 1 Hz."""
    path = recording / "truth.jsonl"
    if not path.is_file():
        return
    for t_s, rows in truth_epochs(path, every(1.0)):
        t_ns = ns_of(t_s)
        markers = [_delete_all(t_ns)]
        for r in rows:
            size = (max(r["length_m"], 0.1), max(r["beam_m"], 0.1), max(r["height_m"], 0.1))
            markers += _box_and_label(t_ns, r["kind"], r["id"], (*row_centre_xy(r), size[2] / 2.0),
                                      math.radians(90.0 - r["heading_deg"]), size,
                                      KIND_COLOURS.get(r["kind"], (0.6, 0.6, 0.6)), r["name"], 1.5)
        yield BagMessage(t_ns, "/truth/objects", "visualization_msgs/msg/MarkerArray",
                         make("visualization_msgs/msg/MarkerArray", markers=markers))
        yield _geojson(t_ns, "/truth/geojson", [
            _point_feature(*row_centre_lat_lon(r)[::-1], {"name": r["name"], "kind": r["kind"], "id": r["id"],
                                                "sog_mps": r["sog_mps"], "heading_deg": r["heading_deg"]})
            for r in rows])


def target_box_m(descriptor: str, footprint_m2: float) -> tuple[float, float, float]:
    """(length, width, height) of a target's box from its class and footprint, m (module docstring)."""
    area = max(float(footprint_m2), 1.0)
    if descriptor == "vessel":
        length, width = math.sqrt(3.0 * area), math.sqrt(area / 3.0)
    else:
        length = width = math.sqrt(area)
    return max(length, 1.0), max(width, 1.0), max(width / 2.0, 1.0)


def _label(r: dict) -> str:
    return f"T{r['target_id']} {r['object_descriptor']} {r['sog_mps'] * KNOTS_PER_MPS:.1f} kn"


def _detection(t_ns: int, r: dict, xy, yaw_rad: float, size) -> object:
    cov = np.zeros((6, 6))
    cov[:2, :2] = np.asarray(r["position_cov_m2"], dtype=np.float64).reshape(2, 2)
    centre = pose(xy[0], xy[1], size[2] / 2.0, yaw_quaternion(yaw_rad))
    hypothesis = make("vision_msgs/msg/ObjectHypothesisWithPose",
                      hypothesis=make("vision_msgs/msg/ObjectHypothesis", class_id=r["object_descriptor"], score=1.0),
                      pose=make("geometry_msgs/msg/PoseWithCovariance", pose=centre, covariance=cov.ravel()))
    return make("vision_msgs/msg/Detection3D", header=header(t_ns, "map"), results=[hypothesis],
                bbox=make("vision_msgs/msg/BoundingBox3D", center=centre,
                          size=point(*size, msgtype="geometry_msgs/msg/Vector3")),
                id=str(r["target_id"]))


def _custom(r: dict) -> object:
    return make("tdm_msgs/msg/DetectedTarget", target_id=r["target_id"], object_descriptor=r["object_descriptor"],
                longitude=r["longitude"], latitude=r["latitude"], cog_deg=r["cog_deg"], sog_mps=r["sog_mps"],
                cross_section_m2=r["cross_section_m2"], sources=r["sources"],
                position_covariance_m2=np.array(r["position_cov_m2"], dtype=np.float64).ravel(),
                mmsi=r.get("mmsi") or 0)


def target_streams(recording: Path, frame, ns_of: NsOf, period_s: float) -> Iterator[BagMessage]:
    """The four target topics per TDM output epoch (``period_s`` apart: the markers' lifetime is 1.5 of it).

    Parameters
    ----------
    frame : raysim.geodesy.LocalFrame
        The scenario's local ENU frame (``map``).
    """
    path = recording / "tdm" / "detected_targets.jsonl"
    if not path.is_file():
        return
    for t_s, rows in truth_epochs(path, lambda t_s: True):  # any JSON-lines file grouped by its leading "t"
        t_ns = ns_of(t_s)
        yield BagMessage(t_ns, "/tdm/detected_targets", "tdm_msgs/msg/DetectedTargetArray",
                         make("tdm_msgs/msg/DetectedTargetArray", header=header(t_ns, "map"),
                              targets=[_custom(r) for r in rows]))
        x, y = frame.to_local(np.array([r["latitude"] for r in rows]), np.array([r["longitude"] for r in rows]))
        markers, detections = [_delete_all(t_ns)], []
        for r, xy in zip(rows, zip(np.atleast_1d(x).tolist(), np.atleast_1d(y).tolist())):
            size = target_box_m(r["object_descriptor"], r["cross_section_m2"])
            yaw = math.radians(90.0 - r["cog_deg"]) if r["object_descriptor"] == "vessel" else 0.0
            markers += _box_and_label(t_ns, "target", r["target_id"], (xy[0], xy[1], size[2] / 2.0), yaw, size,
                                      TARGET_COLOUR, _label(r), 1.5 * period_s)
            detections.append(_detection(t_ns, r, xy, yaw, size))
        yield BagMessage(t_ns, "/tdm/markers", "visualization_msgs/msg/MarkerArray",
                         make("visualization_msgs/msg/MarkerArray", markers=markers))
        yield BagMessage(t_ns, "/tdm/detections", "vision_msgs/msg/Detection3DArray",
                         make("vision_msgs/msg/Detection3DArray", header=header(t_ns, "map"), detections=detections))
        yield _geojson(t_ns, "/tdm/geojson", [
            _point_feature(r["longitude"], r["latitude"],
                           {"name": _label(r), "target_id": r["target_id"], "class": r["object_descriptor"],
                            "sog_mps": r["sog_mps"], "cog_deg": r["cog_deg"], "sources": r["sources"],
                            "mmsi": r.get("mmsi")}) for r in rows])

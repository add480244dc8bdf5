"""The scenario turned into a world: objects with ids, meshes and motions.

Truth ids are stable: the own ship is 0, then the obstacles in file order, then
the ships in file order, then the land entries (kind ``land``: in manifest.json and in the sensors'
object lists, not in truth.jsonl's epochs). Every object carries a :class:`raysim.meshes.BodyMesh`
(body frame) and a :class:`raysim.motion.Motion`; :meth:`World.scene_objects`
hands them to the ray engine.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from groundfloor.units import KNOT_MPS  # noqa: F401 (raysim.world.KNOT_MPS)
from raysim import meshes
from raysim.errors import InputError
from raysim.geodesy import LocalFrame
from raysim.limits import check_scene_triangles
from raysim.motion import Motion, SampledTrack, ShipMotion, Stationary, WaveMotion, TRACK_DT_S, waypoint_track
from raysim.pose import yaw_from_heading_deg
from raysim.random_streams import stream
from raysim.scenario import Scenario, ShipAis, WaveMotion as WaveMotionConfig
from raysim.trajectory_csv import read_trajectory_csv



@dataclass(frozen=True)
class WorldObject:
    """One object of the world.

    Attributes
    ----------
    object_id : int
        Truth id (own ship 0).
    name, kind : str
        Kind is ``ownship``, ``ship``, ``iceberg``, ``buoy``, ``mesh`` or ``land``.
    mesh : raysim.meshes.BodyMesh
        Geometry in the body frame.
    motion : raysim.motion.Motion
        Pose for any times.
    length_m, beam_m, height_m : float
        Dimensions for truth (above-water extents of the mesh, or the configured hull size).
    ais : ShipAis or None
        Transponder configuration, if any.
    key_path : str
        Where the object is in the scenario file (for messages).
    centre_body_m : tuple of float
        Centre of the above-water extents in the body frame (x, y), m
        (:meth:`raysim.meshes.BodyMesh.centre_above_water_m`): where the length x beam box of truth
        stands, and the point truth.jsonl reports as the object's centre.
    """

    object_id: int
    name: str
    kind: str
    mesh: meshes.BodyMesh
    motion: Motion
    length_m: float
    beam_m: float
    height_m: float
    ais: ShipAis | None
    key_path: str
    centre_body_m: tuple[float, float] = (0.0, 0.0)


class World:
    """Objects, motions and the local frame of a resolved scenario.

    Parameters
    ----------
    scenario : Scenario
        A resolved scenario (:func:`raysim.scenario.load_scenario`).
    """

    def __init__(self, scenario: Scenario):
        self.scenario = scenario
        self.frame = LocalFrame(scenario.origin.lat, scenario.origin.lon)
        self._mesh_cache: dict = {}
        self._scene_objects: list | None = None
        objects = [self._own_ship()]
        for i, obstacle in enumerate(scenario.obstacles):
            objects.append(self._obstacle(len(objects), i, obstacle))
        for i, ship in enumerate(scenario.ships):
            objects.append(self._ship(len(objects), i, ship))
        objects += self._land(len(objects))
        self.objects: tuple[WorldObject, ...] = tuple(objects)
        check_scene_triangles([(o.key_path, o.mesh.n_triangles) for o in objects], scenario.source_file or "scenario")

    @property
    def own_ship(self) -> WorldObject:
        return self.objects[0]

    def drive_own_ship(self, motion) -> None:
        """Give the own ship another motion (:class:`raysim.motion.Motion`; live mode's fed own ship)."""
        self.objects = (replace(self.objects[0], motion=motion),) + self.objects[1:]
        self._scene_objects = None

    def scene_objects(self) -> list:
        """The objects as the ray engine wants them (:class:`raysim.scene.SceneObject`)."""
        from raysim.scene import SceneObject

        from raysim.land.objects import land_tiles

        if self._scene_objects is not None:
            return list(self._scene_objects)
        out = []
        for o in self.objects:
            for mesh in land_tiles(o.mesh) if o.kind == "land" else (o.mesh,):  # land: in tiles (the engine's culling)
                out.append(SceneObject(o.object_id, mesh.vertices_m, mesh.faces, mesh.face_material, o.motion))
        self._scene_objects = out
        return list(out)

    # ------------------------------------------------------------------ builders

    def _xy(self, lat_lon) -> np.ndarray:
        lat_lon = np.asarray(lat_lon, dtype=float).reshape(-1, 2)
        x, y = self.frame.to_local(lat_lon[:, 0], lat_lon[:, 1])
        return np.stack([x, y], axis=1)

    def _load(self, path: Path, material: str, where: str) -> meshes.BodyMesh:
        key = ("file", str(path), material)
        if key not in self._mesh_cache:
            try:
                self._mesh_cache[key] = meshes.load_mesh(path, material=material)
            except meshes.MeshError as exc:
                raise InputError(self.scenario.source_file or "scenario", where, exc.message) from None
        return self._mesh_cache[key]

    def _check_reference_point(self, ship, length_m: float, beam_m: float, where: str) -> None:
        """A transponder's reference point must stand on its hull: at most its length from the bow and its beam from
        the port side (the mesh's extents for a mesh ship)."""
        point = ship.ais.reference_point_m if ship.ais is not None else None
        if point is not None and (point[0] > length_m or point[1] > beam_m):
            raise InputError(self.scenario.source_file or "scenario", where + ".ais.reference_point_m",
                             f"[{point[0]:g}, {point[1]:g}] m lies off the hull: at most [{length_m:g}, {beam_m:g}] "
                             f"(length, beam)")

    def _waves(self, cfg: WaveMotionConfig, name: str) -> WaveMotion:
        return WaveMotion(
            cfg.roll_amplitude_deg, cfg.roll_period_s, cfg.pitch_amplitude_deg, cfg.pitch_period_s,
            cfg.heave_amplitude_m, cfg.heave_period_s, stream(self.scenario.seed, f"{name}.waves"),
        )

    def _own_ship(self) -> WorldObject:
        s = self.scenario
        own = s.own_ship
        waves = self._waves(own.motion, "own_ship")
        if own.route is not None:
            track = waypoint_track(
                self._xy(own.route.waypoints), own.route.speed_kn * KNOT_MPS, s.duration_s,
                own.route.heading_time_constant_s, own.route.at_end,
            )
        elif own.trajectory_csv is not None:
            track, carries_attitude = self._csv_track(own.trajectory_csv)
            if carries_attitude:
                waves = None  # the file's own roll/pitch/heave replace the wave model
        else:
            xy = self._xy(own.position)[0]
            yaw = float(yaw_from_heading_deg(own.heading_deg))
            track = SampledTrack(TRACK_DT_S, xy[:1], xy[1:], np.array([yaw]), speed_mps=np.zeros(1), yaw_rate_rps=np.zeros(1))
        if own.mesh is not None:
            mesh = self._load(own.mesh, own.material, "own_ship.mesh")
        else:
            mesh = meshes.own_ship(own.length_m, own.beam_m)
        length, beam, height = mesh.extents_above_water_m()
        return WorldObject(0, own.name, "ownship", mesh, ShipMotion(track, waves), length, beam, height, None, "own_ship",
                           mesh.centre_above_water_m())

    def _csv_track(self, path: Path) -> tuple[SampledTrack, bool]:
        """The trajectory file resampled on the track grid, and whether it carries roll/pitch/heave."""
        table = read_trajectory_csv(path)
        t = np.arange(0.0, table.t_s[-1] + 0.5 * TRACK_DT_S, TRACK_DT_S)
        x, y = self.frame.to_local(table.lat_deg, table.lon_deg)
        yaw = np.unwrap(yaw_from_heading_deg(table.heading_deg))
        interp = lambda col: None if col is None else np.interp(t, table.t_s, col)  # noqa: E731
        pitch = interp(table.pitch_deg)
        track = SampledTrack(
            TRACK_DT_S, np.interp(t, table.t_s, x), np.interp(t, table.t_s, y), np.interp(t, table.t_s, yaw),
            roll_rad=None if table.roll_deg is None else np.radians(interp(table.roll_deg)),
            pitch_rad=None if pitch is None else -np.radians(pitch),
            z_m=interp(table.heave_m),
        )
        return track, any(c is not None for c in (table.roll_deg, table.pitch_deg, table.heave_m))

    def _obstacle(self, object_id: int, index: int, o) -> WorldObject:
        where = f"obstacles[{index}]"
        xy = self._xy(o.position)[0]
        motion = Stationary([xy[0], xy[1], 0.0], float(yaw_from_heading_deg(o.heading_deg)))
        if o.kind == "iceberg":
            mesh = meshes.iceberg(o.radius_m, o.height_m, o.seed)
        elif o.kind == "buoy":
            key = ("buoy",)
            mesh = self._mesh_cache.setdefault(key, meshes.buoy())
        else:
            mesh = self._load(o.mesh, o.material, where + ".mesh")
        length, beam, height = mesh.extents_above_water_m()
        return WorldObject(object_id, o.name, o.kind, mesh, motion, length, beam, height, None, where,
                           mesh.centre_above_water_m())

    def _land(self, first_id: int) -> list[WorldObject]:
        """The ``land`` entries, one object each (kind ``land``), standing at the origin in the local frame."""
        from raysim.land.objects import land_bodies

        objects = []
        for k, body in enumerate(land_bodies(self.scenario, self.frame)):
            length, beam, height = body.mesh.extents_above_water_m()
            objects.append(WorldObject(first_id + k, body.name, "land", body.mesh, Stationary([0.0, 0.0, 0.0], 0.0),
                                       length, beam, height, None, body.key_path))
        return objects

    def _ship(self, object_id: int, index: int, ship) -> WorldObject:
        where = f"ships[{index}]"
        s = self.scenario
        track = waypoint_track(
            self._xy(ship.waypoints), ship.speed_kn * KNOT_MPS, s.duration_s, ship.heading_time_constant_s,
            ship.at_end, heading_rad=float(yaw_from_heading_deg(ship.heading_deg)),
        )
        if ship.mesh is not None:
            mesh = self._load(ship.mesh, ship.material, where + ".mesh")
            length, beam, height = mesh.extents_above_water_m()
        else:
            key = ("hull", ship.length_m, ship.beam_m)
            if key not in self._mesh_cache:
                self._mesh_cache[key] = meshes.ship_hull(ship.length_m, ship.beam_m)
            mesh = self._mesh_cache[key]
            _, _, height = mesh.extents_above_water_m()
            length, beam = ship.length_m, ship.beam_m
        self._check_reference_point(ship, length, beam, where)
        return WorldObject(object_id, ship.name, "ship", mesh, ShipMotion(track), length, beam, height, ship.ais, where,
                           mesh.centre_above_water_m())


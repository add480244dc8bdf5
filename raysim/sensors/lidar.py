"""Velodyne HDL-32E on the own ship: raw packets (PCAP) and per-revolution sweeps (NPZ).

The firing schedule is the sensor's (:mod:`groundfloor.hdl32e`): one laser every
1.152 us in DSR order, 46.08 us cycles, 12 cycles per packet (6 in dual-return
mode). Every firing is cast from the sensor pose at its own instant -- the own
ship's pose is evaluated at every cycle boundary and interpolated to each firing
-- against every object at its pose at that instant (:class:`raysim.scene.Scene`),
so own-ship yaw, roll and pitch and target motion distort a sweep as they do on
the real sensor. Physics: :mod:`raysim.sensors.lidar_physics` and :mod:`raysim.sea`.

Work is done a chunk of packets (about one revolution) at a time: memory stays flat.
"""

from __future__ import annotations

import datetime as dt
import time
from collections import deque
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from groundfloor import hdl32e
from groundfloor.frames import mount_transform  # noqa: F401 (raysim.sensors.lidar.mount_transform)
from raysim import jit
from raysim.materials import material_index, material_table
from raysim.random_streams import chunk_stream, stream
from raysim.recording import nmea
from raysim.recording.velodyne import PcapWriter, encode_data_packets, encode_position_packet
from raysim.scene import NO_HIT, SEA_ID, intersect_sea
from raysim.sea import FoamField
from raysim.sensors import lidar_kernels
from raysim.sensors import lidar_physics as phys
from raysim.sensors.blas_threads import single_blas_thread
from raysim.sensors.carrier import CarrierScene
from raysim.sensors.lidar_rays import CAST_RANGE_MARGIN_M, LidarGeometry, _Rays
from raysim.sensors.lidar_run import render_chunks
from raysim.world import World

SOURCE_OBJECT, SOURCE_SEA, SOURCE_WEATHER = 0, 1, 2
FOAM_REFLECTANCE = 0.25  # whitecap foam at 905 nm, diffuse (unverified; bright in the visible, darker in NIR)
#: Largest value of the packets' 16-bit distance field, 2 mm units (HDL-32E user manual, 131.07 m).
MAX_DISTANCE_UNITS = 65535
#: Diffuse reflectivity byte per unit of apparent reflectance (0..100,
#: :func:`raysim.sensors.lidar_physics.reflectivity_byte`).
REFLECTIVITY_BYTE_PER_UNIT_REFLECTANCE = 100
#: Encoder azimuth steps (0.01 deg) to degrees.
DEG_PER_CENTIDEG = 0.01
#: Returns per firing in dual-return mode (last and strongest): a packet holds half as many cycles.
DUAL_RETURNS = 2
#: Slack of the firing-cycle count of the run, in cycles: a duration that is a whole number of
#: cycles in decimal is not always one in binary floating point.
CYCLE_COUNT_SLACK = 1e-9
SECONDS_PER_HOUR = 3600.0
MICROSECONDS_PER_SECOND = 1e6
DEG_PER_TURN = 360.0


@dataclass
class Firings:
    """What the sensor measured in a chunk of C firing cycles.

    ``returns`` is 1 (strongest or last) or 2 (dual: [last, strongest], the second-strongest in
    place of the strongest when the strongest is the last: :func:`raysim.sensors.lidar_physics.dual_pick`).
    distance_units, reflectivity, object_id, source: (C, returns, 32).
    """

    cycle_time_s: np.ndarray
    block_azimuth: np.ndarray
    firing_azimuth: np.ndarray
    distance_units: np.ndarray
    reflectivity: np.ndarray
    object_id: np.ndarray
    source: np.ndarray


@dataclass
class _Cast:
    """A chunk's rays cast (:meth:`LidarRenderer._cast_stage`): the M rays cast, their hits and indices among
    the chunk's N rays, the candidates with the own ship's echoes in, and the own ship's body-frame hits (or None)."""

    cycle_time_s: np.ndarray
    firing_azimuth: np.ndarray
    cand: "_Candidates"
    cast: _Rays
    hits: object
    free: np.ndarray
    own_body: tuple | None


@dataclass
class _Candidates:
    """Candidate echoes of F firings, (F, E) each: E = K sub-rays (+ 1 weather false echo)."""

    range_m: np.ndarray
    power: np.ndarray
    byte: np.ndarray
    object_id: np.ndarray
    source: np.ndarray

    @classmethod
    def empty(cls, f: int, e: int) -> _Candidates:
        """No echo anywhere: infinite range, zero power, id -1."""
        return cls(np.full((f, e), np.inf), np.zeros((f, e)), np.zeros((f, e), dtype=np.uint8),
                   np.full((f, e), -1, dtype=np.int32), np.zeros((f, e), dtype=np.uint8))


@dataclass
class LidarChunk:
    """One chunk of a LiDAR render (:meth:`LidarRenderer.chunks`).

    Attributes
    ----------
    time_s : (C,) float64
        Start of each firing cycle, s since the scenario start.
    firings : Firings
        What each firing measured.
    payloads : (P, 1206) uint8
        The chunk's data packets.
    sent_s : (P,) float64
        When each data packet leaves the sensor (the end of its last cycle), s.
    position_times_s : list of float
        Times of the position packets due in the chunk, s.
    """

    time_s: np.ndarray
    firings: Firings
    payloads: np.ndarray
    sent_s: np.ndarray
    position_times_s: list


class LidarRenderer(LidarGeometry):
    """Renders the HDL-32E of a world's own ship.

    Parameters
    ----------
    world : raysim.world.World
    scene : raysim.sensors.carrier.CarrierScene
        The ray engine over the world's objects (sea included), own ship cast in its body frame.
    """

    def __init__(self, world: World, scene: CarrierScene):
        self.world = world
        self.scene = scene
        s = world.scenario
        self.cfg = s.sensors.lidar
        self.dual = self.cfg.return_mode == "dual"
        self.cycles_per_packet = hdl32e.BLOCKS_PER_PACKET // (DUAL_RETURNS if self.dual else 1)
        self.mount_rotation, self.mount_translation = mount_transform(self.cfg.mount)
        self.alpha = phys.extinction_per_m(s.environment.fog_visibility_m, s.environment.rain_mm_per_h)
        self.threshold = phys.detection_threshold(self.cfg.detection_reflectance)
        self.foam = FoamField(s.environment.wind_speed_mps, s.environment.sea_state, s.environment.wind_from_deg,
                              stream(s.seed, "sea.foam"))
        self.noise_rng = chunk_stream(s.seed, "lidar.range_noise", 0)  # chunks() gives each chunk its own
        self.weather_rng = chunk_stream(s.seed, "lidar.weather", 0)
        self.materials = material_table()
        self.sea_material = material_index("sea")
        self.offsets = phys.sub_ray_offsets(self.cfg.sub_rays, self.cfg.beam_divergence_mrad * 1e-3)
        self.own_table = self._own_ship_table() if self.offsets.shape[0] == 1 else None
        self.start_unix_s = s.start_time.timestamp()
        self.n_cycles = int(np.floor(s.duration_s / hdl32e.CYCLE_DT_S + CYCLE_COUNT_SLACK))
        self.n_packets = self.n_cycles // self.cycles_per_packet
        #: (scenario seconds, wall seconds) of each chunk of the last run (benchmarks read it)
        self.chunk_wall_s: list[tuple[float, float]] = []

    def measure(self, cycle_time_s: np.ndarray, block_azimuth: np.ndarray, firing_azimuth: np.ndarray) -> Firings:
        """Cast and measure C firing cycles (:meth:`_cast_stage`, then :meth:`_echo_stage`)."""
        return self._echo_stage(self._cast_stage(cycle_time_s, firing_azimuth), block_azimuth)

    def _cast_stage(self, cycle_time_s: np.ndarray, firing_azimuth: np.ndarray) -> _Cast:
        """The rays of C firing cycles into the world: the own ship's echoes answered, the rest cast.

        No random numbers are drawn here, so a chunk's cast may run while the chunk before it is measured.
        """
        c = cycle_time_s.shape[0]
        k = self.offsets.shape[0]
        f = c * hdl32e.N_LASERS
        n = f * k
        # candidate echoes per firing: K sub-rays and, in weather, one false echo near the sensor
        cand = _Candidates.empty(f, k + (1 if self.alpha > 0 else 0))
        if jit.ENABLED and self.own_table is not None:  # one ray per beam, the own ship from its table: one pass
            free, cast = self._rays_past_own_ship(cycle_time_s, firing_azimuth, cand)
            hits, own_body = self._cast(cast), None
        else:
            origins_s, directions_s = self._sensor_rays(firing_azimuth)
            o_w, d_w, t_firing = self._world_rays(cycle_time_s, origins_s, directions_s)
            rays = _Rays(o_w.reshape(n, 3), d_w.reshape(n, 3),
                         np.repeat(t_firing.reshape(-1), k) if k > 1 else t_firing.reshape(-1))
            if self.own_table is not None:
                hits, free, cast, own_body = self._cast_past_own_ship(cand, rays, firing_azimuth)
            else:
                hits, free, cast, own_body = self._cast_with_own_ship(rays, origins_s, directions_s)
        return _Cast(cycle_time_s, firing_azimuth, cand, cast, hits, free, own_body)

    def _echo_stage(self, stage: _Cast, block_azimuth: np.ndarray) -> Firings:
        """The echoes of a cast's hits and the returns the sensor reports (this chunk's random streams)."""
        c, k = stage.cycle_time_s.shape[0], self.offsets.shape[0]
        f = c * hdl32e.N_LASERS
        cand = stage.cand
        self._world_echoes(cand, stage.cast, stage.hits, stage.free, stage.own_body, k)
        if self.alpha > 0:
            self._false_echoes(cand, f, k)
        units, refl, oid, src = self._returns(cand, f)
        shape = (units.shape[0], c, hdl32e.N_LASERS)
        to_c = lambda a: np.moveaxis(a.reshape(shape), 0, 1)  # noqa: E731
        return Firings(stage.cycle_time_s, block_azimuth, stage.firing_azimuth, to_c(units), to_c(refl), to_c(oid),
                       to_c(src))

    def _cast(self, rays: _Rays):
        """The world's first hits of ``rays`` (the own ship's beams already answered), to the range limit and margin."""
        return self.scene.world.cast(rays.origins_m, rays.directions, rays.times_s,
                                     max_range_m=self.cfg.range_max_m + CAST_RANGE_MARGIN_M)

    def _cast_past_own_ship(self, cand: _Candidates, rays: _Rays, firing_azimuth: np.ndarray):
        """The own ship's echoes from the beam table into candidate 0; only the other rays go into the world.

        The numpy path of :meth:`_rays_past_own_ship`. Returns the world's hits, the indices of the rays
        cast into the world, those rays, and None (no own-ship body-frame hits among them).
        """
        t = self.own_table
        # gathers by np.take: the same values as fancy indexing, several times faster on these sizes
        key = (firing_azimuth.astype(np.int32) * hdl32e.N_LASERS + np.arange(hdl32e.N_LASERS, dtype=np.int32)).reshape(-1)
        on_own = np.take(t["hit"], key)
        wet = np.flatnonzero(np.take(t["wet"], key))
        if wet.size:
            r_wet = np.take(t["range_m"], np.take(key, wet)).astype(np.float64)
            sea_m = intersect_sea(np.take(rays.origins_m, wet, axis=0)[:, 2], np.take(rays.directions, wet, axis=0)[:, 2])
            on_own[wet] &= ~(sea_m < r_wet)
        own = np.flatnonzero(on_own)
        key_own = np.take(key, own)
        cand.range_m[:, 0][own] = np.take(t["range_m"], key_own)  # float32 -> float64, exact
        cand.power[:, 0][own] = np.take(t["power"], key_own)
        cand.byte[:, 0][own] = np.take(t["byte"], key_own)
        cand.object_id[:, 0][own] = t["object_id"]
        free = np.flatnonzero(~on_own)
        cast = _Rays(np.take(rays.origins_m, free, axis=0), np.take(rays.directions, free, axis=0),
                     np.take(rays.times_s, free))
        return self._cast(cast), free, cast, None

    def _cast_with_own_ship(self, rays: _Rays, origins_s: np.ndarray, directions_s: np.ndarray):
        """Every ray cast, the own ship in its body frame (sub-rays: no beam table).

        Returns the hits, the indices of all rays, the rays, and ``(on_carrier, body-frame directions)``.
        """
        n = rays.origins_m.shape[0]
        o_b = origins_s.reshape(n, 3) @ self.mount_rotation.T + self.mount_translation
        d_b = directions_s.reshape(n, 3) @ self.mount_rotation.T
        hits, on_carrier = self.scene.cast(rays.origins_m, rays.directions, rays.times_s, o_b, d_b,
                                           max_range_m=self.cfg.range_max_m + CAST_RANGE_MARGIN_M)
        return hits, np.arange(n), rays, (on_carrier, d_b)

    def _world_echoes(self, cand: _Candidates, cast: _Rays, hits, free: np.ndarray, own_body, k: int) -> None:
        """Echo range, power, byte, id and source of the rays that hit something, into the candidates.

        ``cast``: the M rays cast (row i: the chunk's ray ``free[i]``), ``hits`` theirs. Physics only
        on those rays (the sky is a large part of a sweep); calm sea is a mirror (nothing comes back),
        foam a diffuse reflector.
        """
        o_w, d_w, times = cast.origins_m, cast.directions, cast.times_s
        if jit.ENABLED and k == 1 and own_body is None:  # two compiled passes around the foam test, the same values
            lidar_kernels.world_echoes(hits, free, o_w, d_w, times, self.materials, self.alpha, self.threshold,
                                       self.foam, cand, SEA_ID, SOURCE_SEA, FOAM_REFLECTANCE)
            return
        hit_local = np.flatnonzero(hits.object_id != NO_HIT)
        h = np.take(free, hit_local)
        r_h = np.take(hits.range_m, hit_local)
        obj_h = np.take(hits.object_id, hit_local)
        normal_h = np.take(hits.normal, hit_local, axis=0)
        cos_h = np.abs(np.einsum("ij,ij->i", normal_h, np.take(d_w, hit_local, axis=0)))
        if own_body is not None:  # own-ship normals are in its body frame: use the body-frame direction
            on_carrier, d_b = own_body
            own_h = np.flatnonzero(on_carrier[h])
            cos_h[own_h] = np.abs(np.einsum("ij,ij->i", normal_h[own_h], d_b[h[own_h]]))
        mat_h = np.take(hits.material, hit_local)
        reflectance = np.take(self.materials["reflectance_905nm"], mat_h).astype(np.float64)
        retro = np.take(self.materials["retroreflective"], mat_h)
        source = np.zeros(h.size, dtype=np.uint8)
        sea = obj_h == SEA_ID
        on_sea = np.flatnonzero(sea)
        if on_sea.size:
            reflectance[on_sea] = 0.0  # calm water: a specular mirror, nothing comes back
            source[on_sea] = SOURCE_SEA
            # foam is looked up only where a foam echo could be detected at all
            foam_power = phys.echo_power(FOAM_REFLECTANCE * np.take(cos_h, on_sea), np.take(r_h, on_sea), self.alpha)
            could = np.take(on_sea, np.flatnonzero(foam_power >= self.threshold))
            if could.size:
                rays_c = np.take(hit_local, could)
                r_c = np.take(r_h, could)
                o_c, d_c = np.take(o_w, rays_c, axis=0), np.take(d_w, rays_c, axis=0)
                foam = self.foam.is_foam(o_c[:, 0] + r_c * d_c[:, 0], o_c[:, 1] + r_c * d_c[:, 1], np.take(times, rays_c))
                reflectance[could[foam]] = FOAM_REFLECTANCE
        power_h = phys.echo_power(reflectance * cos_h, r_h, self.alpha) / k
        values = ((cand.range_m, r_h), (cand.power, power_h), (cand.byte, phys.reflectivity_byte(reflectance, cos_h, retro)),
                  (cand.object_id, np.where(sea, -1, obj_h)), (cand.source, source))
        if k == 1:  # the candidates of column 0, by ray
            for column, value in values:
                column[:, 0][h] = value
        else:
            row, col = h // k, h % k
            for column, value in values:
                column[row, col] = value

    def _false_echoes(self, cand: _Candidates, f: int, k: int) -> None:
        """Weather's false echoes near the sensor (fog droplets, rain drops) into candidate column ``k``."""
        p_false = 1.0 - np.exp(-self.alpha * phys.FALSE_ECHO_WINDOW_M)
        has = self.weather_rng.random(f) < p_false
        r_false = self.cfg.range_min_m + self.weather_rng.exponential(phys.FALSE_ECHO_MEAN_RANGE_M, f)
        has &= r_false < phys.FALSE_ECHO_WINDOW_M
        cand.range_m[has, k] = r_false[has]
        cand.power[has, k] = phys.echo_power(np.full(has.sum(), phys.FALSE_ECHO_REFLECTANCE), r_false[has], self.alpha)
        cand.byte[has, k] = round(REFLECTIVITY_BYTE_PER_UNIT_REFLECTANCE * phys.FALSE_ECHO_REFLECTANCE)
        cand.source[has, k] = SOURCE_WEATHER

    def _returns(self, cand: _Candidates, f: int):
        """The returns the sensor reports per firing: (R, F) distance units, reflectivity bytes, ids, sources.

        Echoes are grouped and picked by the return mode (R = 2 in dual mode), range noise added,
        the range quantised to 2 mm units and kept within the sensor's range.
        """
        if jit.ENABLED and cand.range_m.shape[1] == 1 and not self.dual:  # one candidate: strongest = last
            return lidar_kernels.single_returns(cand, self.threshold, self.noise_rng, self.cfg.range_noise_m,
                                                hdl32e.DISTANCE_UNIT_M, self.cfg.range_min_m, self.cfg.range_max_m,
                                                MAX_DISTANCE_UNITS)
        echoes = phys.select_echoes(cand.range_m, cand.power, self.threshold)
        strongest, last, group_r, group_id = echoes.strongest, echoes.last, echoes.group_range, echoes.group
        picks = [last, phys.dual_pick(echoes)] if self.dual else [last if self.cfg.return_mode == "last" else strongest]
        n_ret = len(picks)
        units = np.zeros((n_ret, f), dtype=np.uint16)
        refl = np.zeros((n_ret, f), dtype=np.uint8)
        oid = np.full((n_ret, f), -1, dtype=np.int32)
        src = np.zeros((n_ret, f), dtype=np.uint8)
        e = cand.range_m.shape[1]
        for i, pick in enumerate(picks):
            rows = np.flatnonzero(pick >= 0)
            flat = rows * e + np.take(pick, rows)  # (row, column) of the picked candidates, flattened
            measured = np.take(group_r.reshape(-1), flat)
            if self.cfg.range_noise_m > 0:
                measured = measured + self.noise_rng.normal(0.0, self.cfg.range_noise_m, rows.size)
            q = np.round(measured / hdl32e.DISTANCE_UNIT_M)
            ok = np.flatnonzero((measured >= self.cfg.range_min_m) & (measured <= self.cfg.range_max_m) & (q >= 1)
                                & (q <= MAX_DISTANCE_UNITS))
            rows, flat = np.take(rows, ok), np.take(flat, ok)
            units[i][rows] = np.take(q, ok)
            refl[i][rows] = np.take(cand.byte.reshape(-1), flat)
            oid[i][rows] = np.take(cand.object_id.reshape(-1), flat)
            src[i][rows] = np.take(cand.source.reshape(-1), flat)
        if self.dual:  # a single echo group: both blocks carry the same measurement
            rows = np.arange(f)
            same = (group_id[rows, np.maximum(picks[0], 0)] == group_id[rows, np.maximum(picks[1], 0)]) & (units[0] > 0)
            units[1] = np.where(same, units[0], units[1])
            refl[1] = np.where(same, refl[0], refl[1])
            oid[1] = np.where(same, oid[0], oid[1])
            src[1] = np.where(same, src[0], src[1])
        return units, refl, oid, src

    # ------------------------------------------------------------------ outputs

    def points(self, fire: Firings) -> tuple[dict[str, np.ndarray], np.ndarray]:
        """Sweep arrays (the NPZ contract) of a chunk's returns in firing order, and each point's cycle index.

        Geometry exactly as a decoder reconstructs it from the packets:
        ``x = d cos w cos a, y = -d cos w sin a, z = d sin w + z_offset``.
        """
        if jit.ENABLED and not self.dual:  # one return a firing: one compiled pass, the same values
            return lidar_kernels.points(fire.distance_units, fire.reflectivity, fire.object_id, fire.source,
                                        fire.firing_azimuth, fire.cycle_time_s)
        units = fire.distance_units  # (C, R, 32)
        keep = units > 0
        if self.dual:  # a repeated echo (same distance in both blocks) is one point, as decoders report it
            keep[:, 1] &= units[:, 1] != units[:, 0]
        # np.nonzero's (cycle, return, laser) indices from the flat ones; gathers by np.take (same values, faster)
        flat = np.flatnonzero(keep)
        per_cycle = units.shape[1] * hdl32e.N_LASERS
        cc, rest = np.divmod(flat, per_cycle)
        rr, jj = np.divmod(rest, hdl32e.N_LASERS)
        gather = lambda a: np.take(a.reshape(-1), flat)  # noqa: E731 (a (C, R, 32) array at the kept returns)
        d = gather(units).astype(np.float64) * hdl32e.DISTANCE_UNIT_M
        az = np.take(fire.firing_azimuth.reshape(-1), cc * hdl32e.N_LASERS + jj)
        xy = d * np.take(hdl32e.COS_ELEVATION, jj)
        arrays = {
            "x": (xy * np.take(hdl32e.COS_AZIMUTH_STEP, az)).astype(np.float32),
            "y": (-xy * np.take(hdl32e.SIN_AZIMUTH_STEP, az)).astype(np.float32),
            "z": (d * np.take(hdl32e.SIN_ELEVATION, jj) + np.take(hdl32e.Z_OFFSET_M, jj)).astype(np.float32),
            "intensity": gather(fire.reflectivity).astype(np.uint8),
            "ring": np.take(hdl32e.RING, jj),
            "time": np.take(fire.cycle_time_s, cc) + jj * hdl32e.FIRING_DT_S,
            "azimuth_deg": (az.astype(np.float64) * DEG_PER_CENTIDEG).astype(np.float32),
            "object_id": gather(fire.object_id).astype(np.int32),
            "return_source": gather(fire.source).astype(np.uint8),
            "return_index": rr.astype(np.uint8),
        }
        return arrays, cc

    def packets(self, fire: Firings) -> np.ndarray:
        """(P, 1206) uint8 data packets of a chunk (C a multiple of the cycles per packet)."""
        c = fire.cycle_time_s.shape[0]
        p = c // self.cycles_per_packet
        blocks, lasers = hdl32e.BLOCKS_PER_PACKET, hdl32e.N_LASERS
        if self.dual:
            az = np.repeat(fire.block_azimuth, DUAL_RETURNS).reshape(p, blocks)
            dist = fire.distance_units.reshape(p, blocks, lasers)  # (C, 2, 32): blocks last, strongest
            refl = fire.reflectivity.reshape(p, blocks, lasers)
        else:
            az = fire.block_azimuth.reshape(p, blocks)
            dist = fire.distance_units[:, 0].reshape(p, blocks, lasers)
            refl = fire.reflectivity[:, 0].reshape(p, blocks, lasers)
        first = fire.cycle_time_s[:: self.cycles_per_packet]
        stamp = self._hour_microseconds(first)
        mode = hdl32e.RETURN_MODE_BYTE[self.cfg.return_mode]
        return encode_data_packets(az, dist, refl, stamp, mode).view(np.uint8).reshape(p, hdl32e.PACKET_BYTES)

    def _hour_microseconds(self, t_s: np.ndarray) -> np.ndarray:
        """Microseconds since the top of the UTC hour (the packet timestamp field)."""
        unix = self.start_unix_s + np.asarray(t_s, dtype=np.float64)
        return np.round(np.mod(unix, SECONDS_PER_HOUR) * MICROSECONDS_PER_SECOND).astype(np.int64).astype(np.uint32)

    def position_packet(self, t_s: float) -> bytes:
        """The 8308 packet at time t: timestamp and a $GPRMC of the own ship."""
        world = self.world
        motion = world.own_ship.motion
        poses = motion.poses(np.array([t_s]))
        lat, lon = world.frame.to_geodetic(poses.position_m[:, 0], poses.position_m[:, 1])
        v = motion.velocity_mps(np.array([t_s]))[0]
        utc = dt.datetime.fromtimestamp(self.start_unix_s + t_s, tz=dt.timezone.utc)
        sentence = nmea.gprmc(utc, float(lat[0]), float(lon[0]), float(np.hypot(v[0], v[1])),
                              float(np.degrees(np.arctan2(v[0], v[1]))))
        return encode_position_packet(int(self._hour_microseconds(np.array([t_s]))[0]), sentence)

    # ------------------------------------------------------------------ the run

    @property
    def chunk_packets(self) -> int:
        """Data packets of a chunk: the fewest that hold a revolution."""
        return max(1, int(np.ceil(hdl32e.cycles_per_revolution(self.cfg.rotation_hz) / self.cycles_per_packet)))

    @property
    def n_chunks(self) -> int:
        """Chunks of the whole run (the last may be short)."""
        return -(-self.n_packets // self.chunk_packets)

    def chunk_start_s(self, index: int) -> float:
        """Start of chunk ``index`` (``n_chunks``: the end of the run), s."""
        return min(index * self.chunk_packets, self.n_packets) * self.cycles_per_packet * hdl32e.CYCLE_DT_S

    def chunks(self, progress=None, first: int = 0, end: int | None = None, claim=None, cast_ahead: bool = True):
        """Render chunks ``first .. end - 1`` (about one revolution each; all by default) in time order.

        Each chunk draws its range noise and weather from its own random streams
        (:func:`raysim.random_streams.chunk_stream`), so a chunk's bytes do not depend on which
        chunks were rendered before it, nor in which process.

        A chunk's cast (:meth:`_cast_stage`, no random draws) runs on a second thread while the chunk
        before it is measured (:meth:`_echo_stage`), so a chunk is claimed and cast one chunk ahead of
        the one yielded (``cast_ahead`` False: each chunk cast when it is due, the same bytes). numpy's
        BLAS stays at one thread while the generator lives (the chunks' matrix products are small:
        :mod:`raysim.sensors.blas_threads`). ``chunk_wall_s`` gets each
        chunk's wall time from the hand-on of the one before.

        Parameters
        ----------
        progress : callable, optional
            Wraps the iterable of chunk indices (a progress bar).
        first, end : int
            The chunks to render (``end`` None: to the end of the run).
        claim : callable, optional
            ``claim(index) -> bool``, asked before each chunk: False stops the render there
            (:class:`raysim.sensors.lidar_run.ChunkClaims`, two processes sharing a run).
        cast_ahead : bool
            Cast the next chunk while this one is measured (live mode with a fed own ship: not, so that
            no chunk is cast from a pose further ahead of the clock than the one it is due at).

        Yields
        ------
        LidarChunk
            The chunk's firings, data packets and their send times, and the position packets due in it.
        """
        next_position_s = self._positions_before(first)[0]
        indices = range(first, self.n_chunks if end is None else min(end, self.n_chunks))
        lead = 1 if cast_ahead else 0  # chunks cast before the oldest cast one is measured and handed on
        casts: deque = deque()
        # (BLAS outermost: its thread count is restored only after the cast thread has stopped)
        with single_blas_thread(), ThreadPoolExecutor(1, thread_name_prefix="lidar-cast") as caster:
            started = time.perf_counter()
            for index in (progress(indices) if progress else indices):
                if claim is not None and not claim(index):
                    break
                t, block_az, firing_az = self._chunk_firings(index)
                casts.append((index, block_az, caster.submit(self._cast_stage, t, firing_az)))
                if len(casts) > lead:
                    chunk, next_position_s = self._finish_chunk(*casts.popleft(), next_position_s)
                    yield chunk
                    started = self._timed(chunk, started)
            while casts:  # the chunks cast ahead of the last one claimed
                chunk, next_position_s = self._finish_chunk(*casts.popleft(), next_position_s)
                yield chunk
                started = self._timed(chunk, started)

    def _chunk_firings(self, index: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Chunk ``index``'s cycle start times (C,) s, block azimuths (C,) and firing azimuths (C, 32), 0.01 deg."""
        first_packet = index * self.chunk_packets
        packets_here = min(self.chunk_packets, self.n_packets - first_packet)
        k0 = first_packet * self.cycles_per_packet
        t = (k0 + np.arange(packets_here * self.cycles_per_packet)) * hdl32e.CYCLE_DT_S
        block_az = hdl32e.block_azimuth_centideg(t, self.cfg.rotation_hz, self.cfg.azimuth0_deg)
        az_blocks = (np.repeat(block_az, DUAL_RETURNS) if self.dual else block_az).reshape(-1, hdl32e.BLOCKS_PER_PACKET)
        firing_az = (lidar_kernels.decoder_azimuths(az_blocks, self.dual) if jit.ENABLED
                     else hdl32e.decoder_azimuths_centideg(az_blocks, dual=self.dual))
        firing_az = firing_az[:, ::2] if self.dual else firing_az
        return t, block_az, firing_az.reshape(-1, hdl32e.N_LASERS)

    def _finish_chunk(self, index: int, block_az: np.ndarray, cast, next_position_s: float) -> tuple[LidarChunk, float]:
        """Chunk ``index`` measured from its cast (a future) with its own random streams, its packets encoded;
        and the time of the next position packet, s."""
        seed = self.world.scenario.seed
        self.noise_rng = chunk_stream(seed, "lidar.range_noise", index)
        self.weather_rng = chunk_stream(seed, "lidar.weather", index)
        fire = self._echo_stage(cast.result(), block_az)
        t = fire.cycle_time_s
        payloads = self.packets(fire)
        sent = t[:: self.cycles_per_packet] + self.cycles_per_packet * hdl32e.CYCLE_DT_S
        # position packets due within this chunk go in time order with the data packets
        t_end = t[-1] + hdl32e.CYCLE_DT_S
        position_times = []
        while self.cfg.position_packet_rate_hz > 0 and next_position_s < t_end:
            position_times.append(next_position_s)
            next_position_s += 1.0 / self.cfg.position_packet_rate_hz
        return LidarChunk(t, fire, payloads, sent, position_times), next_position_s

    def _timed(self, chunk: LidarChunk, started: float) -> float:
        """Record the chunk's scenario span and the wall time since the last chunk was handed on; returns now."""
        now = time.perf_counter()
        t = chunk.time_s
        self.chunk_wall_s.append((t[-1] + hdl32e.CYCLE_DT_S - t[0], now - started))
        return now

    def _positions_before(self, first: int) -> tuple[float, int]:
        """The time of the first position packet of chunk ``first``, s (summed as the chunks before it sum
        it), and how many position packets the chunks before it hold."""
        next_position_s, count = 0.0, 0
        if first == 0 or self.cfg.position_packet_rate_hz <= 0:
            return next_position_s, count
        # the end of chunk first - 1 exactly as chunks() computes it: its last cycle's start plus a cycle
        t_end = (first * self.chunk_packets * self.cycles_per_packet - 1) * hdl32e.CYCLE_DT_S + hdl32e.CYCLE_DT_S
        while next_position_s < t_end:
            next_position_s += 1.0 / self.cfg.position_packet_rate_hz
            count += 1
        return next_position_s, count

    def run(self, out_dir: Path, progress=None) -> dict:
        """Render the whole scenario into ``out_dir/lidar``; returns counts for the manifest."""
        return render_chunks(self, out_dir, progress)

    def _write_in_order(self, pcap: PcapWriter, payloads: np.ndarray, sent: np.ndarray, position_times: list[float]) -> None:
        if not position_times:
            pcap.write_udp(payloads, hdl32e.DATA_PORT, self.start_unix_s + sent)
            return
        cut = 0
        for tp in position_times:
            upto = int(np.searchsorted(sent, tp, side="right"))
            if upto > cut:
                pcap.write_udp(payloads[cut:upto], hdl32e.DATA_PORT, self.start_unix_s + sent[cut:upto])
                cut = upto
            packet = np.frombuffer(self.position_packet(tp), np.uint8)[None, :]
            pcap.write_udp(packet, hdl32e.POSITION_PORT, np.array([self.start_unix_s + tp]))
        if cut < payloads.shape[0]:
            pcap.write_udp(payloads[cut:], hdl32e.DATA_PORT, self.start_unix_s + sent[cut:])

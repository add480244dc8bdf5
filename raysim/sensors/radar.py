"""Marine X-band radar (Simrad/Navico Broadband class) on the own ship: polar sweeps and PPI pictures.

Per revolution (all spokes at once, numpy-vectorised):

1. Schedule: spoke i of revolution r is fired at ``(r S + i) / (S rpm / 60)`` s, antenna
   azimuth ``i 360 / S`` deg clockwise from the bow; the own-ship pose (heading, roll, pitch,
   heave) is evaluated at every spoke time.
2. Rays: per spoke ``K_az`` azimuth sub-rays (1 unless the spokes are coarser than
   ``az_ray_spacing_deg``, 0.2 deg: the spokes themselves sample azimuth) times ``K_el`` elevation rays: a few at and
   above the horizon and the rest aimed at the flat sea at geometrically spaced distances from
   the near edge of the -10 deg ray to 1.5 x the range scale, so low targets at every range are
   hit. All rays of a revolution go into ONE :meth:`CarrierScene.cast`.
3. Targets (:mod:`raysim.sensors.radar_targets`): coherent physical optics of the patches the rays light,
   with the sea's image paths and a second specular bounce; summed with their phases per spoke and
   range sample, convolved with the range impulse response of the model and over the spokes with the
   two-way voltage pattern of the antenna (sidelobes included), through the radar equation.
4. Sea clutter (:mod:`raysim.sensors.radar_clutter`): NRL sigma0 x cell area through the radar
   equation with the GIT wind-direction factor, K-distributed (texture with Ward's shape per cell,
   longer along the wave crests; exponential speckle per spoke), only before the first object hit of
   the spoke (radar shadow).
5. Rain (:mod:`raysim.sensors.radar_rain`): a uniform background and EXCELL cells drifting with the
   wind; two-way path attenuation on every echo; volume clutter with exponential speckle.
6. Receiver: thermal noise (exponential power, mean 1 = the noise level), other radars' pulses
   (:mod:`raysim.sensors.radar_interference`), STC, saturation (:mod:`raysim.sensors.radar_receiver`),
   FTC, log video, 4-bit quantisation on fixed levels re. noise, interference rejection.

Outputs (docs/contracts.md, recording directory): ``radar/sweeps/NNNNNN.npz`` and ``radar/ppi/NNNNNN.png``.
"""

from __future__ import annotations

import math
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
from scipy.signal import fftconvolve, lfilter

from groundfloor.frames import mount_transform
from groundfloor.recording import RADAR_SWEEP
from raysim.materials import material_table
from raysim.pose import heading_deg_from_yaw
from raysim.random_streams import stream
from raysim.recording.npz import write_sweep
from raysim.recording.ppi import PpiLabels, write_ppi
from raysim.sensors import radar_physics as phys
from raysim.sensors import radar_receiver
from raysim.sensors.carrier import CarrierScene
from raysim.sensors.context import SensorContext
from raysim.sensors.radar_beam import (antenna_pattern, block_kernel, convolve_cells_compact, convolve_rows_sparse,
                                      range_kernel)
from raysim.sensors.radar_clutter import SeaClutter
from raysim.sensors.radar_interference import Interference, reject
from raysim.sensors.radar_rain import RainEchoes, RainField
from raysim.sensors.radar_targets import TargetEchoes
from raysim.world import World


#: mean of 10 log10 of exponential noise power of mean 1: -10 gamma / ln 10 (Euler's gamma), dB
NOISE_LOG_MEAN_DB = -2.507
SECONDS_PER_MINUTE = 60.0
DEG_PER_TURN = 360.0
#: Lowest antenna height the geometry uses, m: the ray fan's design height (a mount at or below the
#: waterline still gets a fan) and, smaller, the height in the clutter tables (a grazing angle exists).
FAN_MIN_HEIGHT_M = 0.1
CLUTTER_MIN_HEIGHT_M = 0.05
#: Rays are cast to this multiple of the range scale plus a margin, m: objects just beyond the scale are still
#: found (first hits for the shadow and the objects seen); echoes placed beyond the last sample are dropped.
CAST_RANGE_FACTOR = 1.5
CAST_RANGE_MARGIN_M = 10.0
#: Floor of the summed power before taking dB (no log of 0).
POWER_FLOOR = 1e-30
#: Range samples per block of the incoherent range skirt (a smooth pedestal: formed on blocks, repeated).
SKIRT_BLOCK = 8


@dataclass(frozen=True)
class RadarParams:
    """Radar model parameters with their defaults (sources in :mod:`raysim.sensors.radar_physics`).

    The scenario's ``sensors.radar`` keys set the operator-facing ones (:meth:`from_config`).
    """

    f_ghz: float = phys.FREQUENCY_GHZ
    pt_w: float = phys.PT_W
    gain_dbi: float = phys.ANTENNA_GAIN_DBI
    sweep_s: float = phys.SWEEP_S
    noise_figure_db: float = phys.NOISE_FIGURE_DB
    losses_db: float = phys.LOSSES_DB
    beam_az_deg: float = phys.BEAM_AZ_DEG
    beam_el_deg: float = phys.BEAM_EL_DEG
    range_resolution_m: float = phys.RANGE_RESOLUTION_M
    polarisation: str = "HH"  # marine X-band radars are horizontally polarised
    # target scattering (REF 3.6): gain of the materials' rough-surface lobe (unverified engineering default);
    # the specular part is physical optics over the ray tubes, calibrated on the flat plate (no free gain)
    diffuse_gain: float = 1.0
    # receiver (REF 3.10): video level v = floor((SNR_dB + STC - floor_db) / step_db), clipped 0..15.
    # floor 6.6 dB + one 3 dB step = 9.6 dB threshold: noise alone crosses it with Pfa ~ 1e-4 (REF 3 table)
    video_floor_db: float = 6.6
    video_step_db: float = 3.0
    # STC (REF 3.10) min(0, -A0 + 10 n log10(R/R0)): a moderate sea-clutter control setting, 0 dB beyond
    # 316 m (engineering default, unverified); a0 = 0 turns it off
    stc_a0_db: float = 20.0
    stc_n: float = 4.0  # REF 3.10: 3..4
    stc_r0_m: float = 100.0
    ftc_m: float = 0.0  # rain control (FTC): range time constant of the log-video high-pass, m; 0 = off
    blanking_m: float = 3.0  # main-bang blanking: samples nearer than this are 0 (unverified; FMCW, REF 3 table)
    # propagation
    earth_curvature: bool = True  # drop hits below the 4/3-earth radar horizon (REF 3.4)
    multipath: bool = True  # two-ray interference over the sea (REF 3.5)
    # ray fan: rays at most resolve_m apart at the range scale (capped at the horizon of a top_height_m
    # object), so a 15 m berg there gets about 2.5 rays each way (issue 4)
    resolve_m: float = 6.0
    top_height_m: float = 40.0  # tallest object the fan is dense enough for at the resolve range
    low_height_m: float = 1.0  # lowest object the fan's sea-going rays catch at every range
    elevation_max_deg: float = 20.0
    elevation_min_deg: float = -10.0
    rain_height_m: float = 1500.0  # top of the rain layer (unverified)
    # receiver model (radar_receiver.RECEIVER_MODELS): range response and saturation level
    model: str = "broadband-4g"
    # antenna (raysim.sensors.radar_antenna): one-way near-in sidelobe level of the horizontal pattern, dB;
    # None = the sidelobe-free Gaussian beam of the earlier model (kept for comparisons)
    sidelobe_db: float | None = -25.0

    @classmethod
    def from_config(cls, cfg) -> "RadarParams":
        """The parameters a scenario's ``sensors.radar`` block sets (the rest at their defaults)."""
        return cls(polarisation=cfg.polarisation, video_floor_db=cls.video_floor_db - cfg.gain_db,
                   stc_a0_db=cfg.sea_clutter_control_db,
                   ftc_m=cfg.rain_clutter_control_m, blanking_m=cfg.blanking_m, multipath=cfg.multipath,
                   earth_curvature=cfg.earth_curvature, beam_az_deg=cfg.beam_az_deg, beam_el_deg=cfg.beam_el_deg,
                   resolve_m=cfg.resolve_m, model=cfg.model, sidelobe_db=cfg.sidelobe_db)


@dataclass
class Revolution:
    """One revolution: the NPZ contract arrays and diagnostics."""

    echo: np.ndarray  # (S, N) uint8 0..15
    azimuth_deg: np.ndarray  # (S,) float32, clockwise from the bow
    heading_deg: np.ndarray  # (S,) float32
    time: np.ndarray  # (S,) float64
    range_m: np.ndarray  # (N,) float32
    snr_db: np.ndarray = field(repr=False, default=None)  # (S, N) float32, before quantisation (STC, FTC applied)
    first_hit_m: np.ndarray = field(repr=False, default=None)  # (S,) first object hit (inf: none)
    target_snr: np.ndarray = field(repr=False, default=None)  # (S, N) float32, object echoes alone (linear, re. noise)
    texture_rows: np.ndarray = field(repr=False, default=None)  # (S / sub, N) float32, texture on formed spokes
    clutter: np.ndarray = field(repr=False, default=None)  # (S, N) float32, sea clutter alone (linear, re. noise)
    object_id: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int32))  # (K,) int32, objects the rays hit
    object_spokes: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int32))  # (K,) int32, spokes hitting each
    texture_sub: int = 1  # the texture is formed on every sub-th spoke and repeated

    @property
    def texture(self) -> np.ndarray | None:
        """(S, N) float32 clutter texture (mean 1) of every spoke, or None (sea state 0)."""
        if self.texture_rows is None or self.texture_sub == 1:
            return self.texture_rows
        return np.repeat(self.texture_rows, self.texture_sub, axis=0)

    def arrays(self) -> dict:
        return {"echo": self.echo, "azimuth_deg": self.azimuth_deg, "heading_deg": self.heading_deg,
                "time": self.time, "range_m": self.range_m, "object_id": self.object_id,
                "object_spokes": self.object_spokes}


class RadarRenderer:
    """Renders the marine radar of a world's own ship.

    Parameters
    ----------
    world : raysim.world.World
    scene : CarrierScene
    params : RadarParams, optional
        Model parameters; by default those of the scenario's ``sensors.radar`` block.
    """

    def __init__(self, world: World, scene: CarrierScene, params: RadarParams | None = None):
        self.world = world
        self.scene = scene
        s = world.scenario
        self.cfg = s.sensors.radar
        self.env = s.environment
        self.seed = s.seed
        self.p = p = params or RadarParams.from_config(self.cfg)
        self.spokes, self.samples = int(self.cfg.spokes), int(self.cfg.samples)
        self.rev_s = SECONDS_PER_MINUTE / self.cfg.rpm
        self.mount_rotation, self.mount_translation = mount_transform(self.cfg.mount)
        # range_m[j] = j dR: the first sample at the antenna, the last at the range scale (REF 3 table)
        self.dr = self.cfg.range_m / (self.samples - 1)
        self.range_m = (np.arange(self.samples) * self.dr).astype(np.float32)
        self.r64 = np.maximum(self.range_m.astype(np.float64), 0.5 * self.dr)
        self.cell_m = max(self.dr, p.range_resolution_m)
        self.materials = material_table()
        # ray fan: dense enough to resolve p.resolve_m at the range scale or, if nearer, at the radar
        # horizon of a top_height_m object (beyond it nothing that tall is seen: REF 3.4)
        h = max(self.cfg.mount.z_m, FAN_MIN_HEIGHT_M)
        resolve_range = min(self.cfg.range_m, float(phys.horizon_m(h) + phys.horizon_m(p.top_height_m)))
        spoke_deg = DEG_PER_TURN / self.spokes
        az_spacing_deg = math.degrees(p.resolve_m / resolve_range)
        self.k_az = max(1, int(math.ceil(spoke_deg / az_spacing_deg - 1e-9)))
        self.az_offsets_deg = ((np.arange(self.k_az) + 0.5) / self.k_az - 0.5) * spoke_deg
        self.d_az_rad = math.radians(spoke_deg / self.k_az)
        self.el_rad, self.d_el_rad = phys.elevation_grid_rad(h, resolve_range, p.resolve_m, p.top_height_m, p.low_height_m,
                                                             p.elevation_max_deg, p.elevation_min_deg)
        self.k = self.k_az * self.el_rad.size
        # antenna: the two-way VOLTAGE pattern as a circular kernel over spokes (its FFT, reused every revolution);
        # the echoes are summed coherently: E[i] = sum_s g2(az_s - az_i) F[s] (a correlation)
        self.pattern = antenna_pattern(p, self.seed)
        kernel = self.pattern.spoke_kernel(self.spokes)
        self.az_kernel_f = np.fft.fft(np.roll(kernel[::-1], 1))
        # the two-way POWER pattern at each spoke offset, for incoherent echoes (the range skirt): P[(i - s) % S]
        self.az_power_pattern = np.roll(np.abs(kernel[::-1]) ** 2, 1).astype(np.float32)
        self.range_kernel, self.range_skirt_kernel = range_kernel(p, self.dr, self.cfg.range_m, self.samples)
        self.range_skirt_blocks = block_kernel(self.range_skirt_kernel, SKIRT_BLOCK)
        # clutter / rain cells use the -3 dB width as REF 3.7 does (R theta dR sec psi); a Gaussian
        # two-way pattern's equivalent width would be 0.753 theta3 (1.2 dB less): see docs/radar.md
        self.beam_eq_rad = math.radians(p.beam_az_deg)
        self.el_eq_rad = phys.two_way_equivalent_width_rad(p.beam_el_deg)
        self.snr_kw = dict(pt_w=p.pt_w, gain_dbi=p.gain_dbi, f_ghz=p.f_ghz, sweep_s=p.sweep_s,
                           noise_figure_db=p.noise_figure_db, losses_db=p.losses_db)
        # sea clutter (docs/radar.md section 3): NRL mean x GIT wind direction, Ward-shaped K texture, speckle
        self.sea_clutter = SeaClutter(self.range_m, self.spokes, self.cell_m, p, self.env.sea_state,
                                      self.env.wind_from_deg, self.seed, self.snr_kw)
        # per-range receiver terms (the same every spoke)
        self.stc_db = phys.stc_gain_db(self.r64, p.stc_a0_db, p.stc_n, p.stc_r0_m).astype(np.float32)
        # STC is a gain ahead of the limiting stage (the FMCW beat-signal high-pass before the ADC; the IF gain of a
        # pulse set before its log amplifier), so saturation acts on the power after it
        self.stc_lin = phys.undb(self.stc_db).astype(np.float32)
        self.receiver = radar_receiver.RECEIVER_MODELS[p.model]
        # rain (docs/radar.md section 4): uniform background plus drifting EXCELL cells; interference (other radars)
        rain_volume = self.r64 * self.beam_eq_rad * self.cell_m * np.minimum(self.r64 * self.el_eq_rad / 2.0, p.rain_height_m)
        self.rain = RainEchoes(RainField.from_environment(self.env, world.frame), self.range_m,
                               phys.snr(rain_volume, self.r64, **self.snr_kw), p.f_ghz, self.spokes, p.beam_az_deg)
        self.interference = Interference(self.cfg.interference, world.frame, self.seed, self.cfg.range_m, self.dr,
                                         self.samples, p.beam_az_deg, own_pattern=self.pattern)
        self.blank = int(np.searchsorted(self.range_m, p.blanking_m, side="left"))
        self._clutter_mean_db = self.sea_clutter.mean_db_table(np.array([max(self.cfg.mount.z_m, CLUTTER_MIN_HEIGHT_M)]))[0]
        self.n_revolutions = int(math.floor(s.duration_s / self.rev_s + 1e-9))
        self.targets = TargetEchoes(self)
        self.rev_wall_s: list[float] = []
        # the spokes' azimuths and the rays' sensor-frame directions are the same every revolution, and so are the
        # own-ship hits (body frame, fixed mount): done once here, not per revolution
        self.max_range_m = self.cfg.range_m * CAST_RANGE_FACTOR + CAST_RANGE_MARGIN_M
        self.azimuth_deg = np.arange(self.spokes) * (DEG_PER_TURN / self.spokes)
        self.d_sensor = self._sensor_directions(self.azimuth_deg)  # (S, K, 3)
        d_b = self.d_sensor.reshape(self.spokes * self.k, 3) @ self.mount_rotation.T
        o_b = np.broadcast_to(self.mount_translation, d_b.shape)
        self.own_hits = scene.carrier_hits(o_b, d_b, self.max_range_m)

    # ------------------------------------------------------------------ geometry

    def range_filter(self, rows: np.ndarray, cells: np.ndarray | None = None) -> np.ndarray:
        """Convolve (M, N) complex echoes (sparse: point echoes at the flat indices ``cells``, if known) along range
        with the range impulse response."""
        return convolve_rows_sparse(rows, self.range_kernel, cells)

    def range_filter_cells(self, values: np.ndarray, cells: np.ndarray,
                           shape: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`range_filter` of the (M, N) echoes that are ``values`` (Q,) complex at the flat indices ``cells``
        (Q,) and zero elsewhere, on the cells the filter reaches: (P,) increasing flat indices and (P,) complex
        values (:func:`~raysim.sensors.radar_beam.convolve_cells_compact`)."""
        return convolve_cells_compact(values, cells, shape, self.range_kernel)

    def range_skirt(self, power_rows: np.ndarray) -> np.ndarray | None:
        """(M, B) incoherent range skirt (phase noise) of (M, N) echo powers in blocks of SKIRT_BLOCK samples.

        The skirt is a smooth Lorentzian pedestal 65 dB under its echo (docs/radar.md section 5): it changes by
        under 2 dB over a block, so it is formed on blocks (echo powers summed per block, the kernel averaged over
        each block offset) and added to each of the block's samples (:meth:`add_blocks`). None if the model has none.
        """
        if self.range_skirt_blocks is None:
            return None
        m, n = power_rows.shape
        blocks = -(-n // SKIRT_BLOCK)
        padded = np.asarray(power_rows, dtype=np.float32)  # whole blocks: no padded copy (the same sums)
        if n % SKIRT_BLOCK:
            padded = np.zeros((m, blocks * SKIRT_BLOCK), np.float32)
            padded[:, :n] = power_rows
        per_block = padded.reshape(m, blocks, SKIRT_BLOCK).sum(axis=2)
        half = self.range_skirt_blocks.size // 2
        out = fftconvolve(per_block, self.range_skirt_blocks[None, :], mode="full", axes=1)[:, half: half + blocks]
        return np.maximum(out, 0.0).astype(np.float32)

    def add_blocks(self, power: np.ndarray, blocks: np.ndarray, rows: np.ndarray | None = None) -> None:
        """Add (M, B) values per SKIRT_BLOCK-sample block (:meth:`range_skirt`) to each of their block's samples.

        Parameters
        ----------
        power : (S, N) float32
            Added to in place: all its rows (``rows`` None, M = S) or the rows ``rows`` (M,).
        blocks : (M, B) float32
            One value per block of SKIRT_BLOCK range samples (the last block may be partial).
        """
        n = self.samples
        target = power if rows is None else power[rows]  # C-contiguous either way
        if n % SKIRT_BLOCK == 0:  # a (M, B, SKIRT_BLOCK) view: each block's value broadcast, no (M, N) repeat formed
            target.reshape(target.shape[0], n // SKIRT_BLOCK, SKIRT_BLOCK)[...] += blocks[:, :, None]
        else:
            target += np.repeat(blocks, SKIRT_BLOCK, axis=1)[:, :n]
        if rows is not None:
            power[rows] = target

    def _poses(self, t: np.ndarray):
        poses = self.world.own_ship.motion.poses(t)
        rot_body = poses.rotation()
        rot = rot_body @ self.mount_rotation  # sensor -> world (S, 3, 3)
        pos = poses.position_m + np.einsum("nij,j->ni", rot_body, self.mount_translation)
        return poses, rot, pos

    def _sensor_directions(self, azimuth_deg: np.ndarray) -> np.ndarray:
        """(S, K, 3) unit ray directions in the sensor frame (FLU; azimuth clockwise from x)."""
        a = np.radians(azimuth_deg[:, None, None] + self.az_offsets_deg[None, :, None])  # (S, Kaz, 1)
        e = self.el_rad[None, None, :]
        ce = np.cos(e)
        d = np.stack(np.broadcast_arrays(ce * np.cos(a), -ce * np.sin(a), np.sin(e) + 0 * a), axis=-1)
        return d.reshape(azimuth_deg.size, self.k, 3)

    def rays(self, rev: int):
        """The rays of revolution ``rev``: spoke times (S,) s, azimuths (S,) deg, poses, sensor-to-world rotations
        (S, 3, 3), antenna positions (S, 3) m, and the (S K, 3) world ray origins (m) and directions."""
        S, K = self.spokes, self.k
        t = (rev * S + np.arange(S)) / (S * self.cfg.rpm / SECONDS_PER_MINUTE)
        poses, rot, pos = self._poses(t)
        d_w = (self.d_sensor @ rot.transpose(0, 2, 1)).reshape(S * K, 3)  # each spoke's rows times its rotation's transpose
        o_w = np.repeat(pos, K, axis=0)
        return t, self.azimuth_deg, poses, rot, pos, o_w, d_w

    def _clutter_mean_db_table(self, antenna_h: np.ndarray) -> np.ndarray:
        """(H, N) mean sea clutter, dB re. noise, at the level boresight (:meth:`SeaClutter.mean_db_table`)."""
        return self.sea_clutter.mean_db_table(antenna_h)

    # ------------------------------------------------------------------ one revolution

    def revolution(self, rev: int) -> Revolution:
        """Render revolution ``rev`` (deterministic: its random streams are named after it).

        The sea clutter with the receiver noise, and the rain (numpy work that releases the GIL), are formed on two
        more threads while this one casts the rays and forms the object echoes; the shadow of the objects is cut
        into the clutter once all are done (:meth:`_video`). Every random draw comes from a stream named after its
        job and the revolution, so the bytes do not depend on the threads' timing.
        """
        K = self.k
        t, azimuth, poses, rot, pos, o_w, d_w = self.rays(rev)
        heading = heading_deg_from_yaw(poses.yaw_rad)
        antenna_h = np.maximum(pos[:, 2], CLUTTER_MIN_HEIGHT_M)
        max_range = self.max_range_m
        with ThreadPoolExecutor(max_workers=2, thread_name_prefix="radar-clutter") as pool:
            sea = pool.submit(self._sea_and_noise, rev, t, rot, pos, azimuth, heading, antenna_h)
            rain = pool.submit(self.rain.revolution, self.seed, rev, t, pos, heading + azimuth)
            hits, on_carrier = self.scene.cast(o_w, d_w, np.repeat(t, K), max_range_m=max_range,
                                               carrier_hits=self.own_hits)
            targets, first_hit, seen = self.targets.render(hits, on_carrier, t, o_w, d_w, antenna_h, rot, azimuth,
                                                           max_range)
            clutter, texture, noise = sea.result()
            rain_loss, rain_clutter = rain.result()

        # ---- receiver: rain clutter, attenuation, thermal noise, STC, FTC, log video, fixed 4-bit levels
        def interference(total: np.ndarray) -> None:
            self.interference.add_to(total, t, pos, heading + azimuth)

        echoes = _Echoes(clutter, targets, first_hit, rain_loss, rain_clutter)
        p_db, levels = self._video(echoes, noise, interference if self.interference.active else None)
        echo = reject(levels, self.cfg.interference_rejection)
        echo[:, : self.blank] = 0
        return Revolution(echo, azimuth.astype(np.float32), heading.astype(np.float32), t, self.range_m,
                          snr_db=p_db, first_hit_m=first_hit, target_snr=targets, texture_rows=texture, clutter=clutter,
                          object_id=seen[0], object_spokes=seen[1], texture_sub=self.sea_clutter.sub)

    def _video(self, echoes: "_Echoes", noise: np.ndarray, interference=None) -> tuple[np.ndarray, np.ndarray]:
        """Receiver from the echoes to the 4-bit video, on two halves of the spokes in two threads.

        Per spoke: the shadow cut into the sea clutter, the echo power ``((clutter + targets) + rain) x rain loss``,
        then noise, STC, saturation, log video, FTC (along range) and the fixed levels; so the halves are independent.
        Other radars' pulses (``interference``) are added to the whole revolution between the two stages.

        Parameters
        ----------
        echoes : _Echoes
            The revolution's echoes; its sea clutter gets the shadow, in place.
        noise : (S, N) float32
            Thermal noise power (exponential, mean 1).
        interference : callable, optional
            Adds other radars' pulses to the (S, N) echo power in place.

        Returns
        -------
        p_db : (S, N) float32
            The power over the noise, dB, after STC, saturation and FTC.
        levels : (S, N) uint8
            Video levels 0..15.
        """
        total = np.empty_like(echoes.clutter)
        halves = (slice(0, self.spokes // 2), slice(self.spokes // 2, None))
        if interference is None:
            def both(rows: slice) -> np.ndarray:
                echoes.power(rows, total[rows], self.sea_clutter)
                return self._receive(total[rows], noise[rows])

            return total, np.concatenate(_on_two_threads(both, halves))
        _on_two_threads(lambda rows: echoes.power(rows, total[rows], self.sea_clutter), halves)
        interference(total)
        return total, np.concatenate(_on_two_threads(lambda rows: self._receive(total[rows], noise[rows]), halves))

    def _receive(self, block: np.ndarray, noise: np.ndarray) -> np.ndarray:
        """Noise, STC, saturation, log video, FTC and the fixed 4-bit levels of (M, N) spokes, in place.

        Parameters
        ----------
        block : (M, N) float32
            Echo power (SNR, linear) without the noise; becomes the log video, dB re. noise.
        noise : (M, N) float32
            Thermal noise power (exponential, mean 1).

        Returns
        -------
        (M, N) uint8
            Video levels 0..15.
        """
        p = self.p
        block += noise
        block *= self.stc_lin[None, :]
        radar_receiver.saturate(block, self.receiver.saturation_db, out=block)
        # 10 log10 P as (10 / ln 10) ln P: numpy's float32 log is vectorised, its log10 is not (3x slower)
        np.log(np.maximum(block, np.float32(POWER_FLOOR), out=block), out=block)
        block *= np.float32(10.0 / math.log(10.0))
        if p.ftc_m > 0:
            block[...] = self._ftc(block)
        return phys.quantise(block, p.video_floor_db, p.video_step_db)

    def _sea_and_noise(self, rev, t, rot, pos, azimuth, heading, antenna_h):
        """The revolution's sea clutter without shadow, its texture and the (S, N) thermal noise.

        Sea clutter and receiver noise are both circular Gaussian voltages in a cell, so the power of their sum is
        exponential with the sum of their means: one exponential draw (stream ``radar.noise.<rev>``) is the
        speckle of both, ``(c + 1) E`` (the clutter's share ``c E`` is returned as the clutter).
        """
        speckle = stream(self.seed, f"radar.noise.{rev}").standard_exponential((self.spokes, self.samples),
                                                                               dtype=np.float32)
        clutter, texture = self.sea_clutter.render(rev, t, rot, pos, azimuth, heading, antenna_h, None, speckle)
        return clutter, texture, speckle

    def _ftc(self, p_db: np.ndarray) -> np.ndarray:
        """Rain control (FTC): subtract the log video's excess over the noise, low-passed along range (one-sided).

        A range high-pass as the analogue FTC differentiator: extended echoes (rain) fall to the noise
        level, the leading edges of short ones (boats, buoys, land edges) stay.
        """
        a = math.exp(-self.dr / self.p.ftc_m)
        low = lfilter([1.0 - a], [1.0, -a], p_db, axis=1).astype(np.float32)
        # the reference trails by a guard of about one range resolution, so an echo's leading edge keeps its level
        guard = int(math.ceil(self.p.range_resolution_m / self.dr)) + 1
        ref = np.full_like(low, NOISE_LOG_MEAN_DB)
        ref[:, guard:] = low[:, :-guard]
        return p_db - np.maximum(ref - NOISE_LOG_MEAN_DB, 0.0)

    def render_revolution(self, rev: int) -> dict:
        """The NPZ contract arrays of revolution ``rev`` (echo, azimuth_deg, heading_deg, time, range_m)."""
        return self.revolution(rev).arrays()

    # ------------------------------------------------------------------ the run

    def run(self, out_dir: Path, progress=None) -> dict:
        """Render every complete revolution into ``out_dir/radar``; returns counts for the manifest.

        A revolution's NPZ sweep and PPI picture are written by one writer thread while the next revolution
        renders (compression and PNG encoding release the GIL); at most one revolution waits to be written.
        """
        radar_dir = Path(out_dir) / "radar"
        sweeps_dir, ppi_dir = radar_dir / "sweeps", radar_dir / "ppi"
        sweeps_dir.mkdir(parents=True, exist_ok=True)
        ppi_dir.mkdir(parents=True, exist_ok=True)
        labels = PpiLabels.from_scenario(self.world.scenario)
        counts = {"sweeps": 0, "spokes": 0}
        revs = range(self.n_revolutions)

        def write(rev: int, arrays: dict) -> None:
            write_sweep(sweeps_dir, rev, RADAR_SWEEP, arrays)
            write_ppi(ppi_dir / f"{rev:06d}.png", arrays, labels)

        pending = None
        with ThreadPoolExecutor(max_workers=1, thread_name_prefix="radar-writer") as writer:
            for rev in (progress(revs) if progress else revs):
                started = time.perf_counter()
                arrays = self.revolution(rev).arrays()
                if pending is not None:
                    pending.result()  # a write's error surfaces here, before the next is queued
                pending = writer.submit(write, rev, arrays)
                counts["sweeps"] += 1
                counts["spokes"] += self.spokes
                self.rev_wall_s.append(time.perf_counter() - started)
            if pending is not None:
                pending.result()
        return counts


@dataclass
class _Echoes:
    """A revolution's echoes before the receiver: (S, N) float32 SNR arrays, linear re. noise."""

    clutter: np.ndarray  # (S, N) sea clutter without the shadow
    targets: np.ndarray | None  # (S, N) object echoes, or None
    first_hit_m: np.ndarray  # (S,) first object hit per spoke, m (inf: none)
    rain_loss: np.ndarray | None  # (S, N) or (1, N) two-way rain attenuation (a factor), or None
    rain_clutter: np.ndarray | None  # (S, N) rain echoes, or None

    def power(self, rows: slice, out: np.ndarray, sea: SeaClutter) -> None:
        """Cut the shadow into the clutter of the spokes ``rows`` and write their ``((clutter + targets) + rain) x
        rain loss`` into ``out`` (M, N), the order of the sums of the whole-revolution form."""
        clutter = self.clutter[rows]
        sea.shadow(clutter, self.first_hit_m[rows])
        if self.targets is not None:
            np.add(clutter, self.targets[rows], out=out)
        else:
            out[...] = clutter
        if self.rain_clutter is not None:
            out += self.rain_clutter[rows]
        if self.rain_loss is not None:
            out *= self.rain_loss[rows] if self.rain_loss.shape[0] > 1 else self.rain_loss


def _on_two_threads(work, halves: tuple[slice, slice]) -> list:
    """``[work(halves[0]), work(halves[1])]``, the second half on a thread of its own."""
    with ThreadPoolExecutor(max_workers=1, thread_name_prefix="radar-video") as pool:
        second = pool.submit(work, halves[1])
        first = work(halves[0])
        return [first, second.result()]


def render_radar(ctx: SensorContext) -> None:
    """The ``radar`` entry for :data:`raysim.render.SENSOR_RENDERERS`."""
    renderer = RadarRenderer(ctx.world, ctx.scene())
    from tqdm import tqdm

    progress = (lambda it: tqdm(it, desc="radar", unit="rev", leave=False)) if ctx.progress else None
    counts = renderer.run(ctx.out_dir, progress)
    ctx.counts.update({f"radar/{k}": v for k, v in counts.items()})


__all__ = ["RadarParams", "RadarRenderer", "Revolution", "render_radar", "replace"]

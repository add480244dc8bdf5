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
3. Targets: each object hit gives a facet RCS (:func:`radar_physics.facet_sigma_m2`) times the
   two-way vertical gain at the ray's elevation in the antenna frame, through the radar
   equation, into its range bin; hits below the 4/3-earth horizon are dropped. The azimuth beam
   is applied as a circular convolution over spokes with the two-way Gaussian pattern, the range
   point-spread (physical resolution) as a peak-1 Gaussian along range.
4. Sea clutter: NRL sigma0 x cell area through the radar equation, K-distributed (Gamma texture
   correlated over range and one beamwidth in azimuth, exponential speckle per spoke), only in
   range bins before the first object hit of the spoke (radar shadow).
5. Rain: two-way attenuation on every echo; volume clutter with exponential speckle.
6. Receiver: thermal noise (exponential power, mean 1 = the noise level), STC, log video,
   4-bit quantisation on fixed levels re. noise.

Outputs (docs/contracts.md, recording directory): ``radar/sweeps/NNNNNN.npz`` and ``radar/ppi/NNNNNN.png``.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
from scipy.ndimage import gaussian_filter1d, uniform_filter1d
from scipy.signal import lfilter

from groundfloor.frames import mount_transform
from groundfloor.recording import RADAR_SWEEP
from raysim.materials import material_table
from raysim.pose import heading_deg_from_yaw
from raysim.random_streams import stream
from raysim.recording.npz import write_sweep
from raysim.recording.ppi import PpiLabels, write_ppi
from raysim.scene import NO_HIT, SEA_ID
from raysim.sensors import radar_physics as phys
from raysim.sensors import radar_receiver
from raysim.sensors.carrier import CarrierScene
from raysim.sensors.context import SensorContext
from raysim.sensors.radar_facets import FacetTable
from raysim.sensors.radar_texture import SeaTexture
from raysim.world import World


#: mean of 10 log10 of exponential noise power of mean 1: -10 gamma / ln 10 (Euler's gamma), dB
NOISE_LOG_MEAN_DB = -2.507
#: Largest sea-clutter mean SNR, dB: far above video level 15 (about 55 dB) and far below float32's 385 dB.
MAX_CLUTTER_DB = 200.0
SECONDS_PER_MINUTE = 60.0
DEG_PER_TURN = 360.0
M_PER_KM = 1000.0
#: Lowest antenna height the geometry uses, m: the ray fan's design height (a mount at or below the
#: waterline still gets a fan) and, smaller, the height in the clutter tables (a grazing angle exists).
FAN_MIN_HEIGHT_M = 0.1
CLUTTER_MIN_HEIGHT_M = 0.05
#: Rays are cast to this multiple of the range scale plus a margin, m: echoes from beyond the range
#: scale still spread into its last bins through the range point-spread and the beam.
CAST_RANGE_FACTOR = 1.5
CAST_RANGE_MARGIN_M = 10.0
#: Smallest grazing angle the clutter formulas are evaluated at, deg (below it log terms run away).
MIN_GRAZING_DEG = 1e-3
#: Steepest grazing angle of the NRL sea-clutter fit, deg (REF 3.7: 0.1 to 60 deg).
NRL_MAX_GRAZING_DEG = 60.0
#: Clutter mean beyond the horizon, dB: none, but finite so that it can be interpolated.
NO_CLUTTER_DB = -300.0
#: Floor of the summed power before taking dB (no log of 0).
POWER_FLOOR = 1e-30
#: Full width at half maximum of a Gaussian in standard deviations, 2 sqrt(2 ln 2).
FWHM_PER_SIGMA = 2.3548
#: The range point-spread is applied when its standard deviation is at least this many range bins.
MIN_SPREAD_BINS = 0.3
#: Steps of the clutter mean and texture across one azimuth beamwidth (formed on every sub-th spoke).
CLUTTER_STEPS_PER_BEAM = 6
#: Antenna height step of the clutter table's slope, m (the table at h_mid +- this).
CLUTTER_HEIGHT_STEP_M = 0.05
#: Grazing angles above this, deg, get the exact arcsine in the vertical pattern (the first range bins).
STEEP_GRAZING_DEG = 10.0
#: Swell angle that makes Ward's swell term vanish (cos(2 x 45 deg) = 0), deg: the swell term is added per spoke.
NO_SWELL_DEG = 45.0
#: Range bins of the moving average that normalises the texture's standard deviation along range.
TEXTURE_STD_WINDOW_BINS = 33


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
    # the specular part is facet physical optics, calibrated on the flat plate (no free gain)
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

    @classmethod
    def from_config(cls, cfg) -> "RadarParams":
        """The parameters a scenario's ``sensors.radar`` block sets (the rest at their defaults)."""
        return cls(polarisation=cfg.polarisation, video_floor_db=cls.video_floor_db - cfg.gain_db,
                   stc_a0_db=cfg.sea_clutter_control_db,
                   ftc_m=cfg.rain_clutter_control_m, blanking_m=cfg.blanking_m, multipath=cfg.multipath,
                   earth_curvature=cfg.earth_curvature, beam_az_deg=cfg.beam_az_deg, beam_el_deg=cfg.beam_el_deg,
                   resolve_m=cfg.resolve_m, model=cfg.model)


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
    texture: np.ndarray = field(repr=False, default=None)  # (S, N) float32, clutter texture (mean 1) or None
    clutter: np.ndarray = field(repr=False, default=None)  # (S, N) float32, sea clutter alone (linear, re. noise)
    object_id: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int32))  # (K,) int32, objects the rays hit
    object_spokes: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int32))  # (K,) int32, spokes hitting each

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
        self.facets = FacetTable([o for o in world.objects if o.object_id != world.own_ship.object_id])
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
        # two-way azimuth pattern as a circular kernel over spokes (its FFT, reused every revolution)
        offsets = np.arange(self.spokes)
        offsets = np.where(offsets > self.spokes // 2, offsets - self.spokes, offsets) * spoke_deg
        self.az_kernel_f = np.fft.rfft(phys.two_way_gain(offsets, p.beam_az_deg))
        # clutter / rain cells use the -3 dB width as REF 3.7 does (R theta dR sec psi); the Gaussian
        # two-way pattern's equivalent width would be 0.753 theta3 (1.2 dB less): see docs/radar.md
        self.beam_eq_rad = math.radians(p.beam_az_deg)
        self.el_eq_rad = phys.two_way_equivalent_width_rad(p.beam_el_deg)
        self.gamma = phys.GammaQuantiles()
        self.snr_kw = dict(pt_w=p.pt_w, gain_dbi=p.gain_dbi, f_ghz=p.f_ghz, sweep_s=p.sweep_s,
                           noise_figure_db=p.noise_figure_db, losses_db=p.losses_db)
        self.texture_field = SeaTexture(self.seed, self.env.sea_state, self.env.wind_from_deg)
        # per-range receiver terms (the same every spoke)
        self.stc_db = phys.stc_gain_db(self.r64, p.stc_a0_db, p.stc_n, p.stc_r0_m).astype(np.float32)
        # STC is a gain ahead of the limiting stage (the FMCW beat-signal high-pass before the ADC; the IF gain of a
        # pulse set before its log amplifier), so saturation acts on the power after it
        self.stc_lin = phys.undb(self.stc_db).astype(np.float32)
        self.receiver = radar_receiver.RECEIVER_MODELS[p.model]
        self.rain_loss = phys.undb(-2.0 * float(phys.rain_attenuation_db_per_km(self.env.rain_mm_per_h)) / M_PER_KM
                                   * self.r64).astype(np.float32)
        self.rain_mean = None
        if self.env.rain_mm_per_h > 0:
            volume = (self.r64 * self.beam_eq_rad * self.cell_m
                      * np.minimum(self.r64 * self.el_eq_rad / 2.0, p.rain_height_m))
            eta = phys.rain_eta_m2_per_m3(self.env.rain_mm_per_h, p.f_ghz)
            self.rain_mean = phys.snr(eta * volume, self.r64, **self.snr_kw).astype(np.float32)
        self.blank = int(np.searchsorted(self.range_m, p.blanking_m, side="left"))
        self._clutter_mean_db = self._clutter_mean_db_table(np.array([max(self.cfg.mount.z_m, CLUTTER_MIN_HEIGHT_M)]))[0]
        self.n_revolutions = int(math.floor(s.duration_s / self.rev_s + 1e-9))
        self.rev_wall_s: list[float] = []

    # ------------------------------------------------------------------ geometry

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
        """The rays of revolution ``rev``: spoke times, poses and the world/body ray arrays."""
        S, K = self.spokes, self.k
        idx = np.arange(S)
        t = (rev * S + idx) / (S * self.cfg.rpm / SECONDS_PER_MINUTE)
        azimuth = idx * (DEG_PER_TURN / S)
        poses, rot, pos = self._poses(t)
        d_s = self._sensor_directions(azimuth)  # (S, K, 3)
        d_w = np.einsum("sij,skj->ski", rot, d_s).reshape(S * K, 3)
        o_w = np.repeat(pos, K, axis=0)
        d_b = d_s.reshape(S * K, 3) @ self.mount_rotation.T
        o_b = np.broadcast_to(self.mount_translation, (S * K, 3))
        return t, azimuth, poses, rot, pos, o_w, d_w, o_b, d_b

    def _clutter_mean_db_table(self, antenna_h: np.ndarray) -> np.ndarray:
        """(H, N) mean sea clutter, dB re. noise, at the level boresight: NRL sigma0 x cell area (no pattern)."""
        p = self.p
        psi = phys.grazing_angle_deg(antenna_h[:, None], self.r64[None, :])
        psi_c = np.where(np.isfinite(psi), np.maximum(psi, MIN_GRAZING_DEG), 1.0)
        area = phys.clutter_cell_area_m2(self.r64[None, :], psi_c, self.beam_eq_rad, self.cell_m)
        # the NRL fit holds from 0.1 to 60 deg grazing (REF 3.7); steeper cells (the first metres) keep the 60 deg value
        sigma0_db = phys.nrl_sigma0_db(np.minimum(psi_c, NRL_MAX_GRAZING_DEG), p.f_ghz, self.env.sea_state, p.polarisation)
        mean_db = sigma0_db + phys.db(area) + phys.snr_db(1.0, self.r64[None, :], **self.snr_kw)
        return np.where(np.isfinite(psi), mean_db, NO_CLUTTER_DB)  # beyond the horizon: none (finite, for interpolation)

    # ------------------------------------------------------------------ one revolution

    def revolution(self, rev: int) -> Revolution:
        """Render revolution ``rev`` (deterministic: its random streams are named after it)."""
        S, N, K = self.spokes, self.samples, self.k
        p = self.p
        t, azimuth, poses, rot, pos, o_w, d_w, o_b, d_b = self.rays(rev)
        heading = heading_deg_from_yaw(poses.yaw_rad)
        antenna_h = np.maximum(pos[:, 2], CLUTTER_MIN_HEIGHT_M)
        max_range = self.cfg.range_m * CAST_RANGE_FACTOR + CAST_RANGE_MARGIN_M
        hits, on_carrier = self.scene.cast(o_w, d_w, np.repeat(t, K), o_b, d_b, max_range_m=max_range)
        targets, first_hit, seen = self._targets(hits, on_carrier, t, o_w, d_w, antenna_h)
        clutter, texture = self._sea_clutter(rev, t, rot, pos, azimuth, heading, antenna_h, first_hit)

        # ---- receiver: rain clutter, attenuation, thermal noise, STC, FTC, log video, fixed 4-bit levels
        total = clutter
        if targets is not None:
            total = total + targets
        if self.rain_mean is not None:
            total = total + self.rain_mean[None, :] * stream(self.seed, f"radar.rain.{rev}").standard_exponential((S, N), dtype=np.float32)
        if self.env.rain_mm_per_h > 0:
            total = total * self.rain_loss[None, :]
        total = total + stream(self.seed, f"radar.noise.{rev}").standard_exponential((S, N), dtype=np.float32)
        total = radar_receiver.saturate(total * self.stc_lin[None, :], self.receiver.saturation_db)
        p_db = 10.0 * np.log10(np.maximum(total, np.float32(POWER_FLOOR)), dtype=np.float32)
        if p.ftc_m > 0:
            p_db = self._ftc(p_db)
        echo = phys.quantise(p_db, p.video_floor_db, p.video_step_db)
        echo[:, : self.blank] = 0
        return Revolution(echo, azimuth.astype(np.float32), heading.astype(np.float32), t, self.range_m,
                          p_db, first_hit, targets, texture, clutter, *seen)

    def _targets(self, hits, on_carrier, t, o_w, d_w, antenna_h):
        """(S, N) object echoes (SNR, linear; None if no object is hit), the first hit range per spoke, and
        the objects seen: ((K,) int32 ids of the objects a ray reached, first along it and above the
        radar horizon; (K,) int32 how many spokes reached each)."""
        S, N, K = self.spokes, self.samples, self.k
        p = self.p
        oid = hits.object_id
        h = np.flatnonzero((oid != NO_HIT) & (oid != SEA_ID) & ~on_carrier)
        first_hit = np.full(S, np.inf)
        nothing = (np.zeros(0, np.int32), np.zeros(0, np.int32))
        if h.size == 0:
            return None, first_hit, nothing
        r_h = hits.range_m[h]
        spoke_h = h // K
        point = o_w[h] + r_h[:, None] * d_w[h]
        if p.earth_curvature:  # below the 4/3-earth horizon: hidden (REF 3.4)
            horiz = np.hypot(point[:, 0] - o_w[h, 0], point[:, 1] - o_w[h, 1])
            visible = point[:, 2] >= phys.hidden_height_m(horiz, antenna_h[spoke_h])
            h, r_h, spoke_h, point = h[visible], r_h[visible], spoke_h[visible], point[visible]
            if h.size == 0:
                return None, first_hit, nothing
        np.minimum.at(first_hit, spoke_h, r_h)
        pairs = np.unique(oid[h].astype(np.int64) * S + spoke_h)  # (object, spoke) pairs
        seen_id, seen_spokes = np.unique(pairs // S, return_counts=True)
        seen = (seen_id.astype(np.int32), seen_spokes.astype(np.int32))
        el_idx = (h % K) % self.el_rad.size
        normal = hits.normal[h].astype(np.float64)
        cos_ray = -np.einsum("ij,ij->i", normal, d_w[h])
        area_f, centre = self.facets.lookup(oid[h], hits.primitive[h], t[spoke_h])
        los = centre - o_w[h]
        cos_f = -np.einsum("ij,ij->i", normal, los) / np.maximum(np.linalg.norm(los, axis=1), 1e-9)
        mat = hits.material[h]
        footprint = r_h * r_h * self.d_az_rad * self.d_el_rad[el_idx]
        sigma = phys.facet_sigma_m2(self.materials["radar_reflectivity_db"][mat], footprint, cos_ray,
                                    self.materials["specular_exponent"][mat],
                                    self.materials["radar_roughness_m"][mat], area_f, cos_f, r_h, p.f_ghz,
                                    p.diffuse_gain)
        sigma = sigma * phys.two_way_gain(np.degrees(self.el_rad[el_idx]), p.beam_el_deg)
        if p.multipath:
            sigma = sigma * phys.multipath_f4(antenna_h[spoke_h], point[:, 2], r_h, self.env.sea_state, p.f_ghz)
        power = phys.snr(sigma, r_h, **self.snr_kw)
        bins = np.rint(r_h / self.dr).astype(np.int64)
        ok = bins < N
        flat = spoke_h[ok] * N + bins[ok]
        targets = np.bincount(flat, weights=power[ok], minlength=S * N).reshape(S, N)
        # range point-spread (physical resolution, REF 3.3) on the spokes hit, when bins are finer than it
        rows = np.unique(spoke_h[ok])
        sigma_bins = p.range_resolution_m / FWHM_PER_SIGMA / self.dr
        if sigma_bins > MIN_SPREAD_BINS and rows.size:
            targets[rows] = gaussian_filter1d(targets[rows], sigma_bins, axis=1, mode="constant") * (
                math.sqrt(2 * math.pi) * sigma_bins)
        # azimuth beam: circular convolution over spokes, on the range bins that hold an echo
        cols = np.flatnonzero(targets.any(axis=0))
        if cols.size:
            sub = np.fft.irfft(np.fft.rfft(targets[:, cols], axis=0) * self.az_kernel_f[:, None], n=S, axis=0)
            targets[:, cols] = np.maximum(sub, 0.0)
        return targets.astype(np.float32), first_hit, seen

    def _sea_clutter(self, rev, t, rot, pos, azimuth, heading, antenna_h, first_hit):
        """(S, N) sea clutter SNR (K-distributed, zero in shadow and beyond the horizon) and its texture.

        The mean level and the texture change smoothly over a beamwidth of spokes (the antenna's tilt and
        height follow the ship's motion over seconds; the texture is averaged over the beam), so both are
        formed on every ``sub``-th spoke and repeated; the speckle and the shadow are per spoke.
        """
        S, N = self.spokes, self.samples
        p = self.p
        beam_spokes = p.beam_az_deg / (DEG_PER_TURN / S)
        sub = max(1, int(beam_spokes // CLUTTER_STEPS_PER_BEAM))  # 4 at 2048 spokes and 5.2 deg: 0.7 deg steps in a 5.2 deg beam
        while S % sub:
            sub -= 1
        rows = np.arange(0, S, sub)
        h_rows = antenna_h[rows]
        # mean level: NRL sigma0 x cell area through the radar equation, linear in the antenna height about
        # its mean over the revolution (heave, roll and pitch move it by decimetres)
        h_mid = float(np.mean(antenna_h))
        table = self._clutter_mean_db_table(np.array([h_mid - CLUTTER_HEIGHT_STEP_M, h_mid + CLUTTER_HEIGHT_STEP_M]))
        slope = ((table[1] - table[0]) / (2.0 * CLUTTER_HEIGHT_STEP_M)).astype(np.float32)
        dh = (h_rows - h_mid).astype(np.float32)
        mean_db = (table.mean(axis=0).astype(np.float32))[None, :] + dh[:, None] * slope[None, :]
        # vertical pattern at the sea cell's depression in the antenna frame (roll and pitch included)
        psi = phys.grazing_angle_deg(h_mid, self.r64)
        psi_r = np.radians(np.where(np.isfinite(psi), np.maximum(psi, MIN_GRAZING_DEG), 1.0)).astype(np.float32)
        bearing = np.radians(azimuth[rows])
        dxy = np.stack([np.cos(bearing), -np.sin(bearing), np.zeros(rows.size)], 1)  # horizontal boresight, sensor frame
        bore = np.einsum("sij,sj->si", rot[rows], dxy)
        bh = bore[:, :2] / np.maximum(np.linalg.norm(bore[:, :2], axis=1, keepdims=True), 1e-12)
        z_ax = rot[rows, :, 2]  # the antenna's up axis in the world
        sin_tilt = (z_ax[:, 0] * bh[:, 0] + z_ax[:, 1] * bh[:, 1]).astype(np.float32)
        sin_el = np.cos(psi_r)[None, :] * sin_tilt[:, None] - np.sin(psi_r)[None, :] * z_ax[:, 2].astype(np.float32)[:, None]
        # two-way Gaussian pattern in dB at the elevation asin(sin_el): ~ sin_el (0.5 % at 10 deg) except in the
        # first, steep range bins
        steep = int(np.count_nonzero(np.degrees(psi_r) > STEEP_GRAZING_DEG))
        el_sq = sin_el * sin_el
        el_sq[:, :steep] = np.arcsin(np.clip(sin_el[:, :steep], -1.0, 1.0)) ** 2
        mean_db += np.float32(2.0 * phys.one_way_gain_db(math.degrees(1.0), p.beam_el_deg)) * el_sq
        # no sea is nearer than the antenna is high: there the grazing geometry has no solution and the table runs
        # away (278 dB at the antenna, 150 dB jumps per 0.1 m of height, overflowing float32 with the heave's slope;
        # an inf poisons the FTC filter down the whole spoke); the cap keeps the rest of float32 finite
        mean_db[:, self.range_m <= float(np.max(antenna_h))] = -np.inf
        np.minimum(mean_db, np.float32(MAX_CLUTTER_DB), out=mean_db)
        mean = np.power(np.float32(10.0), mean_db * np.float32(0.1))
        texture = None
        if self.env.sea_state > 0:
            # texture: the sea's own field at the cells' world positions, averaged over the beam in azimuth
            rng32 = self.range_m[None, :]
            east = pos[rows, 0, None].astype(np.float32) + bh[:, 0, None].astype(np.float32) * rng32
            north = pos[rows, 1, None].astype(np.float32) + bh[:, 1, None].astype(np.float32) * rng32
            z = self.texture_field.sample(east, north, float(t[S // 2]))
            # two passes of a moving average over one beamwidth (circular in azimuth; on the transposed,
            # contiguous array), then unit variance again at each range
            width = max(1, int(round(beam_spokes / sub)))
            zt = np.ascontiguousarray(z.T)
            zt = uniform_filter1d(uniform_filter1d(zt, width, axis=1, mode="wrap"), width, axis=1, mode="wrap")
            std = np.maximum(uniform_filter1d(zt.std(axis=1), TEXTURE_STD_WINDOW_BINS, mode="nearest"), 1e-6)
            z = np.ascontiguousarray((zt / std[:, None]).T)
            # Ward's shape (REF 3.8) varies with range (grazing, cell area) and with the look direction to the swell
            psi_c = np.where(np.isfinite(psi), np.maximum(psi, MIN_GRAZING_DEG), 1.0)
            area = phys.clutter_cell_area_m2(self.r64, psi_c, self.beam_eq_rad, self.cell_m)
            log_nu_r = np.log(phys.ward_shape_nu(psi_c, area, p.polarisation, NO_SWELL_DEG))  # cos(90 deg) = 0: no swell term
            swell = -np.cos(np.radians(2.0 * ((azimuth[rows] + heading[rows]) - self.env.wind_from_deg))) / 3.0 * math.log(10.0)
            texture = self.gamma(z, (log_nu_r[None, :] + swell[:, None]).astype(np.float32))
            mean *= texture
        clutter = np.repeat(mean, sub, axis=0) if sub > 1 else mean
        if texture is not None:
            clutter *= stream(self.seed, f"radar.clutter.{rev}").standard_exponential((S, N), dtype=np.float32)
            texture = np.repeat(texture, sub, axis=0) if sub > 1 else texture
        # radar shadow: no sea echo at or behind the first object hit of each spoke
        hit_rows = np.flatnonzero(np.isfinite(first_hit))
        if hit_rows.size:
            clutter[hit_rows] *= self.range_m[None, :] < first_hit[hit_rows, None]
        return clutter, texture

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
        """Render every complete revolution into ``out_dir/radar``; returns counts for the manifest."""
        radar_dir = Path(out_dir) / "radar"
        sweeps_dir, ppi_dir = radar_dir / "sweeps", radar_dir / "ppi"
        sweeps_dir.mkdir(parents=True, exist_ok=True)
        ppi_dir.mkdir(parents=True, exist_ok=True)
        counts = {"sweeps": 0, "spokes": 0}
        revs = range(self.n_revolutions)
        for rev in (progress(revs) if progress else revs):
            started = time.perf_counter()
            out = self.revolution(rev)
            write_sweep(sweeps_dir, rev, RADAR_SWEEP, out.arrays())
            write_ppi(ppi_dir / f"{rev:06d}.png", out.arrays(), PpiLabels.from_scenario(self.world.scenario))
            counts["sweeps"] += 1
            counts["spokes"] += self.spokes
            self.rev_wall_s.append(time.perf_counter() - started)
        return counts


def render_radar(ctx: SensorContext) -> None:
    """The ``radar`` entry for :data:`raysim.render.SENSOR_RENDERERS`."""
    renderer = RadarRenderer(ctx.world, ctx.scene())
    from tqdm import tqdm

    progress = (lambda it: tqdm(it, desc="radar", unit="rev", leave=False)) if ctx.progress else None
    counts = renderer.run(ctx.out_dir, progress)
    ctx.counts.update({f"radar/{k}": v for k, v in counts.items()})


__all__ = ["RadarParams", "RadarRenderer", "Revolution", "render_radar", "replace"]

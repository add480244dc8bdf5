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

Outputs (DESIGN.md recording contract): ``radar/sweeps/NNNNNN.npz`` and ``radar/ppi/NNNNNN.png``.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
from scipy.ndimage import gaussian_filter1d

from raysim.materials import material_index, material_table
from raysim.pose import heading_deg_from_yaw
from raysim.random_streams import stream
from raysim.recording.npz import write_npz
from raysim.recording.ppi import write_ppi
from raysim.scene import NO_HIT, SEA_ID
from raysim.sensors import radar_physics as phys
from raysim.sensors.carrier import CarrierScene
from raysim.sensors.lidar import mount_transform


@dataclass(frozen=True)
class RadarParams:
    """Radar model parameters with their defaults (sources in :mod:`raysim.sensors.radar_physics`)."""

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
    # target scattering (REF 3.6; gains unverified engineering defaults)
    diffuse_gain: float = 1.0
    specular_gain: float = 30.0
    # receiver (REF 3.10): video level v = floor((SNR_dB + STC - floor_db) / step_db), clipped 0..15.
    # floor 6.6 dB + one 3 dB step = 9.6 dB threshold: noise alone crosses it with Pfa ~ 1e-4 (REF 3 table)
    video_floor_db: float = 6.6
    video_step_db: float = 3.0
    # STC (REF 3.10) min(0, -A0 + 10 n log10(R/R0)): a moderate sea-clutter control setting, 0 dB beyond
    # 316 m (engineering default, unverified); a0 = 0 turns it off
    stc_a0_db: float = 20.0
    stc_n: float = 4.0  # REF 3.10: 3..4
    stc_r0_m: float = 100.0
    # geometry
    earth_curvature: bool = True  # drop hits below the 4/3-earth radar horizon (REF 3.4)
    elevation_up_deg: tuple = (5.0, 2.0, 0.0)  # rays at and above the horizon, antenna frame
    elevation_min_deg: float = -10.0  # steepest down-looking ray
    az_ray_spacing_deg: float = 0.2  # widest azimuth step between rays (small targets must not fall between)
    down_rays: int = 10  # rays aimed at the sea between the -10 deg ray and 1.5 x range scale
    rain_height_m: float = 1500.0  # top of the rain layer (unverified)


def _elevations(mount_height_m: float, range_m: float, p: RadarParams) -> tuple[np.ndarray, np.ndarray]:
    """Elevation angles (rad, antenna frame, descending) and the angular extent each ray stands for."""
    h = max(mount_height_m, 0.1)
    d_near = h / math.tan(math.radians(-p.elevation_min_deg))
    d_far = 1.5 * range_m
    down = -np.arctan2(h, np.geomspace(d_far, d_near, p.down_rays))
    el = np.concatenate([np.radians(np.asarray(p.elevation_up_deg, dtype=float)), down])
    el = np.unique(el)[::-1]
    edges = np.concatenate([[el[0] + 0.5 * (el[0] - el[1])], 0.5 * (el[1:] + el[:-1]), [el[-1] - 0.5 * (el[-2] - el[-1])]])
    return el, edges[:-1] - edges[1:]


@dataclass
class Revolution:
    """One revolution: the NPZ contract arrays and diagnostics."""

    echo: np.ndarray  # (S, N) uint8 0..15
    azimuth_deg: np.ndarray  # (S,) float32, clockwise from the bow
    heading_deg: np.ndarray  # (S,) float32
    time: np.ndarray  # (S,) float64
    range_m: np.ndarray  # (N,) float32
    snr_db: np.ndarray = field(repr=False, default=None)  # (S, N) float32, before quantisation
    first_hit_m: np.ndarray = field(repr=False, default=None)  # (S,) first object hit (inf: none)

    def arrays(self) -> dict:
        return {"echo": self.echo, "azimuth_deg": self.azimuth_deg, "heading_deg": self.heading_deg,
                "time": self.time, "range_m": self.range_m}


class RadarRenderer:
    """Renders the marine radar of a world's own ship.

    Parameters
    ----------
    world : raysim.world.World
    scene : CarrierScene
    params : RadarParams, optional
    """

    def __init__(self, world, scene: CarrierScene, params: RadarParams | None = None):
        self.world = world
        self.scene = scene
        s = world.scenario
        self.cfg = s.sensors.radar
        self.env = s.environment
        self.seed = s.seed
        self.p = params or RadarParams()
        self.spokes, self.samples = int(self.cfg.spokes), int(self.cfg.samples)
        self.rev_s = 60.0 / self.cfg.rpm
        self.mount_rotation, self.mount_translation = mount_transform(self.cfg.mount)
        # range_m[j] = j dR: the first sample at the antenna, the last at the range scale (REF 3 table)
        self.dr = self.cfg.range_m / (self.samples - 1)
        self.range_m = (np.arange(self.samples) * self.dr).astype(np.float32)
        self.cell_m = max(self.dr, self.p.range_resolution_m)
        self.materials = material_table()
        self.sea_material = material_index("sea")
        # azimuth sub-rays: the spokes sample azimuth unless coarser than az_ray_spacing_deg
        spoke_deg = 360.0 / self.spokes
        self.k_az = max(1, int(math.ceil(spoke_deg / self.p.az_ray_spacing_deg - 1e-9)))
        self.az_offsets_deg = ((np.arange(self.k_az) + 0.5) / self.k_az - 0.5) * spoke_deg
        self.d_az_rad = math.radians(spoke_deg / self.k_az)
        self.el_rad, self.d_el_rad = _elevations(self.cfg.mount.z_m, self.cfg.range_m, self.p)
        self.k = self.k_az * self.el_rad.size
        # two-way azimuth pattern as a circular kernel over spokes (its FFT, reused every revolution)
        offsets = np.arange(self.spokes)
        offsets = np.where(offsets > self.spokes // 2, offsets - self.spokes, offsets) * spoke_deg
        self.az_kernel_f = np.fft.rfft(phys.two_way_gain(offsets, self.p.beam_az_deg))
        # clutter / rain cells use the -3 dB width as REF 3.7 does (R theta dR sec psi); the Gaussian
        # two-way pattern's equivalent width would be 0.753 theta3 (1.2 dB less): see docs/radar.md
        self.beam_eq_rad = math.radians(self.p.beam_az_deg)
        self.bin_m = self.dr
        self._clutter_mean_db = np.full(self.samples, -np.inf)  # mean sea clutter SNR of spoke 0, no shadow (diagnostic)
        self.el_eq_rad = phys.two_way_equivalent_width_rad(self.p.beam_el_deg)
        self.gamma = phys.GammaQuantiles()
        self.snr_kw = dict(pt_w=self.p.pt_w, gain_dbi=self.p.gain_dbi, f_ghz=self.p.f_ghz, sweep_s=self.p.sweep_s,
                           noise_figure_db=self.p.noise_figure_db, losses_db=self.p.losses_db)
        self.rain_db_per_m = float(phys.rain_attenuation_db_per_km(self.env.rain_mm_per_h)) / 1000.0
        self._clutter_mean_db = phys.db(self._clutter_mean(np.array([max(self.cfg.mount.z_m, 0.05)]),
                                                           np.array([0.0]))[0])  # level own ship, spoke 0
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

    def _clutter_mean(self, antenna_h: np.ndarray, sin_tilt: np.ndarray, z_up: np.ndarray | None = None) -> np.ndarray:
        """(S, N) mean sea clutter (SNR units) without shadow: NRL sigma0 x cell area x vertical gain.

        ``sin_tilt`` (S,): world-z component of the antenna's horizontal boresight (pitch/roll tilt);
        ``z_up`` (S,): world-z component of the antenna's up axis (1 when level).
        """
        p = self.p
        r = np.maximum(self.range_m.astype(np.float64)[None, :], 0.5 * self.dr)
        psi = phys.grazing_angle_deg(antenna_h[:, None], r)
        psi_c = np.where(np.isfinite(psi), np.maximum(psi, 1e-3), 1.0)
        area = phys.clutter_cell_area_m2(r, psi_c, self.beam_eq_rad, self.cell_m)
        sigma0 = phys.undb(phys.nrl_sigma0_db(psi_c, p.f_ghz, self.env.sea_state, p.polarisation))
        zu = np.ones_like(antenna_h) if z_up is None else z_up
        psi_r = np.radians(psi_c)
        sin_el = np.cos(psi_r) * sin_tilt[:, None] - np.sin(psi_r) * zu[:, None]
        el_ant = np.degrees(np.arcsin(np.clip(sin_el, -1.0, 1.0)))
        mean = phys.snr(sigma0 * area, r, **self.snr_kw) * phys.two_way_gain(el_ant, p.beam_el_deg)
        return np.where(np.isfinite(psi), mean, 0.0)

    # ------------------------------------------------------------------ one revolution

    def revolution(self, rev: int) -> Revolution:
        """Render revolution ``rev`` (deterministic: its random streams are named after it)."""
        S, N, K = self.spokes, self.samples, self.k
        p = self.p
        idx = np.arange(S)
        t = (rev * S + idx) / (S * self.cfg.rpm / 60.0)
        azimuth = idx * (360.0 / S)
        poses, rot, pos = self._poses(t)
        heading = heading_deg_from_yaw(poses.yaw_rad)
        antenna_h = np.maximum(pos[:, 2], 0.05)

        d_s = self._sensor_directions(azimuth)  # (S, K, 3)
        d_w = np.einsum("sij,skj->ski", rot, d_s).reshape(S * K, 3)
        o_w = np.repeat(pos, K, axis=0)
        times = np.repeat(t, K)
        d_b = d_s.reshape(S * K, 3) @ self.mount_rotation.T
        o_b = np.broadcast_to(self.mount_translation, (S * K, 3))
        max_range = self.cfg.range_m * 1.5 + 10.0
        hits, on_carrier = self.scene.cast(o_w, d_w, times, o_b, d_b, max_range_m=max_range)

        # ---- targets: object hits (not the sea, not the own ship, not below the horizon)
        oid = hits.object_id
        target = (oid != NO_HIT) & (oid != SEA_ID) & ~on_carrier
        h = np.flatnonzero(target)
        r_h = hits.range_m[h]
        spoke_h = h // K
        el_idx = (h % K) % self.el_rad.size
        if p.earth_curvature and h.size:
            point = o_w[h] + r_h[:, None] * d_w[h]
            horiz = np.hypot(point[:, 0] - o_w[h, 0], point[:, 1] - o_w[h, 1])
            visible = point[:, 2] >= phys.hidden_height_m(horiz, antenna_h[spoke_h])
            h, r_h, spoke_h, el_idx = h[visible], r_h[visible], spoke_h[visible], el_idx[visible]
        cos_inc = np.abs(np.einsum("ij,ij->i", hits.normal[h].astype(np.float64), d_w[h]))
        mat = hits.material[h]
        sigma = phys.facet_sigma_m2(self.materials["radar_reflectivity_db"][mat], cos_inc,
                                    self.materials["specular_exponent"][mat], r_h, self.d_az_rad,
                                    self.d_el_rad[el_idx], p.diffuse_gain, p.specular_gain)
        sigma = sigma * phys.two_way_gain(np.degrees(self.el_rad[el_idx]), p.beam_el_deg)
        power = phys.snr(sigma, r_h, **self.snr_kw)
        bins = np.rint(r_h / self.dr).astype(np.int64)
        ok = bins < N
        targets = np.bincount(spoke_h[ok] * N + bins[ok], weights=power[ok], minlength=S * N).reshape(S, N)
        first_hit = np.full(S, np.inf)
        np.minimum.at(first_hit, spoke_h, r_h)
        # azimuth beam: circular convolution over spokes; range point-spread when bins are finer than it
        if h.size:
            targets = np.fft.irfft(np.fft.rfft(targets, axis=0) * self.az_kernel_f[:, None], n=S, axis=0)
            np.maximum(targets, 0.0, out=targets)
            sigma_bins = p.range_resolution_m / 2.3548 / self.dr
            if sigma_bins > 0.3:
                targets = gaussian_filter1d(targets, sigma_bins, axis=1, mode="constant") * (math.sqrt(2 * math.pi) * sigma_bins)

        # ---- sea clutter (NRL mean, K-distributed), absent in the shadow behind the first hit
        r = self.range_m.astype(np.float64)[None, :]
        psi = phys.grazing_angle_deg(antenna_h[:, None], np.maximum(r, 0.5 * self.dr))  # (S, N), NaN beyond horizon
        sea = np.isfinite(psi) & (r < first_hit[:, None])
        psi_c = np.where(np.isfinite(psi), np.maximum(psi, 1e-3), 1.0)
        area = phys.clutter_cell_area_m2(np.maximum(r, 0.5 * self.dr), psi_c, self.beam_eq_rad, self.cell_m)
        sigma0 = phys.undb(phys.nrl_sigma0_db(psi_c, p.f_ghz, self.env.sea_state, p.polarisation))
        # vertical pattern at the depression of the sea cell in the antenna frame (roll/pitch included)
        bearing = np.radians(azimuth)
        dxy = np.stack([np.cos(bearing), -np.sin(bearing), np.zeros(S)], 1)  # horizontal in the sensor frame
        bore = np.einsum("sij,sj->si", rot, dxy)
        bh = bore[:, :2] / np.maximum(np.linalg.norm(bore[:, :2], axis=1, keepdims=True), 1e-12)
        z_ax = rot[:, :, 2]  # the antenna's up axis in the world
        psi_r = np.radians(psi_c)
        sin_el = (np.cos(psi_r) * (z_ax[:, 0] * bh[:, 0] + z_ax[:, 1] * bh[:, 1])[:, None]
                  - np.sin(psi_r) * z_ax[:, 2][:, None])
        el_ant = np.degrees(np.arcsin(np.clip(sin_el, -1.0, 1.0)))
        clutter_open = np.where(np.isfinite(psi), phys.snr(sigma0 * area, np.maximum(r, 0.5 * self.dr), **self.snr_kw)
                                * phys.two_way_gain(el_ant, p.beam_el_deg), 0.0)
        clutter_mean = np.where(sea, clutter_open, 0.0)
        rng = stream(self.seed, f"radar.clutter.{rev}")
        if self.env.sea_state >= 0 and sea.any():
            theta_sw = (azimuth + heading)[:, None] - self.env.wind_from_deg
            nu = phys.ward_shape_nu(psi_c, area, p.polarisation, theta_sw)
            texture = self._texture(rng, nu)
            speckle = rng.standard_exponential((S, N))
            clutter = clutter_mean * texture * speckle
        else:
            clutter = clutter_mean

        # ---- rain: volume clutter (exponential speckle) and two-way attenuation
        rain = 0.0
        if self.env.rain_mm_per_h > 0:
            rr = np.maximum(r, 0.5 * self.dr)
            volume = rr * self.beam_eq_rad * self.cell_m * np.minimum(rr * self.el_eq_rad / 2.0, p.rain_height_m)
            eta = phys.rain_eta_m2_per_m3(self.env.rain_mm_per_h, p.f_ghz)
            rain = phys.snr(eta * volume, rr, **self.snr_kw) * stream(self.seed, f"radar.rain.{rev}").standard_exponential((S, N))
        loss = phys.undb(-2.0 * self.rain_db_per_m * r)

        # ---- receiver
        noise = stream(self.seed, f"radar.noise.{rev}").standard_exponential((S, N))
        total = (targets + clutter + rain) * loss + noise
        p_db = phys.db(total) + phys.stc_gain_db(r, p.stc_a0_db, p.stc_n, p.stc_r0_m)
        echo = phys.quantise(p_db, p.video_floor_db, p.video_step_db)
        return Revolution(echo, azimuth.astype(np.float32), heading.astype(np.float32), t, self.range_m,
                          p_db.astype(np.float32), first_hit)

    def _texture(self, rng: np.random.Generator, nu: np.ndarray) -> np.ndarray:
        """Gamma(nu, mean 1) texture correlated over range (REF 3.8 length) and one beamwidth in azimuth."""
        S, N = nu.shape
        white = rng.standard_normal((S, N))
        length = phys.texture_correlation_length_m(self.env.sea_state)
        sig_r = length / self.dr  # bins
        sig_a = (self.p.beam_az_deg / 2.3548) / (360.0 / S)  # spokes
        fs = np.fft.fftfreq(S)[:, None]
        fr = np.fft.rfftfreq(N)[None, :]
        transfer = np.exp(-2.0 * math.pi**2 * ((fs * sig_a) ** 2 + (fr * sig_r) ** 2))
        field_ = np.fft.irfft2(np.fft.rfft2(white) * transfer, s=(S, N))
        std = math.sqrt(float(np.sum(transfer[:, 0] ** 2) + 2.0 * np.sum(transfer[:, 1:] ** 2)) / (S * N))
        return self.gamma(field_ / max(std, 1e-12), nu)

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
            write_npz(sweeps_dir / f"{rev:06d}.npz", out.arrays())
            write_ppi(ppi_dir / f"{rev:06d}.png", out.arrays())
            counts["sweeps"] += 1
            counts["spokes"] += self.spokes
            self.rev_wall_s.append(time.perf_counter() - started)
        return counts


def render_radar(ctx) -> None:
    """The ``radar`` entry for :data:`raysim.render.SENSOR_RENDERERS`."""
    renderer = RadarRenderer(ctx.world, ctx.scene())
    from tqdm import tqdm

    progress = (lambda it: tqdm(it, desc="radar", unit="rev", leave=False)) if ctx.progress else None
    counts = renderer.run(ctx.out_dir, progress)
    ctx.counts.update({f"radar/{k}": v for k, v in counts.items()})


__all__ = ["RadarParams", "RadarRenderer", "Revolution", "render_radar", "replace"]

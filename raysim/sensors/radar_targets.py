"""The radar's object echoes: coherent physical optics over the rays of the beam, two bounces, the sea's image.

Per revolution, from the hits of the fan of rays (:meth:`raysim.sensors.radar.RadarRenderer.rays`):

1. **Patches.** Each ray that hits an object (the own ship excluded; below the 4/3-earth horizon
   dropped, REF 3.4) lights a patch; its echo is the physical-optics amplitude of
   :func:`raysim.sensors.radar_po.patch_amplitude`, with its phase ``exp(-j k L)``.
2. **The sea's image** (multipath, REF 3.5): the four paths antenna -> patch -> antenna with either
   leg reflected by the sea, each with its own bistatic PO amplitude, the sea's reflection
   coefficient ``Gamma`` (:func:`sea_gamma`: Fresnel of sea water times Ament) per sea leg and the vertical antenna pattern at each
   leg's elevation. A vertical wall over the sea is then the hull-sea dihedral it is, and low parts
   of a target fade in the two-ray nulls.
3. **Second bounce** (shooting and bouncing rays): each lit patch reflects its tube specularly,
   ``d' = d - 2 (d.n) n``, Embree casts it, and the patch it reaches radiates back to the antenna
   (directly and via the sea): deck-superstructure dihedrals and corner reflectors return what
   they do.
4. **Surface roughness** (REF 3.6): a material of rms height ``h`` keeps the coherent fraction
   ``q = exp(-(2 k h cos theta)^2)`` of the specular amplitude; the rest goes into its rough lobe
   ``(1 - q) rho a (4 (n + 2) / 3) cos^n theta`` with the phase of the surface's micro-relief, a
   smooth random field fixed to the body (named stream ``radar.roughness``): it moves with the object.
5. **Coherent beam.** The complex echoes are summed per (spoke, range sample), convolved along range
   with the range impulse response and over the spokes with the two-way *voltage* pattern of the
   antenna (main lobe and sidelobes), then ``|.|^2`` through the radar equation. Spokes are fired at
   different times; before the sum each echo's phase is advanced to a common time with the radial
   velocity of its object (translation): the sum over the beam is that of one instant, as the real
   echo is. Fluctuation (scintillation) comes from the phases as the aspect, the antenna's height
   and the sampled patches change: nothing is drawn.
"""

from __future__ import annotations

import math
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import scipy.fft

from raysim.motion import Stationary
from raysim.random_streams import stream
from raysim.rcs.sea import sea_reflection_coefficient
from raysim.scene import NO_HIT, SEA_ID
from raysim.sensors import radar_physics as phys
from raysim.sensors.radar_po import dot, patch_amplitude, reflect

__all__ = ["TargetEchoes", "sea_gamma"]

#: Offset of a bounced ray's origin along its new direction, m.
BOUNCE_EPSILON_M = 1e-3
#: Time step of the finite difference giving an object's velocity, s.
VELOCITY_STEP_S = 0.05
#: Echoes whose peak SNR stays under this (linear) are left out of the beam sum: at most 1 % of the noise power.
INVISIBLE_SNR = 0.01
#: Threads of the beam's FFTs over spokes.
FFT_WORKERS = 2
#: Up to this many spokes with a strong echo the range skirt goes over the spokes by a matrix product on the
#: main lobe's rows; beyond, by an FFT over all spokes (a coast paints on every spoke).
SKIRT_MATMUL_MAX_SPOKES = 64
#: Roughness relief: wavevectors of the body-fixed random phase field (count, wavelength m, phase scale).
RELIEF_WAVES = 8
RELIEF_WAVELENGTH_M = 0.3
RELIEF_PHASE_SCALE = 2.0


def sea_gamma(sin_grazing: np.ndarray, sea_state: int, f_ghz: float, pol: str = "HH") -> np.ndarray:
    """Coherent amplitude reflection coefficient of the sea (REF 3.5): Fresnel of sea water times Ament's roughness.

    :func:`raysim.rcs.sea.sea_reflection_coefficient` (Klein-Swift permittivity; near -1 for HH at low grazing).

    Parameters
    ----------
    sin_grazing : (M,) float
    sea_state : int
    f_ghz : float
    pol : str

    Returns
    -------
    (M,) complex128
    """
    psi = np.arcsin(np.clip(np.asarray(sin_grazing, dtype=float), 0.0, 1.0))
    return sea_reflection_coefficient(psi, pol, sea_state, f_ghz)


def _unit(v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    length = np.linalg.norm(v, axis=1)
    return v / np.maximum(length, 1e-12)[:, None], length


class TargetEchoes:
    """Object echoes of a radar renderer's revolutions (module docstring).

    Parameters
    ----------
    renderer : raysim.sensors.radar.RadarRenderer
        Its geometry (spokes, samples, ray fan), parameters, scene, world and seed are used.
    """

    def __init__(self, renderer):
        self.r = renderer
        p = renderer.p
        self.k = 2.0 * math.pi / phys.wavelength_m(p.f_ghz)
        self.n_el = renderer.el_rad.size
        objs = renderer.world.objects
        self.motion = {o.object_id: o.motion for o in objs}
        rng = stream(renderer.seed, "radar.roughness")
        dirs = rng.standard_normal((RELIEF_WAVES, 3))
        self.relief_k = dirs / np.linalg.norm(dirs, axis=1, keepdims=True) * (2.0 * math.pi / RELIEF_WAVELENGTH_M)
        self.relief_phase = rng.uniform(0.0, 2.0 * math.pi, RELIEF_WAVES)
        self.snr_amp = np.sqrt(phys.snr(1.0, renderer.r64, **renderer.snr_kw))  # (N,) sqrt(SNR) per sqrt(m^2)
        self._az_kernel_f_row = renderer.az_kernel_f.astype(np.complex64)[None, :]  # (1, S) voltage pattern spectrum
        self._az_power_pattern_f_row = np.fft.rfft(renderer.az_power_pattern)[None, :]  # (1, S // 2 + 1) power pattern
        self._stationary: dict[int, tuple[np.ndarray, np.ndarray]] = {}  # poses of stationary objects, by id
        skirt = renderer.range_skirt_kernel
        self._skirt_peak = 0.0 if skirt is None else float(np.max(skirt))

    # ------------------------------------------------------------------ per hit

    def _tube_axes(self, spoke: np.ndarray, j: np.ndarray, rot: np.ndarray, azimuth: np.ndarray):
        r = self.r
        a = np.radians(azimuth[spoke] + r.az_offsets_deg[j // self.n_el])
        e = r.el_rad[j % self.n_el]
        u_s = np.stack([-np.sin(a), -np.cos(a), np.zeros_like(a)], axis=1)
        v_s = np.stack([-np.sin(e) * np.cos(a), np.sin(e) * np.sin(a), np.cos(e)], axis=1)
        return np.einsum("nij,nj->ni", rot[spoke], u_s), np.einsum("nij,nj->ni", rot[spoke], v_s)

    def _object_terms(self, oid: np.ndarray, t_hit: np.ndarray, point: np.ndarray):
        """Per hit: its object's velocity (translation, m/s) and the body-fixed relief phase (rad)."""
        velocity = np.zeros_like(point)
        relief = np.zeros(len(oid))
        for obj in np.unique(oid):
            idx = np.flatnonzero(oid == obj)
            motion = self.motion[int(obj)]
            if isinstance(motion, Stationary):  # land, buoys: one pose for all hits, no velocity (the same values)
                rotation_1, position_1 = self._stationary_pose(int(obj), motion)
                rotation = np.broadcast_to(rotation_1, (idx.size, 3, 3))
                body = np.einsum("nji,nj->ni", rotation, point[idx] - position_1)
            else:
                now = motion.poses(t_hit[idx])
                later = motion.poses(t_hit[idx] + VELOCITY_STEP_S)
                velocity[idx] = (later.position_m - now.position_m) / VELOCITY_STEP_S
                body = now.to_body(point[idx])
            relief[idx] = RELIEF_PHASE_SCALE * 2.0 * math.pi * np.sum(
                np.cos(body @ self.relief_k.T + self.relief_phase + 1.7 * float(obj)), axis=1)
        return velocity, relief

    def _stationary_pose(self, object_id: int, motion: Stationary) -> tuple[np.ndarray, np.ndarray]:
        """(1, 3, 3) body -> world rotation and (1, 3) position, m, of a stationary object (formed once, kept)."""
        pose = self._stationary.get(object_id)
        if pose is None:
            now = motion.poses(np.zeros(1))
            pose = self._stationary[object_id] = (now.rotation(), now.position_m)
        return pose

    def _material(self, material: np.ndarray, cos_i: np.ndarray):
        m = self.r.materials
        rho = phys.undb(m["radar_reflectivity_db"][material])
        q = np.exp(-(2.0 * self.k * m["radar_roughness_m"][material] * cos_i) ** 2)
        return rho, q, m["specular_exponent"][material].astype(float)

    def _v_gain(self, el_rad: np.ndarray) -> np.ndarray:
        return self.r.pattern.vertical_voltage(np.degrees(el_rad))

    # ------------------------------------------------------------------ the revolution

    def render(self, hits, on_carrier, t, o_w, d_w, antenna_h, rot, azimuth, max_range_m: float):
        """(S, N) object echoes (SNR, linear; None if none), the first hit range per spoke, the objects seen.

        Returns
        -------
        targets : (S, N) float32 or None
        first_hit : (S,) float64, m (inf: no object hit)
        seen : tuple of two (K,) int32
            Ids of the objects a ray reached (first along it, above the horizon) and on how many spokes.
        """
        r = self.r
        S, K = r.spokes, r.k
        oid = hits.object_id
        h = np.flatnonzero((oid != NO_HIT) & (oid != SEA_ID) & ~on_carrier)
        first_hit = np.full(S, np.inf)
        nothing = (np.zeros(0, np.int32), np.zeros(0, np.int32))
        if h.size == 0:
            return None, first_hit, nothing
        r_h = hits.range_m[h]
        spoke = h // K
        point = o_w[h] + r_h[:, None] * d_w[h]
        if r.p.earth_curvature:  # below the 4/3-earth horizon: hidden (REF 3.4)
            horiz = np.hypot(point[:, 0] - o_w[h, 0], point[:, 1] - o_w[h, 1])
            keep = point[:, 2] >= phys.hidden_height_m(horiz, antenna_h[spoke])
            h, r_h, spoke, point = h[keep], r_h[keep], spoke[keep], point[keep]
            if h.size == 0:
                return None, first_hit, nothing
        np.minimum.at(first_hit, spoke, r_h)
        pairs = np.unique(oid[h].astype(np.int64) * S + spoke)
        seen_id, seen_spokes = np.unique(pairs // S, return_counts=True)
        seen = (seen_id.astype(np.int32), seen_spokes.astype(np.int32))

        velocity, relief = self._object_terms(oid[h], t[spoke], point)
        amp, rng_m = self._first_bounce(h, r_h, spoke, point, hits, o_w, d_w, rot, azimuth, relief)
        amp2, rng2, keep2 = self._second_bounce(h, r_h, spoke, point, hits, t, o_w, d_w, rot, azimuth, max_range_m)
        # phases advanced to the revolution's start with each object's radial velocity (module docstring)
        ant_v = np.gradient(o_w[::K], t, axis=0) if S > 1 else np.zeros((1, 3))
        v_r = dot(velocity - ant_v[spoke], d_w[h])
        doppler = np.exp(1j * 2.0 * self.k * v_r * (t[spoke] - t[0]))
        amp = amp * doppler
        if amp2 is not None:
            spoke = np.concatenate([spoke, spoke[keep2]])
            rng_m = np.concatenate([rng_m, rng2])
            amp = np.concatenate([amp, amp2 * doppler[keep2]])
        return self._beam(*self._deposit(spoke, rng_m, amp)), first_hit, seen

    def _first_bounce(self, h, r_h, spoke, point, hits, o_w, d_w, rot, azimuth, relief):
        """Complex amplitudes (H,) of the lit patches (four sea paths, rough lobe) and their ranges (H,), m."""
        r = self.r
        j = h % r.k
        d = d_w[h]
        o = o_w[h]
        n = hits.normal[h].astype(np.float64)
        u, v = self._tube_axes(spoke, j, rot, azimuth)
        w_u = r_h * r.d_az_rad
        w_v = r_h * r.d_el_rad[j % self.n_el]
        cos_i = np.clip(-dot(n, d), 0.0, 1.0)
        rho, q, lobe_n = self._material(hits.material[h], cos_i)
        el_d = r.el_rad[j % self.n_el]
        g_d = self._v_gain(el_d)
        path = [(d, -d, 2.0 * r_h, g_d * g_d)]
        diffuse_legs = g_d
        if r.p.multipath:
            o_img = o * np.array([1.0, 1.0, -1.0])
            d_img, l_img = _unit(point - o_img)
            sin_psi = d_img[:, 2]
            gamma = sea_gamma(sin_psi, r.env.sea_state, r.p.f_ghz, r.p.polarisation)
            el_i = el_d + (-np.arcsin(np.clip(sin_psi, -1, 1)) - np.arcsin(np.clip(d[:, 2], -1, 1)))
            g_i = self._v_gain(el_i) * gamma
            # out by the sea and back direct, and its reverse: the same patch amplitude (d_in - d_out, lit legs and
            # length alike), formed once and added twice (term by term, as two paths are)
            path += [(d_img, -d, l_img + r_h, g_i * g_d), (None, None, None, g_d * g_i),
                     (d_img, -d_img, 2.0 * l_img, g_i * g_i)]
            lit_img = -dot(n, d_img) > 0.0
            diffuse_legs = g_d + np.where(lit_img, g_i, 0.0) * np.exp(-1j * self.k * (l_img - r_h))
        spec = np.zeros(h.size, complex)
        for d_in, d_out, length, gain in path:
            if d_in is not None:
                patch = patch_amplitude(self.k, n, d, u, v, w_u, w_v, d_in, d_out, length)
            spec += gain * patch
        spec *= np.sqrt(rho * q)
        sigma_rough = (r.p.diffuse_gain * rho * (1.0 - q) * w_u * w_v * (4.0 * (lobe_n + 2.0) / 3.0)
                       * np.power(cos_i, lobe_n))
        rough = np.sqrt(sigma_rough) * diffuse_legs * diffuse_legs * np.exp(-1j * (2.0 * self.k * r_h + relief))
        return spec + rough, r_h

    def _second_bounce(self, h, r_h, spoke, point, hits, t, o_w, d_w, rot, azimuth, max_range_m):
        """Complex amplitudes of the patches the specular bounce of each lit patch reaches, their ranges, which."""
        r = self.r
        j = h % r.k
        d = d_w[h]
        n = hits.normal[h].astype(np.float64)
        d2 = reflect(d, n)
        origin = point + BOUNCE_EPSILON_M * d2
        hits2 = r.scene.world.cast(origin, d2, t[spoke], max_range_m=max_range_m)
        keep = np.flatnonzero((hits2.object_id != NO_HIT) & (hits2.object_id != SEA_ID))
        if keep.size == 0:
            return None, None, keep
        d, d2, n = d[keep], d2[keep], n[keep]
        r1, r2 = r_h[keep], hits2.range_m[keep]
        p2 = origin[keep] + r2[:, None] * d2
        n2 = hits2.normal[keep].astype(np.float64)
        o = o_w[h[keep]]
        u, v = self._tube_axes(spoke[keep], j[keep], rot, azimuth)
        u2, v2 = reflect(u, n), reflect(v, n)
        w_u = r1 * r.d_az_rad
        w_v = r1 * r.d_el_rad[j[keep] % self.n_el]
        rho1, q1, _ = self._material(hits.material[h[keep]], np.clip(-dot(n, d), 0, 1))
        rho2, q2, _ = self._material(hits2.material[keep], np.clip(-dot(n2, d2), 0, 1))
        el_in = r.el_rad[j[keep] % self.n_el]
        tilt = el_in - np.arcsin(np.clip(d[:, 2], -1, 1))  # antenna-frame minus world elevation
        g_in = self._v_gain(el_in)
        s_d, l_d = _unit(o - p2)
        outs = [(s_d, l_d, self._v_gain(np.arcsin(np.clip(-s_d[:, 2], -1, 1)) + tilt))]
        if r.p.multipath:
            s_i, l_i = _unit(o * np.array([1.0, 1.0, -1.0]) - p2)
            gamma = sea_gamma(-s_i[:, 2], r.env.sea_state, r.p.f_ghz, r.p.polarisation)
            outs.append((s_i, l_i, gamma * self._v_gain(np.arcsin(np.clip(-s_i[:, 2], -1, 1)) + tilt)))
        amp = np.zeros(keep.size, complex)
        for s_out, l_out, gain in outs:
            amp += g_in * gain * patch_amplitude(self.k, n2, d2, u2, v2, w_u, w_v, d2, s_out, r1 + r2 + l_out)
        amp *= np.sqrt(rho1 * q1 * rho2 * q2)
        amp *= self._return_gain(d, s_d)
        return amp, (r1 + r2 + l_d) / 2.0, keep

    def _return_gain(self, d_in: np.ndarray, s_back: np.ndarray) -> np.ndarray:
        """(M,) complex one-way horizontal gain of a second bounce's return leg off the incident ray's azimuth.

        The echo is placed on its incident ray's spoke and the beam sum gives it the two-way pattern about
        that direction, as if it came back the way it went. It comes back from the second patch: seen from the
        antenna at azimuth ``Delta`` off the incident ray, it is received with ``g_h(Delta)`` (one way), at the
        main lobe only when both patches lie in the beam (a corner of one object), through a sidelobe when they
        do not (a quay seen across a basin from another quay).

        Parameters
        ----------
        d_in : (M,) 3-vectors
            Unit directions of the incident rays (antenna -> first patch), world frame.
        s_back : (M,) 3-vectors
            Unit directions second patch -> antenna, world frame.
        """
        az_in = np.degrees(np.arctan2(d_in[:, 0], d_in[:, 1]))
        az_back = np.degrees(np.arctan2(-s_back[:, 0], -s_back[:, 1]))
        return self.r.pattern.horizontal_voltage(az_back - az_in)

    # ------------------------------------------------------------------ sum, range and beam

    def _deposit(self, spoke: np.ndarray, range_m: np.ndarray, amp: np.ndarray):
        """Sum the amplitudes per spoke and nearest range sample (beyond the scale: dropped).

        Returns
        -------
        rows : (R,) int64
            The spokes with an echo.
        cells : (Q,) int64
            Increasing flat indices, in an (R, N) array of ``rows``' range samples, of the cells holding an echo.
        values : (Q,) complex64
            Their summed amplitudes, sqrt(SNR) (through the radar equation at each echo's range).
        """
        N = self.r.samples
        bins = np.rint(range_m / self.r.dr).astype(np.int64)
        ok = bins < N
        rows, row_of = np.unique(spoke[ok], return_inverse=True)
        cells, cell_of = np.unique(row_of * N + bins[ok], return_inverse=True)
        amp = amp[ok] * self.snr_amp[bins[ok]]  # sqrt(m^2) -> sqrt(SNR) through the radar equation at the echo's range
        values = np.empty(cells.size, np.complex64)
        values.real = np.bincount(cell_of, weights=amp.real, minlength=cells.size)
        values.imag = np.bincount(cell_of, weights=amp.imag, minlength=cells.size)
        return rows, cells, values

    def _skirt(self, rows: np.ndarray, cells: np.ndarray, values: np.ndarray):
        """The incoherent range skirt (phase noise) of the strong echoes, through the two-way power pattern.

        Only cells whose skirt can rise over INVISIBLE_SNR are spread (the skirt is -65 dB under its echo: echoes
        over about 45 dB): along range by :meth:`RadarRenderer.range_skirt` (on blocks of samples), over spokes by one
        matrix product with the power pattern, on the spokes where the pattern can lift the strongest skirt over
        INVISIBLE_SNR (the main lobe: the skirt's sidelobes would be some 115 dB under its echo).

        Parameters
        ----------
        rows : (R,) int64
            Spokes of the echoes' rows.
        cells : (Q,) int64
            Increasing flat indices of the echo cells in the (R, N) array of ``rows``' range samples.
        values : (Q,) complex64
            Summed amplitudes of those cells before the range response, sqrt(SNR).

        Returns
        -------
        None, or blocks : (M, B) float32 and spokes : (M,) int or None
            SNR to add per block of range samples (:meth:`RadarRenderer.add_blocks`) on the spokes ``spokes``
            (None: all S spokes).
        """
        r = self.r
        if r.range_skirt_kernel is None:
            return None
        N = r.samples
        cell_power = values.real**2 + values.imag**2
        strong = np.flatnonzero(cell_power * np.float32(self._skirt_peak) > INVISIBLE_SNR)
        if strong.size == 0:
            return None
        strong_rows, row_of = np.unique(cells[strong] // N, return_inverse=True)
        strong_power = np.zeros((strong_rows.size, N), np.float32)
        strong_power[row_of, cells[strong] % N] = cell_power[strong]
        skirt = r.range_skirt(strong_power)  # (R', B)
        S = r.spokes
        reach = np.flatnonzero(r.az_power_pattern * skirt.max() > INVISIBLE_SNR)  # spoke offsets that count
        spokes = rows[strong_rows]
        if spokes.size <= SKIRT_MATMUL_MAX_SPOKES:  # a few strong spokes: the main lobe's rows by a matrix product
            out = np.unique((spokes[:, None] + reach[None, :]) % S)
            pattern = r.az_power_pattern[(out[:, None] - spokes[None, :]) % S]  # (O, R') float32, >= 0
            return pattern @ skirt, out
        # many (a coast on every spoke): one circular convolution over all spokes, on the blocks, one block a row (the
        # FFTs along memory: the same values as down the columns of an (S, B) array, in half the time)
        full = np.zeros((skirt.shape[1], S), np.float32)
        full[:, spokes] = skirt.T
        spread = scipy.fft.irfft(scipy.fft.rfft(full, axis=1, workers=FFT_WORKERS) * self._az_power_pattern_f_row,
                                 n=S, axis=1, workers=FFT_WORKERS)
        return np.maximum(spread.T, 0.0).astype(np.float32, order="C"), None

    def _beam(self, rows: np.ndarray, cells: np.ndarray, values: np.ndarray) -> np.ndarray | None:
        """Range impulse response and two-way voltage beam over spokes, then power through the radar equation.

        Parameters
        ----------
        rows : (R,) int64
            Spokes with an echo.
        cells : (Q,) int64
            Increasing flat indices of the echo cells in the (R, N) array of ``rows``' range samples.
        values : (Q,) complex64
            Summed amplitudes of those cells, sqrt(SNR).

        Returns
        -------
        (S, N) float32 or None
            SNR (linear) of the object echoes; None if there is none.
        """
        r = self.r
        S, N = r.spokes, r.samples
        if rows.size == 0:
            return None
        power = np.zeros((S, N), np.float32)
        # the range skirt on a thread of its own (FFTs that release the GIL) beside the range filter; the two sums
        # meet in ``power`` after both, in either order the same bytes (two terms: IEEE addition commutes)
        with ThreadPoolExecutor(max_workers=1, thread_name_prefix="radar-skirt") as pool:
            skirt = pool.submit(self._skirt, rows, cells, values)
            # the range filter on the cells it reaches (a coast on every spoke: a dense field would be mostly zeros)
            reached, field = r.range_filter_cells(values, cells, (rows.size, N))
            row_of, col_of = np.divmod(reached, N)
            # range samples whose strongest echo, even at the beam's peak, stays under INVISIBLE_SNR: left out
            peak = np.zeros(N, np.float32)
            np.maximum.at(peak, col_of, field.real**2 + field.imag**2)
            cols = np.flatnonzero(peak > INVISIBLE_SNR)
            if cols.size:
                slot_of_col = np.full(N, -1, np.int64)
                slot_of_col[cols] = np.arange(cols.size)
                slot = slot_of_col[col_of]
                kept = slot >= 0
                # one range column per row, its spokes contiguous: the FFTs over spokes run along memory (half the
                # time of the same transforms down the columns of an (S, C) array; the same values, line by line)
                full = np.zeros((cols.size, S), np.complex64)
                full[slot[kept], rows[row_of[kept]]] = field[kept]
                spectrum = scipy.fft.fft(full, axis=1, workers=FFT_WORKERS, overwrite_x=True)
                spectrum *= self._az_kernel_f_row
                sub = scipy.fft.ifft(spectrum, axis=1, workers=FFT_WORKERS, overwrite_x=True)
                _add_columns(power, cols, (sub.real**2 + sub.imag**2).T)
            spread = skirt.result()
        if spread is not None:
            r.add_blocks(power, *spread)
        return power


def _add_columns(power: np.ndarray, cols: np.ndarray, values: np.ndarray) -> None:
    """``power[:, cols] += values`` by runs of consecutive columns (slices: a fancy column index is slow).

    Parameters
    ----------
    power : (S, N) float32
    cols : (C,) int, increasing
    values : (S, C) float32
    """
    breaks = np.flatnonzero(np.diff(cols) > 1) + 1
    for a, b in zip(np.r_[0, breaks], np.r_[breaks, cols.size]):  # a few runs per object in range
        power[:, cols[a]: cols[b - 1] + 1] += values[:, a:b]

"""The radar's fast paths against plain dense references: the beam over spokes and the range skirt (issue 23)."""

from __future__ import annotations

import numpy as np
import pytest

from raysim.sensors import radar_targets
from tests.raysim.test_radar_targets import SAMPLES, SPOKES, renderer


@pytest.fixture(scope="module")
def radar(tmp_path_factory):
    return renderer(tmp_path_factory.mktemp("fast"), "fast")


def _echo_cells(rng: np.random.Generator, rows_count: int, per_row: int, amplitude: float):
    """Random spokes (R,), increasing flat cells in their (R, N) array and complex64 values of ``amplitude``."""
    rows = np.sort(rng.choice(SPOKES, rows_count, replace=False))
    cells = np.unique(np.concatenate([r * SAMPLES + rng.choice(np.arange(20, SAMPLES - 20), per_row, replace=False)
                                      for r in range(rows_count)]))
    phase = rng.uniform(0.0, 2.0 * np.pi, cells.size)
    values = (amplitude * rng.uniform(0.5, 1.0, cells.size) * np.exp(1j * phase)).astype(np.complex64)
    return rows, cells, values


def _dense_beam_power(radar, rows, cells, values) -> np.ndarray:
    """(S, N) |range response * two-way voltage beam over spokes|^2, dense, complex128 (no skirt)."""
    field = np.zeros((SPOKES, SAMPLES), complex)
    field[rows[cells // SAMPLES], cells % SAMPLES] = values
    half = radar.range_kernel.size // 2
    field = np.stack([np.convolve(row, radar.range_kernel)[half: half + SAMPLES] for row in field])
    beam = np.fft.ifft(np.fft.fft(field, axis=0) * radar.az_kernel_f[:, None], axis=0)
    return np.abs(beam) ** 2


@pytest.mark.parametrize("rows_count", [3, 40])
def test_beam_over_spokes_equals_the_dense_correlation(radar, rows_count):
    rng = np.random.default_rng(rows_count)
    rows, cells, values = _echo_cells(rng, rows_count, 4, 30.0)  # 30 dB: no skirt over INVISIBLE_SNR
    power = radar.targets._beam(rows, cells, values)
    expected = _dense_beam_power(radar, rows, cells, values)
    assert power.shape == (SPOKES, SAMPLES) and power.dtype == np.float32
    np.testing.assert_allclose(power, expected, rtol=1e-3, atol=1e-4 * expected.max())


@pytest.mark.parametrize("rows_count", [10, 200])  # the matrix product (<= 64 spokes) and the FFT over all spokes
def test_range_skirt_over_spokes_equals_the_dense_circular_sum(radar, rows_count):
    rng = np.random.default_rng(100 + rows_count)
    rows, cells, values = _echo_cells(rng, rows_count, 2, 1e4)  # 80 dB echoes: their skirt shows
    spread = radar.targets._skirt(rows, cells, values)
    assert spread is not None
    blocks, spokes = spread
    assert (spokes is None) == (rows_count > radar_targets.SKIRT_MATMUL_MAX_SPOKES)
    # the dense reference: every echo row's blocks (the range part, shared), then sum_s P[(i - s) % S] skirt[s]
    power = np.zeros((rows_count, SAMPLES), np.float32)
    power[cells // SAMPLES, cells % SAMPLES] = np.abs(values.astype(complex)) ** 2
    per_row = radar.range_skirt(power)
    offsets = (np.arange(SPOKES)[:, None] - rows[None, :]) % SPOKES
    expected = radar.az_power_pattern.astype(float)[offsets] @ per_row.astype(float)  # (S, B)
    got = np.zeros_like(expected)
    got[slice(None) if spokes is None else spokes] = blocks
    assert blocks.dtype == np.float32 and blocks.flags.c_contiguous
    assert expected.max() > 100 * radar_targets.INVISIBLE_SNR
    # the matrix product leaves out the spokes where even the strongest skirt stays under INVISIBLE_SNR (by design)
    np.testing.assert_allclose(got, expected, rtol=1e-3, atol=radar_targets.INVISIBLE_SNR)


# ------------------------------------------------------------------ sea clutter: the same bytes as the plain forms

def _sea_clutter(sea_state: int = 4, spokes: int = 2048, samples: int = 1024):
    from raysim.sensors.radar import RadarParams
    from raysim.sensors.radar_clutter import SeaClutter

    p = RadarParams()
    range_m = (np.arange(samples) * (1852.0 / (samples - 1))).astype(np.float32)
    snr_kw = dict(pt_w=p.pt_w, gain_dbi=p.gain_dbi, f_ghz=p.f_ghz, sweep_s=p.sweep_s,
                  noise_figure_db=p.noise_figure_db, losses_db=p.losses_db)
    return SeaClutter(range_m, spokes, max(float(range_m[1]), p.range_resolution_m), p, sea_state, 60.0, 11, snr_kw)


def _spoke_geometry(clutter, rng: np.random.Generator):
    """Rotations (S, 3, 3) of a rolling, pitching ship heading 30 deg, positions (S, 3), azimuths (S,), heights (S,)."""
    from scipy.spatial.transform import Rotation

    S = clutter.spokes
    angles = np.stack([np.full(S, 90.0 - 30.0), rng.normal(0, 2, S), rng.normal(0, 4, S)], axis=1)
    rot = Rotation.from_euler("ZYX", angles, degrees=True).as_matrix()
    pos = np.stack([rng.normal(300, 5, S), rng.normal(-200, 5, S), 12.0 + rng.normal(0, 0.3, S)], axis=1)
    return rot, pos, np.arange(S) * (360.0 / S), pos[:, 2]


def test_gamma_quantiles_equal_the_plain_interpolation():
    from raysim.sensors.radar_physics import GammaQuantiles

    g = GammaQuantiles()
    rng = np.random.default_rng(3)
    z = np.concatenate([rng.normal(size=20_000), [-9.0, -6.0, 0.0, 5.999, 6.0, 9.0]]).astype(np.float32)
    log_nu = rng.uniform(-5.0, 6.0, z.size).astype(np.float32)  # beyond the table's shapes both ways
    assert np.array_equal(g(z, log_nu), g.reference(z, log_nu))
    grid_z, grid_nu = z[:600].reshape(20, 30), log_nu[:30][None, :]  # broadcast shapes
    assert np.array_equal(g(grid_z, grid_nu), g.reference(grid_z, grid_nu))
    assert np.array_equal(g(grid_z[:1], log_nu[:600].reshape(20, 30)), g.reference(grid_z[:1], log_nu[:600].reshape(20, 30)))


def test_texture_sample_equals_the_plain_lookup():
    import math

    from raysim.sensors.radar_texture import SeaTexture

    tex = SeaTexture(5, 4, 60.0, tile_cells=256)
    rng = np.random.default_rng(4)
    east = rng.uniform(-3000, 3000, (64, 100)).astype(np.float32)
    north = rng.uniform(-3000, 3000, (64, 100)).astype(np.float32)
    for time_s in (0.0, 3.7, 11.2):
        u = time_s / tex.key_s
        k = int(math.floor(u))
        shift = tex.drift_mps * time_s * tex.down_wind
        i = np.floor((east - shift[0]) * (1.0 / tex.cell_m)).astype(np.int64) & (tex.n - 1)
        j = np.floor((north - shift[1]) * (1.0 / tex.cell_m)).astype(np.int64) & (tex.n - 1)
        a, b = tex._key(k).take(i * tex.n + j), tex._key(k + 1).take(i * tex.n + j)
        ca, cb = math.cos(0.5 * math.pi * (u - k)), math.sin(0.5 * math.pi * (u - k))
        expected = (ca * a + cb * b).astype(np.float32, copy=False)
        got = tex.sample(east, north, time_s)
        assert got.dtype == np.float32 and np.array_equal(got, expected)


def _plain_mean_rows(c, rot, azimuth_deg, antenna_h_m, h_max_m):
    """SeaClutter.mean_rows as first written (new arrays at each step)."""
    import math

    from raysim.sensors import radar_clutter as rc
    from raysim.sensors import radar_physics as phys

    h_rows = antenna_h_m[:: c.sub]
    h_mid = float(np.mean(antenna_h_m))
    table = c.mean_db_table(np.array([h_mid - rc.CLUTTER_HEIGHT_STEP_M, h_mid + rc.CLUTTER_HEIGHT_STEP_M]))
    slope = ((table[1] - table[0]) / (2.0 * rc.CLUTTER_HEIGHT_STEP_M)).astype(np.float32)
    dh = (h_rows - h_mid).astype(np.float32)
    mean_db = (table.mean(axis=0).astype(np.float32))[None, :] + dh[:, None] * slope[None, :]
    psi, psi_c = c.grazing_deg(h_mid)
    psi_r = np.radians(psi_c).astype(np.float32)
    bh, sin_tilt, z_up = c._boresight(rot, azimuth_deg)
    sin_el = np.cos(psi_r)[None, :] * sin_tilt[:, None] - np.sin(psi_r)[None, :] * z_up[:, None]
    steep = int(np.count_nonzero(psi_c > rc.STEEP_GRAZING_DEG))
    el_sq = sin_el * sin_el
    el_sq[:, :steep] = np.arcsin(np.clip(sin_el[:, :steep], -1.0, 1.0)) ** 2
    mean_db += np.float32(2.0 * phys.one_way_gain_db(math.degrees(1.0), c.p.beam_el_deg)) * el_sq
    cos_up = (bh @ c.wind_from_en).astype(np.float32)
    gain_db, mean_gain_db = phys.git_wind_direction_db(psi_c, c.p.f_ghz)
    mean_db += gain_db.astype(np.float32)[None, :] * cos_up[:, None] - mean_gain_db.astype(np.float32)[None, :]
    mean_db[:, c.range_m <= h_max_m] = -np.inf
    np.minimum(mean_db, np.float32(rc.MAX_CLUTTER_DB), out=mean_db)
    mean_db *= np.float32(math.log(10.0) / 10.0)
    return np.exp(mean_db, out=mean_db), bh, cos_up, psi_c


def _plain_texture_rows(c, pos, bh, cos_up, psi_c_deg, time_s):
    """SeaClutter.texture_rows as first written (cells spoke by spoke, then transposed)."""
    from scipy.ndimage import uniform_filter1d

    from raysim.sensors import radar_clutter as rc

    rng32 = c.range_m[None, :]
    east = pos[:, 0, None].astype(np.float32) + bh[:, 0, None].astype(np.float32) * rng32
    north = pos[:, 1, None].astype(np.float32) + bh[:, 1, None].astype(np.float32) * rng32
    z = c.texture_field.sample(east, north, time_s)
    width = max(1, int(round(c.beam_spokes / c.sub)))
    zt = np.ascontiguousarray(z.T)
    zt = uniform_filter1d(uniform_filter1d(zt, width, axis=1, mode="wrap"), width, axis=1, mode="wrap")
    std = np.maximum(uniform_filter1d(zt.std(axis=1), rc.TEXTURE_STD_WINDOW_BINS, mode="nearest"), 1e-6)
    z = np.ascontiguousarray((zt / std[:, None]).T)
    texture = c.gamma.reference(z, c.ward_log_nu(psi_c_deg, cos_up))
    return np.maximum(texture, np.float32(rc.TEXTURE_FLOOR), out=texture)


def test_sea_clutter_mean_texture_and_speckle_equal_the_plain_forms():
    c = _sea_clutter()
    assert c.sub > 1
    rng = np.random.default_rng(5)
    rot, pos, azimuth, height = _spoke_geometry(c, rng)
    rows = c.rows
    got = c.mean_rows(rot[rows], azimuth[rows], height, float(height.max()))
    expected = _plain_mean_rows(c, rot[rows], azimuth[rows], height, float(height.max()))
    for a, b in zip(got, expected):
        assert np.array_equal(a, b)
    mean, bh, cos_up, psi_c = got
    texture = c.texture_rows(pos[rows], bh, cos_up, psi_c, 7.5)
    assert np.array_equal(texture, _plain_texture_rows(c, pos[rows], bh, cos_up, psi_c, 7.5))
    # the clutter: each formed spoke's mean x texture repeated over its sub spokes, times the speckle
    t = np.full(c.spokes, 7.5)
    speckle = rng.standard_exponential((c.spokes, c.samples), dtype=np.float32)
    clutter, tex = c.render(0, t, rot, pos, azimuth, azimuth, height, None, speckle)
    unit, _ = c.render(0, t, rot, pos, azimuth, azimuth, height, None, np.ones_like(speckle))
    assert np.array_equal(unit, np.repeat((mean * texture).astype(np.float32), c.sub, axis=0))
    assert np.array_equal(clutter, unit * speckle)


# ------------------------------------------------------------------ receiver: halves on two threads

@pytest.mark.parametrize("with_targets, with_rain, with_interference", [(True, False, False), (False, True, True),
                                                                        (True, True, False), (True, False, True)])
def test_video_in_halves_equals_the_whole_revolution_form(radar, with_targets, with_rain, with_interference):
    from raysim.sensors.radar import _Echoes

    rng = np.random.default_rng(9)
    shape = (SPOKES, SAMPLES)
    clutter = rng.standard_exponential(shape, dtype=np.float32) * np.float32(30.0)
    targets = rng.standard_exponential(shape, dtype=np.float32) ** 4 if with_targets else None
    first_hit = np.where(rng.random(SPOKES) < 0.3, rng.uniform(50.0, 500.0, SPOKES), np.inf)
    rain_loss = rng.uniform(0.5, 1.0, (1, SAMPLES)).astype(np.float32) if with_rain else None
    rain_clutter = rng.standard_exponential(shape, dtype=np.float32) if with_rain else None
    noise = rng.standard_exponential(shape, dtype=np.float32)
    pulses = (rng.random(shape) < 1e-3).astype(np.float32) * np.float32(1e5)

    def interference(total):
        total += pulses

    # the whole-revolution form: shadow, sum, rain, interference, then the receiver on all spokes at once
    plain_clutter = clutter.copy()
    radar.sea_clutter.shadow(plain_clutter, first_hit)
    total = plain_clutter + targets if targets is not None else plain_clutter.copy()
    if with_rain:
        total += rain_clutter
        total *= rain_loss
    if with_interference:
        interference(total)
    levels = radar._receive(total, noise.copy())

    echoes = _Echoes(clutter, targets, first_hit, rain_loss, rain_clutter)
    p_db, got = radar._video(echoes, noise, interference if with_interference else None)
    assert np.array_equal(clutter, plain_clutter)  # the shadow, in place
    assert np.array_equal(p_db, total) and np.array_equal(got, levels)
    assert 0 < np.count_nonzero(levels) < levels.size


def test_relief_of_a_stationary_object_from_its_kept_pose_equals_a_fresh_pose(radar):
    import math

    from raysim.motion import Stationary

    motion = Stationary([120.0, -40.0, 0.5], 0.7)
    radar.targets.motion[99] = motion
    rng = np.random.default_rng(12)
    point = rng.uniform(-50.0, 50.0, (300, 3)) + motion.position_m
    oid = np.full(300, 99)
    now = motion.poses(np.zeros(1))
    body = np.einsum("nji,nj->ni", np.broadcast_to(now.rotation(), (300, 3, 3)), point - now.position_m)
    expected = radar_targets.RELIEF_PHASE_SCALE * 2.0 * math.pi * np.sum(
        np.cos(body @ radar.targets.relief_k.T + radar.targets.relief_phase + 1.7 * 99.0), axis=1)
    for _ in range(2):  # the first forms the pose, the second reads it back
        velocity, relief = radar.targets._object_terms(oid, np.full(300, 3.0), point)
        assert np.array_equal(relief, expected) and not velocity.any()
    del radar.targets.motion[99]

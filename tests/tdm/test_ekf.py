"""The thesis's model as an EKF, against analytic cases."""

import numpy as np
import pytest

from tdm import ekf


def test_straight_line_motion_matches_course_and_speed():
    x = np.array([0.0, 0.0, np.radians(90.0), 5.0, 0.0, 10.0])  # due east at 5 m/s
    out = ekf.predict_mean(x, 10.0)
    assert out[ekf.E] == pytest.approx(50.0)
    assert out[ekf.N] == pytest.approx(0.0, abs=1e-9)


def test_constant_turn_stays_on_its_circle():
    r = np.radians(3.0)  # rad/s
    u = 5.0
    x = np.array([0.0, 0.0, 0.0, u, r, 0.0])
    radius = u / r
    for _ in range(600):  # 60 s in 0.1 s steps: 180 deg of turn
        x, _ = ekf.transition(x, 0.1)
    centre = np.array([radius, 0.0])  # turning to starboard from north: centre to the east
    assert np.hypot(*(x[:2] - centre)) == pytest.approx(radius, rel=1e-3)
    assert np.degrees(ekf.wrap_pi(x[ekf.PSI])) == pytest.approx(-180.0, abs=1e-6) or \
        np.degrees(x[ekf.PSI]) == pytest.approx(180.0, abs=1e-6)


def test_jacobian_matches_finite_differences():
    x = np.array([3.0, -2.0, 0.7, 4.0, 0.02, 30.0])
    _, f = ekf.transition(x, 2.0)
    num = np.zeros((6, 6))
    for j in range(6):
        dx = np.zeros(6)
        dx[j] = 1e-6
        num[:, j] = (ekf.transition(x + dx, 2.0)[0] - ekf.transition(x - dx, 2.0)[0]) / 2e-6
    np.testing.assert_allclose(f, num, atol=1e-6)


def test_joseph_update_equals_the_optimal_gain_form():
    rng = np.random.default_rng(1)
    a = rng.normal(size=(6, 6))
    p = a @ a.T + np.eye(6)
    x = rng.normal(size=6)
    h = ekf.H_POSITION_SIZE
    r = np.diag([2.0, 3.0, 5.0])
    z = rng.normal(size=3)
    x1, p1, nis = ekf.update(x, p, z, h, r)
    s = h @ p @ h.T + r
    k = p @ h.T @ np.linalg.inv(s)
    np.testing.assert_allclose(p1, (np.eye(6) - k @ h) @ p, atol=1e-9)
    assert nis == pytest.approx(float((z - h @ x) @ np.linalg.solve(s, z - h @ x)))


def test_angle_residual_is_wrapped():
    x = np.array([0.0, 0.0, np.radians(179.0), 5.0, 0.0, 0.0])
    p = np.diag([1.0, 1.0, 0.1, 1.0, 1e-4, 1.0])
    h = ekf.h_rows(ekf.PSI)
    x1, _, _ = ekf.update(x, p, np.array([np.radians(-179.0)]), h, np.array([[1e-4]]), angle_rows=(0,))
    # the measurement is 2 deg away across the wrap, not 358 deg
    assert abs(np.degrees(ekf.wrap_pi(x1[ekf.PSI] - np.radians(-179.5)))) < 1.0


def test_filter_is_consistent_on_its_own_model():
    """NEES of position-only tracking of a simulated model target averages the state dimension."""
    rng = np.random.default_rng(7)
    q = ekf.ProcessNoise(position_m2_per_s=0.0, course_rad2_per_s=0.0, speed_m2_per_s3=0.01,
                         turn_rate_rad2_per_s3=1e-7, cross_section_m4_per_s=0.1)
    dt, n = 1.0, 300
    nees = []
    for run in range(20):
        truth = np.array([0.0, 0.0, 0.3, 5.0, 0.0, 100.0])
        x = truth + rng.normal(size=6) * [3, 3, 0.05, 0.3, 0.001, 5]
        p = np.diag([9.0, 9.0, 0.05**2, 0.09, 1e-6, 25.0])
        r = np.diag([4.0, 4.0, 4.0])
        for k in range(n):
            truth, _ = ekf.transition(truth, dt)
            truth[ekf.U] += rng.normal() * np.sqrt(q.speed_m2_per_s3 * dt)
            truth[ekf.R] += rng.normal() * np.sqrt(q.turn_rate_rad2_per_s3 * dt)
            x, p = ekf.predict(x, p, dt, q)
            z = ekf.H_POSITION_SIZE @ truth + rng.normal(size=3) * 2.0
            x, p, _ = ekf.update(x, p, z, ekf.H_POSITION_SIZE, r)
            if k > 50:
                e = x[:2] - truth[:2]
                nees.append(e @ np.linalg.solve(p[:2, :2], e))
    assert 1.6 < np.mean(nees) < 2.6  # ideal 2 (2-D position)


def _van_loan(a: np.ndarray, qc: np.ndarray, dt: float) -> np.ndarray:
    """Van Loan (1978): expm([[-A, Qc], [0, A^T]] dt) = [[., F^-1 Qd], [0, F^T]]."""
    from scipy.linalg import expm

    n = a.shape[0]
    m = np.zeros((2 * n, 2 * n))
    m[:n, :n], m[:n, n:], m[n:, n:] = -a, qc, a.T
    e = expm(m * dt)
    f = e[n:, n:].T
    return f @ e[:n, n:]


@pytest.mark.parametrize("dt", [0.1, 2.5, 10.0])
def test_process_noise_is_the_van_loan_discretisation(dt):
    q = ekf.ProcessNoise()
    x = np.array([10.0, -5.0, np.radians(40.0), 6.0, np.radians(0.5), 300.0])
    expected = _van_loan(ekf.continuous_dynamics(x), ekf.noise_density(q), dt)
    np.testing.assert_allclose(ekf.process_covariance(x, dt, q), expected, rtol=1e-9, atol=1e-12)


def test_speed_noise_grows_the_along_track_position_over_an_ais_gap():
    """Only speed noise, due north at 5 m/s: 10 s grows the north variance by q dt^3 / 3 (6.7 m^2)."""
    q = ekf.ProcessNoise(position_m2_per_s=0.0, course_rad2_per_s=0.0, speed_m2_per_s3=0.02,
                         turn_rate_rad2_per_s3=0.0, cross_section_m4_per_s=0.0)
    x = np.array([0.0, 0.0, 0.0, 5.0, 0.0, 0.0])
    qd = ekf.process_covariance(x, 10.0, q)
    assert qd[ekf.N, ekf.N] == pytest.approx(0.02 * 10.0**3 / 3.0)  # 6.67 m^2, not the 0 of a per-state Q
    assert qd[ekf.E, ekf.E] == pytest.approx(0.0, abs=1e-12)
    assert qd[ekf.N, ekf.U] == pytest.approx(0.02 * 10.0**2 / 2.0)
    # a turn-rate noise grows the cross-track one as u^2 q dt^5 / 20
    q_turn = ekf.ProcessNoise(position_m2_per_s=0.0, course_rad2_per_s=0.0, speed_m2_per_s3=0.0,
                              turn_rate_rad2_per_s3=1e-4, cross_section_m4_per_s=0.0)
    assert ekf.process_covariance(x, 10.0, q_turn)[ekf.E, ekf.E] == pytest.approx(25.0 * 1e-4 * 1e5 / 20.0)


def _random_states(n: int, seed: int = 5) -> tuple[np.ndarray, np.ndarray]:
    """n states (n, 6) and intervals (n,) s as the trackers meet them, with the edge cases (speed and course
    exactly 0, negative speeds and intervals, wrapped courses) among them."""
    rng = np.random.default_rng(seed)
    x = np.column_stack([rng.normal(0, 500, n), rng.normal(0, 500, n), rng.uniform(-4, 4, n), rng.normal(0, 6, n),
                         rng.normal(0, 0.03, n), rng.uniform(0, 500, n)])
    x[::7, ekf.U] = 0.0
    x[::5, ekf.PSI] = 0.0
    x[::11, ekf.R] = 0.0
    dt = rng.choice([-1.0, 1.0], n) * rng.exponential(2.0, n) * rng.choice([1e-3, 1.0, 20.0], n)
    return x, dt


def test_scalar_fast_paths_are_bit_identical_to_the_matrix_forms():
    """transition, process_covariance, predict_mean and velocity_en of one state on Python floats give the very
    bytes of the numpy matrix forms they replace (and would not if a rounding or a summation order changed)."""
    q = ekf.ProcessNoise()
    x, dt = _random_states(3000)
    for xi, dti in zip(x, dt):
        for d in (float(dti), np.float64(dti)):
            out, f = ekf.transition(xi, d)
            ref_out, ref_f = ekf._transition_array(xi, d)
            assert out.tobytes() == ref_out.tobytes() and f.tobytes() == ref_f.tobytes()
            assert ekf.process_covariance(xi, d, q).tobytes() == ekf._process_covariance_array(xi, d, q).tobytes()
            assert ekf.predict_mean(xi, d).tobytes() == ekf.predict_mean(xi[None], np.array([d]))[0].tobytes()
        assert ekf.velocity_en(xi).tobytes() == ekf.velocity_en(xi[None])[0].tobytes()


def test_non_finite_states_take_the_matrix_forms():
    x = np.array([1.0, 2.0, np.nan, 3.0, 0.0, 4.0])
    q = ekf.ProcessNoise()
    np.testing.assert_array_equal(ekf.process_covariance(x, 2.0, q), ekf._process_covariance_array(x, 2.0, q))
    np.testing.assert_array_equal(ekf.transition(x, 2.0)[1], ekf._transition_array(x, 2.0)[1])
    assert np.isnan(ekf.predict_mean(x, 2.0)[ekf.PSI])


def test_one_angle_wraps_as_the_array_form():
    angles = np.concatenate([np.random.default_rng(6).normal(0, 30, 20000), [np.pi, -np.pi, 0.0, -0.0, 3 * np.pi]])
    for a in angles:
        assert ekf.wrap_pi(float(a)).tobytes() == ekf.wrap_pi(np.array([a]))[0].tobytes()
        assert ekf.wrap_pi(a).tobytes() == ekf.wrap_pi(np.array([a]))[0].tobytes()
    assert np.isnan(ekf.wrap_pi(float("nan")))


def test_many_states_are_predicted_bit_for_bit_as_one_by_one():
    """predict_many gives the very bytes of predict for each state (batched BLAS products, elementwise numpy on the
    scalar path's operations), with zero intervals and a non-finite state among them."""
    q = ekf.ProcessNoise()
    x, dt = _random_states(2000, seed=12)
    rng = np.random.default_rng(13)
    m = rng.normal(size=(len(x), 6, 6))
    p = m @ m.transpose(0, 2, 1) + np.eye(6)
    dts = dt.tolist()
    dts[3] = dts[10] = 0.0
    x[17, ekf.U] = np.nan
    for lo, hi in ((0, 1), (0, 2), (0, 37), (37, 2000)):
        xs, ps = ekf.predict_many(x[lo:hi], p[lo:hi], dts[lo:hi], q)
        for k in range(lo, hi):
            x1, p1 = ekf.predict(x[k], p[k], dts[k], q)
            assert xs[k - lo].tobytes() == x1.tobytes() and ps[k - lo].tobytes() == p1.tobytes(), k

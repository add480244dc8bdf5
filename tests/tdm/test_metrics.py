"""OSPA, GOSPA and the assignment against analytic cases and brute force over permutations."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from tdm.metrics import assign, gospa, ospa

C = 50.0


def _brute_ospa(X, Y, c, p):
    """OSPA straight from Schuhmacher's definition: min over all permutations."""
    X, Y = np.asarray(X, float).reshape(-1, 2), np.asarray(Y, float).reshape(-1, 2)
    if len(X) > len(Y):
        X, Y = Y, X
    m, n = len(X), len(Y)
    if n == 0:
        return 0.0
    best = min(sum(min(c, np.linalg.norm(X[i] - Y[j])) ** p for i, j in enumerate(perm))
               for perm in itertools.permutations(range(n), m))
    return ((best + c ** p * (n - m)) / n) ** (1 / p)


def _brute_gospa(X, Y, c, p, alpha):
    """GOSPA from Rahmathullah's definition (min over permutations, c^p/alpha per cardinality error)."""
    X, Y = np.asarray(X, float).reshape(-1, 2), np.asarray(Y, float).reshape(-1, 2)
    if len(X) > len(Y):
        X, Y = Y, X
    m, n = len(X), len(Y)
    best = min((sum(min(c, np.linalg.norm(X[i] - Y[j])) ** p for i, j in enumerate(perm))
                for perm in itertools.permutations(range(n), m)), default=0.0)
    return (best + c ** p / alpha * (n - m)) ** (1 / p)


def test_identical_sets_score_zero():
    X = np.array([[0.0, 0.0], [100.0, 5.0], [-30.0, 40.0]])
    assert ospa(X, X, C, 2) == 0.0
    g = gospa(X, X[::-1], C, 2)
    assert g["total"] == 0.0 and g["missed"] == 0 and g["false"] == 0 and g["assigned"] == 3
    rows, cols = assign(X, X[::-1], C)
    assert sorted(zip(rows.tolist(), cols.tolist())) == [(0, 2), (1, 1), (2, 0)]


def test_empty_sets():
    X = np.array([[0.0, 0.0], [10.0, 0.0]])
    assert ospa([], [], C, 2) == 0.0
    assert ospa(X, [], C, 2) == pytest.approx(C)
    assert ospa([], X, C, 1) == pytest.approx(C)
    g = gospa(X, np.zeros((0, 2)), C, 2)
    assert g["total"] == pytest.approx(math.sqrt(2 * C ** 2 / 2)) and g["missed"] == 2 and g["false"] == 0
    assert gospa([], [], C, 2)["total"] == 0.0
    rows, cols = assign(X, [], C)
    assert rows.size == 0 and cols.size == 0


@pytest.mark.parametrize("p", [1.0, 2.0, 3.0])
def test_one_missed_target_gospa_is_half_cutoff_penalty(p):
    X = np.array([[0.0, 0.0], [200.0, 0.0]])
    Y = np.array([[0.0, 0.0]])
    g = gospa(X, Y, C, p)
    assert g["total"] == pytest.approx((C ** p / 2) ** (1 / p))
    assert (g["missed"], g["false"], g["assigned"]) == (1, 0, 1)
    # a false target costs the same as a missed one
    g2 = gospa(Y, X, C, p)
    assert g2["total"] == pytest.approx(g["total"]) and (g2["missed"], g2["false"]) == (0, 1)


def test_ospa_with_different_cardinalities():
    X = np.array([[0.0, 0.0], [100.0, 0.0], [0.0, 300.0]])
    Y = np.array([[3.0, 0.0]])
    # n = 3, m = 1: ((1/3)(3^2 + 2 c^2))^(1/2)
    assert ospa(X, Y, C, 2) == pytest.approx(math.sqrt((9 + 2 * C ** 2) / 3))
    assert ospa(Y, X, C, 2) == pytest.approx(ospa(X, Y, C, 2))
    # p = 1: (3 + 2 c) / 3
    assert ospa(X, Y, C, 1) == pytest.approx((3 + 2 * C) / 3)
    g = gospa(X, Y, C, 2)
    assert g["total"] == pytest.approx(math.sqrt(9 + C ** 2 / 2 * 2))
    assert g["localisation"] == pytest.approx(3.0)


def test_cutoff():
    X = np.array([[0.0, 0.0]])
    far, near = np.array([[60.0, 0.0]]), np.array([[0.0, 49.0]])
    assert ospa(X, far, C, 2) == pytest.approx(C)
    g = gospa(X, far, C, 2)
    assert g["total"] == pytest.approx(C) and (g["missed"], g["false"], g["assigned"]) == (1, 1, 0)
    assert assign(X, far, C)[0].size == 0
    assert ospa(X, near, C, 2) == pytest.approx(49.0)
    assert gospa(X, near, C, 2)["total"] == pytest.approx(49.0)
    rows, cols = assign(X, near, C)
    assert rows.tolist() == [0] and cols.tolist() == [0]
    # a smaller cut-off drops the pair
    assert assign(X, near, 40.0)[0].size == 0
    assert ospa(X, near, 40.0, 2) == pytest.approx(40.0)


def test_assignment_is_optimal_not_greedy():
    # greedy on the closest pair (b-u, 1 m) would leave a-v at 7.5 m: 57.25 m^2;
    # the optimum pairs a-u (3 m) and b-v (3.5 m): 21.25 m^2
    X = np.array([[0.0, 0.0], [4.0, 0.0]])
    Y = np.array([[3.0, 0.0], [7.5, 0.0]])
    rows, cols = assign(X, Y, C)
    assert rows.tolist() == [0, 1] and cols.tolist() == [0, 1]
    assert gospa(X, Y, C, 2)["total"] == pytest.approx(math.sqrt(21.25))
    assert ospa(X, Y, C, 2) == pytest.approx(math.sqrt(21.25 / 2))


def test_against_brute_force_definitions():
    rng = np.random.default_rng(3)
    for _ in range(60):
        n, m = rng.integers(0, 5, size=2)
        X, Y = rng.uniform(0, 120, (n, 2)), rng.uniform(0, 120, (m, 2))
        p = float(rng.choice([1.0, 2.0, 3.0]))
        assert ospa(X, Y, C, p) == pytest.approx(_brute_ospa(X, Y, C, p), abs=1e-9)
        for alpha in (2.0, 1.0):
            assert gospa(X, Y, C, p, alpha)["total"] == pytest.approx(_brute_gospa(X, Y, C, p, alpha), abs=1e-9)
        g = gospa(X, Y, C, p)
        assert g["total"] ** p == pytest.approx(g["localisation"] ** p + C ** p / 2 * (g["missed"] + g["false"]))
        assert g["missed"] == n - g["assigned"] and g["false"] == m - g["assigned"]
        rows, cols = assign(X, Y, C, p)
        assert rows.size == g["assigned"]
        assert np.all(np.linalg.norm(X[rows] - Y[cols], axis=1) < C)


def test_bad_arguments():
    X = np.zeros((2, 2))
    with pytest.raises(ValueError):
        ospa(X, X, 0.0, 2)
    with pytest.raises(ValueError):
        ospa(X, X, C, 0.5)
    with pytest.raises(ValueError):
        gospa(X, X, C, 2, alpha=3)
    with pytest.raises(ValueError):
        assign(np.zeros((2, 3)), X, C)

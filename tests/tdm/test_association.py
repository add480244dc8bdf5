"""tdm.association: the chi-square gate, Mahalanobis distances and GNN on hand-made cost matrices."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tdm.association import FORBIDDEN, chi2_gate, gnn, mahalanobis2


def test_chi2_gate_for_two_degrees_of_freedom_is_minus_two_log_of_the_miss():
    # chi-square with 2 dof: P(X <= g) = 1 - exp(-g / 2)
    assert chi2_gate(0.99, 2) == pytest.approx(-2.0 * math.log(0.01))
    assert chi2_gate(0.95, 2) == pytest.approx(-2.0 * math.log(0.05))


def test_mahalanobis2_equals_the_quadratic_form():
    rng = np.random.default_rng(0)
    a = rng.normal(size=(20, 2, 2))
    cov = a @ a.transpose(0, 2, 1) + 0.1 * np.eye(2)
    r = rng.normal(size=(20, 2))
    expected = np.einsum("ni,ni->n", r, np.linalg.solve(cov, r[:, :, None])[:, :, 0])
    assert mahalanobis2(r, cov) == pytest.approx(expected, rel=1e-10)
    # broadcast: one covariance for many residuals
    assert mahalanobis2(np.array([[3.0, 4.0]]), np.diag([9.0, 16.0])) == pytest.approx([2.0])


def test_gnn_takes_the_global_optimum_not_the_greedy_choice():
    # greedy would give track 0 measurement 0 (cost 1) and leave track 1 with 10: total 11;
    # the optimum is 0 -> 1 (2) and 1 -> 0 (2): total 4
    cost = np.array([[1.0, 2.0],
                     [2.0, 10.0]])
    assert sorted(gnn(cost, gate=20.0)) == [(0, 1), (1, 0)]


def test_gnn_never_pairs_outside_the_gate():
    cost = np.array([[1.0, 50.0],
                     [50.0, 60.0]])
    assert gnn(cost, gate=9.21) == [(0, 0)]
    assert gnn(np.full((2, 3), 100.0), gate=9.21) == []


def test_gnn_on_rectangular_and_empty_matrices():
    cost = np.array([[5.0, 0.5, 3.0]])  # one track, three measurements
    assert gnn(cost, gate=9.0) == [(0, 1)]
    assert gnn(cost.T, gate=9.0) == [(1, 0)]
    assert gnn(np.zeros((0, 4)), gate=9.0) == []
    assert gnn(np.zeros((3, 0)), gate=9.0) == []


def test_the_gate_is_inclusive_and_forbidden_is_far_above_any_gate():
    assert gnn(np.array([[9.0]]), gate=9.0) == [(0, 0)]
    assert FORBIDDEN > chi2_gate(0.9999, 3) * 1e3

"""tdm.association: the chi-square gate, Mahalanobis distances and GNN on hand-made cost matrices."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tdm.association import FORBIDDEN, chi2_gate, gnn, gnn_first, mahalanobis2


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


def test_a_miss_cost_keeps_a_row_on_its_nearest_measurement():
    # row 0 is at 0.0 from column 0 and 9.2 from column 1; row 1 gates with column 0 only (9.7). Without a miss
    # cost the assignment pairs both rows (total 18.9); with a miss cost of the gate (13.8), row 0 keeping column 0
    # and row 1 missing (0 + 13.8) is cheaper
    cost = np.array([[0.0, 9.2],
                     [9.7, 50.0]])
    assert sorted(gnn(cost, gate=13.8)) == [(0, 1), (1, 0)]
    assert gnn(cost, gate=13.8, miss_cost=13.8) == [(0, 0)]
    # where moving a row saves more than a miss costs, both are paired as before
    assert sorted(gnn(np.array([[1.0, 2.0], [2.0, 10.0]]), gate=20.0, miss_cost=20.0)) == [(0, 1), (1, 0)]
    assert gnn(np.zeros((0, 2)), gate=9.0, miss_cost=9.0) == []


def test_first_rows_choose_before_the_others():
    # row 1 (a confirmed track) is nearest column 0; row 0 (tentative) gates with column 0 only. In one round the
    # tentative row takes column 0 and pushes the confirmed row onto column 1, even with a miss cost (1.8 + 4.7 <
    # 0 + 13.8); the confirmed row choosing first keeps column 0
    cost = np.array([[4.7, 50.0],
                     [0.0, 1.8]])
    assert sorted(gnn(cost, gate=13.8, miss_cost=13.8)) == [(0, 0), (1, 1)]
    assert gnn_first(cost, gate=13.8, first=np.array([False, True]), miss_cost=13.8) == [(1, 0)]
    # the others choose among the columns left, their indices those of the whole matrix
    cost = np.array([[0.5, 0.2, 50.0],
                     [0.1, 9.0, 3.0]])
    assert gnn_first(cost, gate=13.8, first=np.array([False, True])) == [(0, 1), (1, 0)]
    assert gnn_first(cost, gate=13.8, first=np.array([False, False])) == gnn(cost, gate=13.8)
    assert gnn_first(np.zeros((2, 0)), gate=1.0, first=np.array([True, False])) == []

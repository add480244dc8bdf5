"""Data association: Mahalanobis gating and global nearest neighbour (docs/reference.md section 5).

GNN is the optimal one-to-one assignment (``scipy.optimize.linear_sum_assignment``) of
measurements to tracks on the squared Mahalanobis distance, with pairs outside the gate
forbidden (Stone Soup's ``GNNWith2DAssignment`` over a ``DistanceHypothesiser``).
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import linear_sum_assignment
from scipy.stats import chi2

#: Cost given to pairs outside the gate (never chosen when a gated pair exists for both).
FORBIDDEN = 1e9


def chi2_gate(probability: float, dof: int) -> float:
    """Squared-Mahalanobis gate holding ``probability`` of true measurements (chi-square, ``dof``)."""
    return float(chi2.ppf(probability, dof))


def mahalanobis2(residual: np.ndarray, covariance: np.ndarray) -> np.ndarray:
    """Squared Mahalanobis distances.

    Parameters
    ----------
    residual : (..., 2) float
    covariance : (..., 2, 2) float
        Innovation covariances, broadcast against ``residual``.

    Returns
    -------
    (...,) float
    """
    a, b, d = covariance[..., 0, 0], covariance[..., 0, 1], covariance[..., 1, 1]
    det = a * d - b * b
    x, y = residual[..., 0], residual[..., 1]
    return (d * x * x - 2 * b * x * y + a * y * y) / det


def gnn(cost: np.ndarray, gate: float, miss_cost: float | None = None) -> list[tuple[int, int]]:
    """Global-nearest-neighbour pairs (row, column) with ``cost <= gate``.

    Parameters
    ----------
    cost : (T, D) float
        Squared Mahalanobis distances of T tracks to D measurements.
    gate : float
        Largest admissible cost.
    miss_cost : float, optional
        What leaving a row without a measurement costs (Stone Soup's ``DistanceHypothesiser`` ``missed_distance``):
        the assignment minimises the costs of its pairs plus ``miss_cost`` for each row left out, so a row is moved
        from its nearest measurement to a further one only where that saves more than it costs. None: the
        assignment pairs as many rows as the gate allows, then minimises the cost, and a row that gates with one
        measurement only takes it from a row that had a nearer choice.
    """
    rows, cols = _assigned(cost, gate, miss_cost)
    return list(zip(rows.tolist(), cols.tolist()))


def _assigned(cost: np.ndarray, gate: float, miss_cost: float | None) -> tuple[np.ndarray, np.ndarray]:
    """:func:`gnn`'s pairs as two (P,) int arrays, rows and columns, by row."""
    admissible = cost <= gate
    if miss_cost is not None:
        admissible &= cost < miss_cost
    if not admissible.any():
        return np.zeros(0, dtype=np.intp), np.zeros(0, dtype=np.intp)
    if miss_cost is None:
        masked = np.where(admissible, cost, FORBIDDEN)
    else:
        # the costs less the miss cost (so a row left out adds nothing), a pair that saves nothing set to 0: the same
        # optimum as a miss column per row, on a (T, D) matrix (a 0 pair is one left out)
        masked = np.where(admissible, cost - miss_cost, 0.0)
    rows, cols = linear_sum_assignment(masked)
    keep = admissible[rows, cols]
    return rows[keep], cols[keep]


def gnn_first(cost: np.ndarray, gate: float, first: np.ndarray, miss_cost: float | None = None
              ) -> list[tuple[int, int]]:
    """GNN in two rounds: the ``first`` rows (a confirmed track's) choose among all measurements, the other rows
    among the measurements left.

    One optimal assignment over all rows maximises the number of gated pairs before it minimises their cost, so a
    tentative track that gates with one plot only can take it from the confirmed track it belongs to and push that
    track onto a plot further off (harbour_approach seed 34: one-hit tracks of spots beside the anchored tanker took
    its hull's plot twice, and its confirmed track was moved 35 m, then 59 m, onto small plots beside it and turned
    into an 8 m/s track circling in place). A confirmed track's association is not bent by tracks that may be
    clutter.

    Parameters
    ----------
    cost : (T, D) float
        Squared Mahalanobis distances of T tracks to D measurements.
    gate : float
        Largest admissible cost.
    first : (T,) bool
        Rows that choose first.
    miss_cost : float, optional
        As for :func:`gnn`, in each round.

    Returns
    -------
    list of (int, int)
        (row, column) pairs, by row.
    """
    first = np.asarray(first, dtype=bool)
    rows_a, rows_b = np.flatnonzero(first), np.flatnonzero(~first)
    ia, ja = _assigned(cost[rows_a], gate, miss_cost)
    free = np.ones(cost.shape[1], dtype=bool)
    free[ja] = False
    free_cols = np.flatnonzero(free)
    ib, jb = _assigned(cost[rows_b][:, free_cols], gate, miss_cost)
    rows = np.concatenate([rows_a[ia], rows_b[ib]])
    cols = np.concatenate([ja, free_cols[jb]])
    order = np.argsort(rows, kind="stable")
    return list(zip(rows[order].tolist(), cols[order].tolist()))

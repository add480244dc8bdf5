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


def gnn(cost: np.ndarray, gate: float) -> list[tuple[int, int]]:
    """Global-nearest-neighbour pairs (row, column) with ``cost <= gate``.

    Parameters
    ----------
    cost : (T, D) float
        Squared Mahalanobis distances of T tracks to D measurements.
    gate : float
        Largest admissible cost.
    """
    if cost.size == 0:
        return []
    masked = np.where(cost <= gate, cost, FORBIDDEN)
    rows, cols = linear_sum_assignment(masked)
    keep = masked[rows, cols] < FORBIDDEN
    return list(zip(rows[keep].tolist(), cols[keep].tolist()))

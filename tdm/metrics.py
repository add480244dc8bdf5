"""Distances between finite sets of 2-D positions: OSPA, GOSPA and the assignment behind them.

Pure functions on ENU positions in metres (docs/reference.md section 5, "use position-only
distances in metres"). ``X`` is the truth set (n, 2), ``Y`` the estimate set (m, 2).

Cut-off distance ``d^(c)(x, y) = min(c, ||x - y||)``; order ``p >= 1``.

OSPA (Schuhmacher, Vo and Vo 2008, "A consistent metric for performance evaluation of
multi-object filters", IEEE TSP 56(8)); for ``n >= m`` (swap the sets otherwise)::

    d_p^(c)(X, Y) = ( (1/n) (min_pi sum_{i<=m} d^(c)(x_pi(i), y_i)^p + c^p (n - m)) )^(1/p)

with ``d = 0`` when both sets are empty and ``d = c`` when exactly one is.

GOSPA (Rahmathullah, Garcia-Fernandez and Svensson 2017, "Generalized optimal sub-pattern
assignment metric", FUSION), ``0 < alpha <= 2``, ``n >= m``::

    d_p^(c,alpha)(X, Y) = ( min_pi sum_{i<=m} d^(c)(x_pi(i), y_i)^p + (c^p / alpha) (n - m) )^(1/p)

which for ``alpha = 2`` equals the assignment form used here::

    ( sum_{(i,j) assigned} d(x_i, y_j)^p + (c^p / 2) (#missed + #false) )^(1/p)

where a pair is *assigned* when its distance is below ``c``; truths left over are missed,
estimates left over are false. The decomposition (localisation, missed, false) is defined
for ``alpha = 2`` only.

Both metrics use the same optimal assignment: ``scipy.optimize.linear_sum_assignment`` on
the cost ``d^(c)^p``. Pairs of that assignment at ``d >= c`` cost exactly what leaving both
points unassigned costs (``c^p = 2 c^p / 2``), so dropping them keeps the assignment
optimal for GOSPA; :func:`assign` returns only the pairs with ``d < c``.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import linear_sum_assignment
from scipy.spatial.distance import cdist

#: Default cut-off distance c, metres (the evaluation's default, module ``tdm.evaluate``).
DEFAULT_CUTOFF_M = 50.0
#: Default order p (docs/reference.md section 5 writes the metrics for general p; 2 is the usual choice).
DEFAULT_ORDER_P = 2.0
#: GOSPA alpha: 2 makes GOSPA split into localisation, missed and false terms (docs/reference.md section 5).
GOSPA_ALPHA = 2.0


def _points(a) -> np.ndarray:
    """A point set as a float64 (k, 2) array; an empty input gives (0, 2)."""
    arr = np.asarray(a, dtype=float)
    if arr.size == 0:
        return np.zeros((0, 2))
    if arr.ndim != 2 or arr.shape[1] != 2:
        raise ValueError(f"a point set must have shape (k, 2), not {arr.shape}")
    return arr


def _matrix(d_m) -> np.ndarray:
    """A distance matrix as a float64 (n, m) array."""
    arr = np.asarray(d_m, dtype=float)
    if arr.ndim != 2:
        raise ValueError(f"a distance matrix must be 2-D, not of shape {arr.shape}")
    return arr


def _check(c: float, p: float) -> None:
    if not c > 0:
        raise ValueError(f"cut-off c must be > 0, not {c}")
    if not p >= 1:
        raise ValueError(f"order p must be >= 1, not {p}")


def distance_matrix(X, Y) -> np.ndarray:
    """Euclidean distances between two point sets.

    Parameters
    ----------
    X : (n, 2) array_like
        Positions, metres.
    Y : (m, 2) array_like
        Positions, metres.

    Returns
    -------
    (n, m) float64
        ``||X[i] - Y[j]||``, metres.
    """
    X, Y = _points(X), _points(Y)
    if X.shape[0] == 0 or Y.shape[0] == 0:
        return np.zeros((X.shape[0], Y.shape[0]))
    return cdist(X, Y)


def _full_assignment(d_m: np.ndarray, c: float, p: float) -> tuple[np.ndarray, np.ndarray]:
    """Optimal assignment of min(n, m) pairs on the cost ``min(d, c)^p``."""
    if d_m.shape[0] == 0 or d_m.shape[1] == 0:
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    rows, cols = linear_sum_assignment(np.minimum(d_m, c) ** p)
    return rows.astype(np.int64), cols.astype(np.int64)


def assign_distances(d_m, c: float = DEFAULT_CUTOFF_M, p: float = DEFAULT_ORDER_P) -> tuple[np.ndarray, np.ndarray]:
    """Optimal assignment from a distance matrix, keeping only pairs closer than ``c``.

    Parameters
    ----------
    d_m : (n, m) array_like
        Distances between truth i and estimate j, metres.
    c : float
        Cut-off, metres; pairs at ``d >= c`` are not assigned.
    p : float
        Order of the cost ``min(d, c)^p``.

    Returns
    -------
    rows, cols : (k,) int64
        Assigned truth and estimate indices, ``k <= min(n, m)``, rows increasing.
    """
    _check(c, p)
    d_m = _matrix(d_m)
    rows, cols = _full_assignment(d_m, c, p)
    keep = d_m[rows, cols] < c
    return rows[keep], cols[keep]


def assign(X, Y, c: float = DEFAULT_CUTOFF_M, p: float = DEFAULT_ORDER_P) -> tuple[np.ndarray, np.ndarray]:
    """Optimal (GOSPA, alpha = 2) assignment of estimates ``Y`` to truths ``X`` with cut-off ``c``.

    Parameters
    ----------
    X : (n, 2) array_like
        Truth positions, metres.
    Y : (m, 2) array_like
        Estimated positions, metres.
    c : float
        Cut-off, metres: only pairs closer than ``c`` are returned.
    p : float
        Order of the cost ``min(d, c)^p``.

    Returns
    -------
    rows, cols : (k,) int64
        ``X[rows[i]]`` is assigned to ``Y[cols[i]]``.
    """
    return assign_distances(distance_matrix(X, Y), c, p)


def ospa_distances(d_m, c: float = DEFAULT_CUTOFF_M, p: float = DEFAULT_ORDER_P) -> float:
    """OSPA distance (module docstring) from an (n, m) distance matrix, metres."""
    _check(c, p)
    d_m = _matrix(d_m)
    n, m = d_m.shape
    big = max(n, m)
    if big == 0:
        return 0.0
    rows, cols = _full_assignment(d_m, c, p)
    total = float(np.sum(np.minimum(d_m[rows, cols], c) ** p)) + c ** p * abs(n - m)
    return (total / big) ** (1.0 / p)


def ospa(X, Y, c: float = DEFAULT_CUTOFF_M, p: float = DEFAULT_ORDER_P) -> float:
    """OSPA distance of Schuhmacher et al. (2008) between two position sets.

    Parameters
    ----------
    X : (n, 2) array_like
        Truth positions, metres.
    Y : (m, 2) array_like
        Estimated positions, metres.
    c : float
        Cut-off, metres (the penalty per cardinality error).
    p : float
        Order, >= 1.

    Returns
    -------
    float
        Metres, in [0, c]: 0 for identical sets (and for two empty sets), c when one set is empty.
    """
    return ospa_distances(distance_matrix(X, Y), c, p)


def gospa_distances(d_m, c: float = DEFAULT_CUTOFF_M, p: float = DEFAULT_ORDER_P,
                    alpha: float = GOSPA_ALPHA) -> dict:
    """GOSPA (module docstring) from an (n, m) distance matrix; see :func:`gospa`."""
    _check(c, p)
    if not 0 < alpha <= 2:
        raise ValueError(f"GOSPA alpha must be in (0, 2], not {alpha}")
    d_m = _matrix(d_m)
    n, m = d_m.shape
    rows, cols = _full_assignment(d_m, c, p)
    dist = d_m[rows, cols]
    if alpha == 2:
        close = dist < c
        loc = float(np.sum(dist[close] ** p))
        n_assigned = int(np.count_nonzero(close))
        missed, false = n - n_assigned, m - n_assigned
        total = (loc + c ** p / 2.0 * (missed + false)) ** (1.0 / p)
        return {"total": total, "localisation": loc ** (1.0 / p), "missed": missed, "false": false,
                "assigned": n_assigned}
    total = (float(np.sum(np.minimum(dist, c) ** p)) + c ** p / alpha * abs(n - m)) ** (1.0 / p)
    return {"total": total, "localisation": float("nan"), "missed": None, "false": None, "assigned": None}


def gospa(X, Y, c: float = DEFAULT_CUTOFF_M, p: float = DEFAULT_ORDER_P, alpha: float = GOSPA_ALPHA) -> dict:
    """GOSPA distance of Rahmathullah et al. (2017) and its split (alpha = 2).

    Parameters
    ----------
    X : (n, 2) array_like
        Truth positions, metres.
    Y : (m, 2) array_like
        Estimated positions, metres.
    c : float
        Cut-off, metres.
    p : float
        Order, >= 1.
    alpha : float
        In (0, 2]; the split below is defined for 2 only.

    Returns
    -------
    dict
        ``total`` (metres); ``localisation`` (metres: ``(sum of d^p over assigned pairs)^(1/p)``,
        so ``total^p = localisation^p + c^p/2 (missed + false)``); ``missed`` (truths not
        assigned), ``false`` (estimates not assigned) and ``assigned`` (pairs closer than
        ``c``) as counts. For alpha != 2 only ``total`` is defined (the rest NaN / None).
    """
    return gospa_distances(distance_matrix(X, Y), c, p, alpha)

"""Which target stands for which object over time: the CLEAR MOT correspondence, for the id switches.

Bernardin and Stiefelhagen (2008), "Evaluating multiple object tracking performance: the CLEAR MOT
metrics", EURASIP Journal on Image and Video Processing 2008:246309, section 2.1.1, the rule that
py-motmetrics (``MOTAccumulator.update``) and the MOTChallenge benchmarks follow: at each epoch, a
correspondence made before (an object's last matched target) is kept while that target is reported and
still within the cut-off of the object, whichever other target is closer; the objects and reports left
over are assigned optimally; an object whose new target is not its last one has switched ids. Without
that rule (an optimal assignment at every epoch, what the errors and GOSPA use) two targets near two
objects, each about as far from both, are handed from one object to the other whenever the noise tips the
balance, and every hand-over counts as a switch although no track changed (docs/tdm.md).
"""

from __future__ import annotations

import numpy as np

from tdm.metrics import assign_distances


def carry_forward_assignment(d_m: np.ndarray, target_id: np.ndarray, last_target_id: np.ndarray,
                             c_m: float, p: float) -> tuple[np.ndarray, np.ndarray]:
    """One epoch of the CLEAR MOT correspondence.

    Parameters
    ----------
    d_m : (n, m) float
        Distances from the n objects to the m reports at this epoch, metres (``>= c_m``: cannot match).
    target_id : (m,) int64
        Each report's target id.
    last_target_id : (n,) int64
        Each object's last matched target id (at any earlier epoch), -1 when it was never matched.
    c_m : float
        Cut-off, metres: a pair at ``d >= c_m`` is never matched, kept or new.
    p : float
        Order of the cost of the optimal assignment of what is left (:func:`tdm.metrics.assign_distances`).

    Returns
    -------
    rows, cols : (k,) int64
        Matched object and report indices, rows increasing.
    """
    n, m = d_m.shape
    if n == 0 or m == 0:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    keep = (target_id[None, :] == last_target_id[:, None]) & (last_target_id[:, None] >= 0) & (d_m < c_m)
    kept_r, kept_c = [], []
    used = np.zeros(m, dtype=bool)
    for i in np.flatnonzero(keep.any(axis=1)):  # loop over the objects that still see their target (a few)
        j = np.flatnonzero(keep[i] & ~used)
        if j.size:
            kept_r.append(i)
            kept_c.append(j[0])
            used[j[0]] = True
    free_r = np.setdiff1d(np.arange(n), np.asarray(kept_r, dtype=np.int64))
    free_c = np.flatnonzero(~used)
    new_r, new_c = assign_distances(d_m[np.ix_(free_r, free_c)], c_m, p) if free_r.size and free_c.size \
        else (np.zeros(0, np.int64), np.zeros(0, np.int64))
    rows = np.r_[np.asarray(kept_r, dtype=np.int64), free_r[new_r]]
    cols = np.r_[np.asarray(kept_c, dtype=np.int64), free_c[new_c]]
    order = np.argsort(rows, kind="stable")
    return rows[order].astype(np.int64), cols[order].astype(np.int64)


def switches(matched_target_id: np.ndarray) -> int:
    """Id switches of one object: changes of its matched target id between its consecutive matched epochs.

    Parameters
    ----------
    matched_target_id : (E,) int64
        The object's matched target id per epoch, -1 where it is not matched (gaps do not count).
    """
    tid = matched_target_id[matched_target_id >= 0]
    return int(np.count_nonzero(np.diff(tid)))

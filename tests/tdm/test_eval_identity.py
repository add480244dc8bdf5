"""tdm.eval_identity: the CLEAR MOT correspondence against analytic cases and against py-motmetrics."""

from __future__ import annotations

import numpy as np
import pytest

from tdm.eval_identity import carry_forward_assignment, switches
from tdm.metrics import assign_distances, distance_matrix

C, P = 50.0, 2.0


def _run(objects_e, reports_e, ids_e, carry=True):
    """Matched target id per (epoch, object) over a sequence; per-epoch optimal when not ``carry``."""
    n = objects_e[0].shape[0]
    last = np.full(n, -1, dtype=np.int64)
    out = np.full((len(objects_e), n), -1, dtype=np.int64)
    for e, (obj, rep, ids) in enumerate(zip(objects_e, reports_e, ids_e)):
        d = distance_matrix(obj, rep)
        r, c = carry_forward_assignment(d, ids, last, C, P) if carry else assign_distances(d, C, P)
        out[e, r] = last[r] = ids[c]
    return out


def test_two_targets_between_two_objects_are_not_handed_over():
    # objects 14 m apart (a pier and the ship moored at it); each target about 28 m from both, on the
    # perpendicular bisector, 0.5 m to one side or the other from epoch to epoch
    objects = np.array([[0.0, 0.0], [14.0, 0.0]])
    reports, ids = [], []
    for e in range(20):
        s = 0.5 if e % 2 == 0 else -0.5
        reports.append(np.array([[7.0 + s, 28.0], [7.0 - s, -28.0]]))
        ids.append(np.array([1, 2]))
    optimal = _run([objects] * 20, reports, ids, carry=False)
    kept = _run([objects] * 20, reports, ids)
    assert [switches(optimal[:, k]) for k in range(2)] == [19, 19]
    assert [switches(kept[:, k]) for k in range(2)] == [0, 0]
    assert set(kept[:, 0]) == {1} or set(kept[:, 0]) == {2}


def test_a_kept_target_beyond_the_cut_off_is_let_go():
    obj = np.array([[0.0, 0.0]])
    last = np.array([7])
    d = np.array([[C + 1.0, 3.0]])
    r, c = carry_forward_assignment(d, np.array([7, 8]), last, C, P)
    assert r.tolist() == [0] and c.tolist() == [1]
    # within the cut-off it is kept though the other is closer
    r, c = carry_forward_assignment(np.array([[C - 1.0, 3.0]]), np.array([7, 8]), last, C, P)
    assert c.tolist() == [0]
    assert obj.shape == (1, 2)


def test_two_objects_last_matched_to_one_target_do_not_share_it():
    d = np.array([[5.0, 6.0], [4.0, 30.0]])
    r, c = carry_forward_assignment(d, np.array([3, 4]), np.array([3, 3]), C, P)
    assert r.tolist() == [0, 1] and c.tolist() == [0, 1]  # object 0 keeps 3; object 1 gets what is left


def test_empty_epochs():
    r, c = carry_forward_assignment(np.zeros((0, 3)), np.array([1, 2, 3]), np.zeros(0, np.int64), C, P)
    assert r.size == 0 and c.size == 0
    assert switches(np.array([-1, 4, -1, 4, 5, -1, 4])) == 2


def test_switch_count_matches_py_motmetrics():
    mm = pytest.importorskip("motmetrics")
    rng = np.random.default_rng(22)
    n_obj, n_tgt, n_epochs = 4, 6, 300
    track = rng.uniform(0, 120, size=(n_obj, 2))
    offset = rng.normal(0, 15, size=(n_tgt, 2))
    owner = rng.integers(0, n_obj, size=n_tgt)  # each target follows one object, at its own offset
    acc = mm.MOTAccumulator(auto_id=True)
    objects_e, reports_e, ids_e = [], [], []
    for _ in range(n_epochs):
        track = track + rng.normal(0, 1.0, size=track.shape)
        present = rng.random(n_tgt) < 0.8  # targets come and go
        rep = track[owner[present]] + offset[present] + rng.normal(0, 8.0, size=(present.sum(), 2))
        ids = np.flatnonzero(present).astype(np.int64) + 100
        objects_e.append(track.copy())
        reports_e.append(rep)
        ids_e.append(ids)
        d = distance_matrix(track, rep)
        acc.update(np.arange(n_obj), ids, np.where(d < C, d ** P, np.nan))
    kept = _run(objects_e, reports_e, ids_e)
    ours = sum(switches(kept[:, k]) for k in range(n_obj))
    theirs = mm.metrics.create().compute(acc, metrics=["num_switches"])["num_switches"].iloc[0]
    optimal = _run(objects_e, reports_e, ids_e, carry=False)
    assert ours == theirs > 0
    assert sum(switches(optimal[:, k]) for k in range(n_obj)) > ours

"""The fusion against its best sensor, per object (tdm.eval_best_sensor), on analytic error sets."""

import numpy as np
import pytest

from tdm.eval_best_sensor import MIN_COMMON_EPOCHS, fusion_against_sensors, pair_errors

E = 40  # epochs


def _pairs(errors_by_object: dict[int, np.ndarray], cog_deg: float = 0.0, sog_mps: float = 0.0,
           epochs: np.ndarray | None = None) -> dict:
    """Pairs of objects matched at ``epochs`` (default all E) with the given (E', 2) position errors."""
    pe, pk, err = [], [], []
    for k, e_m in errors_by_object.items():
        ep = np.arange(E) if epochs is None else epochs
        pe.append(ep)
        pk.append(np.full(ep.size, k))
        err.append(np.broadcast_to(e_m, (ep.size, 2)))
    pe, pk, err = np.concatenate(pe), np.concatenate(pk), np.concatenate(err)
    return pair_errors(pe, pk, err, np.full(pe.size, cog_deg), np.full(pe.size, sog_mps))


def _alternating(size_m: float) -> np.ndarray:
    """(E, 2) errors of length ``size_m`` east and west in turn: no bias, scatter ``size_m``."""
    return np.stack([size_m * (-1.0) ** np.arange(E), np.zeros(E)], axis=1)


def test_fusion_better_than_both_sensors_beats_on_every_figure():
    fused = _pairs({0: _alternating(1.0)}, cog_deg=1.0, sog_mps=0.1)
    sensors = {"lidar": _pairs({0: _alternating(2.0)}, cog_deg=2.0, sog_mps=0.2),
               "radar": _pairs({0: _alternating(8.0)}, cog_deg=-9.0, sog_mps=0.5)}
    out = fusion_against_sensors(["alpha"], np.array([7]), E, fused, sensors)
    (obj,) = out["objects"]
    assert obj["id"] == 7 and obj["sensors"] == ["lidar", "radar"]
    assert obj["beats_best_on_all"] and obj["why_not"] == []
    assert obj["figures"]["position_rmse_m"] == {"best_sensor": "lidar", "sensor": pytest.approx(2.0),
                                                 "fused": pytest.approx(1.0), "common_epochs": E}
    assert obj["figures"]["cog_median_deg"]["sensor"] == pytest.approx(2.0)
    assert out["summary"]["objects_fusion_beats_best_on_all"] == 1
    assert out["summary"]["per_figure"]["sog_rmse_mps"] == {"beats": 1, "compared": 1}


def test_fusion_pulled_by_a_biased_sensor_loses_and_says_toward_which():
    # LiDAR unbiased 1 m scatter; radar 10 m east bias; the fusion 3 m east of the truth: pulled toward the radar
    fused = _pairs({0: _alternating(1.0) + [3.0, 0.0]})
    sensors = {"lidar": _pairs({0: _alternating(1.0)}), "radar": _pairs({0: _alternating(1.0) + [10.0, 0.0]})}
    (obj,) = fusion_against_sensors(["alpha"], np.array([1]), E, fused, sensors)["objects"]
    assert not obj["beats"]["position_rmse_m"] and not obj["beats"]["position_median_m"]
    assert not obj["beats_best_on_all"]
    (reason,) = obj["why_not"]
    assert reason.startswith("position: fused bias 3 m against lidar's 0 m") and "toward radar's bias (10 m)" in reason


def test_larger_scatter_is_named_when_there_is_no_bias():
    fused = _pairs({0: _alternating(3.0)})
    sensors = {"lidar": _pairs({0: _alternating(1.0)}), "ais": _pairs({0: _alternating(5.0)})}
    (obj,) = fusion_against_sensors(["alpha"], np.array([1]), E, fused, sensors)["objects"]
    assert obj["why_not"] == ["position: fused scatter 3 m against lidar's 1 m"]


def test_compared_only_on_the_epochs_both_report():
    # the fusion is poor where the LiDAR is silent (epochs 0-19) and better where it reports (20-39)
    fused_err = np.where(np.arange(E)[:, None] < 20, [20.0, 0.0], [0.5, 0.0])
    fused = _pairs({0: fused_err})
    lidar = _pairs({0: np.array([1.0, 0.0])}, epochs=np.arange(20, E))
    radar = _pairs({0: _alternating(8.0)})
    (obj,) = fusion_against_sensors(["alpha"], np.array([1]), E, fused, {"lidar": lidar, "radar": radar})["objects"]
    assert obj["figures"]["position_rmse_m"]["best_sensor"] == "lidar"
    assert obj["figures"]["position_rmse_m"]["common_epochs"] == 20
    assert obj["beats"]["position_rmse_m"]


def test_objects_seen_by_one_sensor_or_too_briefly_are_not_compared():
    fused = _pairs({0: _alternating(1.0), 1: _alternating(1.0)})
    lidar = _pairs({0: _alternating(2.0)})
    radar = pair_errors(*[np.concatenate(x) for x in (
        [np.arange(E), np.arange(MIN_COMMON_EPOCHS - 1)], [np.zeros(E, int), np.ones(MIN_COMMON_EPOCHS - 1, int)],
        [_alternating(4.0), np.zeros((MIN_COMMON_EPOCHS - 1, 2))], [np.zeros(E), np.zeros(MIN_COMMON_EPOCHS - 1)],
        [np.zeros(E), np.zeros(MIN_COMMON_EPOCHS - 1)])])
    out = fusion_against_sensors(["alpha", "bravo"], np.array([1, 2]), E, fused, {"lidar": lidar, "radar": radar})
    assert [o["name"] for o in out["objects"]] == ["alpha"]  # bravo: the radar on 9 epochs, the LiDAR never
    assert out["summary"]["objects_compared"] == 1


def test_cog_of_objects_that_do_not_move_is_not_compared():
    fused = _pairs({0: _alternating(1.0)}, cog_deg=np.nan)
    sensors = {"lidar": _pairs({0: _alternating(2.0)}, cog_deg=np.nan), "radar": _pairs({0: _alternating(3.0)})}
    (obj,) = fusion_against_sensors(["alpha"], np.array([1]), E, fused, sensors)["objects"]
    assert "cog_rmse_deg" not in obj["figures"] and "position_rmse_m" in obj["figures"]
    assert obj["beats_best_on_all"]

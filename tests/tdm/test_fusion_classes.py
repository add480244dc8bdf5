"""tdm.fusion_classes: a fused target's class from its AIS, its speed over time, its footprint and height."""

import numpy as np
import pytest

from tdm import ekf
from tdm.fusion_target import FusedTarget
from tdm.fusion_classes import VESSEL_MOVING_S, VESSEL_SIGMAS, Classifier
from tdm.fusion_config import FusionConfig


def state(speed_mps: float, area_m2: float = 10.0, speed_sigma_mps: float = 0.1):
    x = np.array([0.0, 0.0, 0.0, speed_mps, 0.0, area_m2])
    p = np.diag([1.0, 1.0, 0.01, speed_sigma_mps**2, 1e-4, 1.0])
    return x, p


def run(classifier, target, speed_mps, area_m2=10.0, sigma=0.1, height_m=float("nan"), seconds=30):
    for t in range(seconds + 1):
        classifier.classify(target, *state(speed_mps, area_m2, sigma), float(t), height_m)
    return target.descriptor


def test_a_target_with_ais_is_a_vessel_at_once():
    target = FusedTarget(1, members={"ais": 3})
    Classifier(FusionConfig()).classify(target, *state(0.0), 0.0, float("nan"))
    assert target.descriptor == "vessel"


def test_a_target_is_a_vessel_after_moving_with_confidence_for_the_set_time():
    config = FusionConfig()
    fast = config.vessel_speed_mps + VESSEL_SIGMAS * 0.1 + 0.5
    classifier, target = Classifier(config), FusedTarget(1)
    assert run(classifier, target, fast, seconds=int(VESSEL_MOVING_S) - 1) == "unknown"
    assert run(classifier, target, fast, seconds=int(VESSEL_MOVING_S)) == "vessel"
    # the same speed, too uncertain: not a vessel
    assert run(Classifier(config), FusedTarget(2), fast, sigma=1.0) == "unknown"


@pytest.mark.parametrize("area_m2, height_m, expected", [
    (1000.0, float("nan"), "iceberg"),  # a large footprint
    (10.0, 8.0, "iceberg"),             # a tall LiDAR track
    (10.0, float("nan"), "fixed obstacle"),
])
def test_a_still_target_is_an_iceberg_when_large_else_a_fixed_obstacle_after_settling(area_m2, height_m, expected):
    config = FusionConfig()
    assert config.iceberg_area_m2 < 1000.0 and config.iceberg_height_m < 8.0
    classifier, target = Classifier(config), FusedTarget(1)
    assert run(classifier, target, 0.0, area_m2, height_m=height_m, seconds=int(config.settle_s) - 1) == "unknown"
    assert run(classifier, target, 0.0, area_m2, height_m=height_m, seconds=int(config.settle_s)) == expected


def test_a_vessel_stays_a_vessel_when_it_stops():
    config = FusionConfig()
    classifier, target = Classifier(config), FusedTarget(1)
    run(classifier, target, config.vessel_speed_mps + 1.0)
    assert run(classifier, target, 0.0, 1000.0, seconds=int(config.settle_s) + 5) == "vessel"

"""raysim.pose: rotations of known vectors, frame round trips, heading."""

from __future__ import annotations

import numpy as np
import pytest

from raysim.pose import Poses


def poses(yaw=0.0, pitch=0.0, roll=0.0, position=(0.0, 0.0, 0.0)) -> Poses:
    return Poses(np.array([position], dtype=float), np.array([yaw]), np.array([pitch]), np.array([roll]))


@pytest.mark.parametrize("yaw, pitch, roll, body, world", [
    (0.0, 0.0, 0.0, (1, 0, 0), (1, 0, 0)),              # yaw 0: forward is east
    (np.pi / 2, 0.0, 0.0, (1, 0, 0), (0, 1, 0)),        # yaw counter-clockwise: forward turns north
    (np.pi / 2, 0.0, 0.0, (0, 1, 0), (-1, 0, 0)),       # and left turns west
    (0.0, np.pi / 2, 0.0, (1, 0, 0), (0, 0, -1)),       # FLU pitch positive = bow down
    (0.0, 0.0, np.pi / 2, (0, 1, 0), (0, 0, 1)),        # roll positive = starboard down, port (left) up
    (0.0, 0.0, 0.0, (0, 0, 1), (0, 0, 1)),
])
def test_rotation_maps_known_body_vectors(yaw, pitch, roll, body, world):
    rotation = poses(yaw, pitch, roll).rotation()
    assert rotation.shape == (1, 3, 3)
    assert rotation[0] @ np.array(body, dtype=float) == pytest.approx(np.array(world, dtype=float), abs=1e-12)


def test_rotations_are_orthonormal_with_determinant_one():
    rng = np.random.default_rng(0)
    n = 50
    p = Poses(np.zeros((n, 3)), rng.uniform(-np.pi, np.pi, n), rng.uniform(-1, 1, n), rng.uniform(-1, 1, n))
    r = p.rotation()
    assert np.einsum("nij,nkj->nik", r, r) == pytest.approx(np.broadcast_to(np.eye(3), (n, 3, 3)), abs=1e-12)
    assert np.linalg.det(r) == pytest.approx(np.ones(n), abs=1e-12)


def test_to_world_and_to_body_are_inverse_and_translate():
    p = poses(yaw=0.3, pitch=-0.1, roll=0.2, position=(10.0, -5.0, 1.0))
    point = np.array([[2.0, 1.0, 3.0]])
    assert p.to_body(p.to_world(point)) == pytest.approx(point, abs=1e-12)
    assert poses(position=(10.0, -5.0, 1.0)).to_world(point) == pytest.approx(np.array([[12.0, -4.0, 4.0]]))
    # the body origin is the pose's position
    assert p.to_world(np.zeros((1, 3))) == pytest.approx(p.position_m)


@pytest.mark.parametrize("yaw, heading", [(0.0, 90.0), (np.pi / 2, 0.0), (np.pi, 270.0), (-np.pi / 2, 180.0),
                                          (np.pi / 4, 45.0), (2.5 * np.pi, 0.0)])
def test_heading_is_compass_degrees_clockwise_from_north(yaw, heading):
    assert poses(yaw=yaw).heading_deg[0] % 360.0 == pytest.approx(heading, abs=1e-9)
    assert 0.0 <= poses(yaw=yaw).heading_deg[0] < 360.0

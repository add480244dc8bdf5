"""Checks of a built world over the run: hulls that pass through one another.

raysim does not keep bodies apart: ships follow their waypoints whatever lies on them, and the ray
engine renders two hulls that overlap as one solid. A scenario in which a boat sails through an
anchored ship (harbour_approach's small craft did, through its tanker's centre, until 2026-11-28)
renders without complaint, but no sensor could see it so, and an evaluation of a tracker on it scores
the impossible. :func:`hull_overlaps` finds such moments; :func:`raysim.render.render` prints each as
a one-line warning on stderr. A warning, not an error: a collision-avoidance test may put a target on
a collision course with the own ship on purpose.

The test is certain, never a false alarm: two bodies overlap when their centres are closer than the
sum of their inscribed radii (half the smaller of each one's above-water length and beam): the discs
of those radii lie inside the bodies' outlines for a box-shaped hull. Bodies that overlap only
outside those discs (two hulls' ends, a ship alongside a quay) are not reported.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from raysim.recording.jsonl import centre_positions_m
from raysim.world import World, WorldObject

#: time between the instants the check looks at, s: two inscribed discs of 1 m radius between
#: bodies closing at 4 m/s (8 kn) overlap for at least 0.5 s
STEP_S = 0.5
#: most (instant, moving body, body) triples held at once, to keep memory flat in large scenarios
_BLOCK_ELEMENTS = 2_000_000
#: instants at which every body is posed in one call
_POSE_BLOCK = 600


@dataclass(frozen=True)
class HullOverlap:
    """Two bodies whose hulls overlap, at the instant their centres come closest.

    Attributes
    ----------
    where_a, where_b : str
        The bodies' places in the scenario file (``ships[2]``, ``own_ship``) with their names.
    t_s : float
        Time of the closest approach, s since the start.
    distance_m : float
        Distance between their centres then, m.
    allowed_m : float
        Sum of their inscribed radii, m: closer than this, the hulls overlap.
    """

    where_a: str
    where_b: str
    t_s: float
    distance_m: float
    allowed_m: float

    def message(self) -> str:
        """One line for stderr."""
        return (f"{self.where_a} and {self.where_b}: hulls overlap (centres {self.distance_m:.1f} m apart at "
                f"t = {self.t_s:.1f} s, under the {self.allowed_m:.1f} m their half beams leave)")


def _centres_m(bodies: list[WorldObject], t_s: np.ndarray) -> np.ndarray:
    """(N, M, 2) east and north of each body's above-water centre at the (N,) times, m (truth.jsonl's centre)."""
    out = []
    for o in bodies:
        poses = o.motion.poses(t_s)
        out.append(np.stack(centre_positions_m(poses.position_m, poses.yaw_rad, o.centre_body_m), axis=-1))
    return np.stack(out, axis=1)


def hull_overlaps(world: World, step_s: float = STEP_S) -> list[HullOverlap]:
    """Every pair of bodies (not land) whose hulls overlap at some instant of the run.

    Parameters
    ----------
    world : raysim.world.World
        The built world.
    step_s : float
        Time between the instants looked at, s.

    Returns
    -------
    list of HullOverlap
        One per pair, at its closest approach, in the order of the bodies in the world.
    """
    bodies = [o for o in world.objects if o.kind != "land"]
    m = len(bodies)
    if m < 2:
        return []
    radius_m = np.array([0.5 * min(o.length_m, o.beam_m) for o in bodies])
    allowed = radius_m[:, None] + radius_m[None, :]
    t_all = np.arange(0.0, world.scenario.duration_s + 0.5 * step_s, step_s)
    closest = np.full((m, m), np.inf)
    closest_t = np.zeros((m, m))
    per_block = max(1, _BLOCK_ELEMENTS // (m * m))
    for start in range(0, t_all.size, _POSE_BLOCK):
        t_block = t_all[start:start + _POSE_BLOCK]
        centres_block = _centres_m(bodies, t_block)  # each body posed once per block of instants
        for first in range(0, t_block.size, per_block):
            t_s = t_block[first:first + per_block]
            centres = centres_block[first:first + per_block]
            d = np.hypot(*np.moveaxis(centres[:, :, None, :] - centres[:, None, :, :], -1, 0))  # (N, M, M)
            k = np.argmin(d, axis=0)
            d_min = np.take_along_axis(d, k[None], axis=0)[0]
            better = d_min < closest
            closest = np.where(better, d_min, closest)
            closest_t = np.where(better, t_s[k], closest_t)
    a, b = np.nonzero(np.triu(closest < allowed, k=1))
    return [HullOverlap(f"{bodies[i].key_path} ({bodies[i].name})", f"{bodies[j].key_path} ({bodies[j].name})",
                        float(closest_t[i, j]), float(closest[i, j]), float(allowed[i, j])) for i, j in zip(a, b)]

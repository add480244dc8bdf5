"""Radar echo extents against analytic geometry."""

import numpy as np

from tdm.echoes import inside_echoes


def test_inside_echoes_is_the_beam_plus_the_half_length_in_bearing_and_the_half_length_plus_a_margin_in_range():
    own = np.array([0.0, 0.0])
    centre = np.array([[0.0, 500.0]])  # due north, 500 m; 60 m long
    beam_deg, margin_m = 5.2, 10.0
    half_angle = np.radians(beam_deg) + np.arctan2(30.0, 500.0)

    def at(range_m, bearing_rad):
        return [range_m * np.sin(bearing_rad), range_m * np.cos(bearing_rad)]

    points = np.array([at(500.0, 0.99 * half_angle), at(500.0, 1.01 * half_angle), at(539.0, 0.0), at(541.0, 0.0),
                       at(461.0, -0.99 * half_angle), at(500.0, np.pi)])
    inside = inside_echoes(points, centre, np.array([60.0]), own, beam_deg, margin_m)[:, 0]
    assert inside.tolist() == [True, False, True, False, True, False]
    # a point object: the beam alone, the margin alone
    inside = inside_echoes(np.array([at(500.0, np.radians(5.0)), at(500.0, np.radians(5.4))]), centre, np.zeros(1),
                           own, beam_deg, margin_m)[:, 0]
    assert inside.tolist() == [True, False]

"""Nautical units (docs/reference.md section 1): 1 international nautical mile = 1852 m, 1 knot = 1 NM per hour."""

from __future__ import annotations

#: One nautical mile, metres.
METRES_PER_NM = 1852.0
#: One knot in metres per second (1852 / 3600).
KNOT_MPS = 1852.0 / 3600.0
#: The same, by the name of the conversion it makes (knots -> m/s).
MPS_PER_KNOT = KNOT_MPS
#: Knots per metre per second (3600 / 1852), m/s -> knots.
KNOTS_PER_MPS = 3600.0 / 1852.0

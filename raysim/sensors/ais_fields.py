"""Moved to :mod:`raysim.ais_fields` (below the sensors: the scenario checks need it too); this name stays
only until every importer takes it from there."""

from raysim.ais_fields import *  # noqa: F401,F403

"""Moved to :mod:`groundfloor.hdl32e` (the HDL-32E facts raysim and the TDM share); this name stays only
until every importer takes them from there."""

from groundfloor.hdl32e import *  # noqa: F401,F403

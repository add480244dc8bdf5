"""Radar cross-section of triangle meshes: shooting and bouncing rays with physical optics.

:func:`raysim.rcs.engine.monostatic_rcs` is the engine; :func:`raysim.rcs.command.run` is
``raysim rcs``. Source: Ling, Chou and Lee, IEEE Trans. Antennas Propag. 37(2), 1989.
"""

"""The one error type for bad input: a file, a place in it, and what is wrong.

The command line prints ``error: <file>: <place>: <what>`` on one line and exits
with code 2 (see :mod:`raysim.cli`); nothing else in raysim prints errors.
"""

from __future__ import annotations


class InputError(Exception):
    """Bad user input (scenario, mesh, trajectory, recording, command-line value).

    Parameters
    ----------
    file : str
        The file at fault (or ``"command line"``).
    where : str
        The place in it: a key path such as ``ships[0].ais.mmsi``, or ``line 7``.
    what : str
        What is wrong, in one line.
    """

    def __init__(self, file: str, where: str, what: str):
        self.file = str(file)
        self.where = str(where)
        self.what = " ".join(str(what).split())  # always one line
        super().__init__(f"{self.file}: {self.where}: {self.what}")

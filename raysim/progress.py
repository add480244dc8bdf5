"""Progress of a run's stages on stderr: bars on a terminal, one line per start and end otherwise.

Every stage of ``raysim render`` / ``raysim run`` (world, truth, ownship, each sensor, the TDM,
its evaluation, the bag, the pictures, the point-cloud files) runs inside :func:`stage`:

- ``progress=None`` (the default) and stderr a terminal: the stage's own tqdm bar, or, for a
  stage without one (``bar=False``), a transient line with its name and a clock (ticking each second);
- ``progress=None`` and stderr not a terminal (a log file, CI): two lines per stage,
  ``raysim: lidar: 60 revolutions of the HDL-32E ...`` when it starts and
  ``raysim: lidar: 10850 packets, 1061160 points, 59 sweeps ... done in 12.3 s`` when it ends (what
  it made, when the stage says; ``failed after`` on an error);
- ``progress=True``: bars even without a terminal; ``progress=False`` (``--no-progress``): nothing.
"""

from __future__ import annotations

import sys
import threading
import time
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Iterator, Literal

__all__ = ["Stage", "bars", "mode", "stage"]

PREFIX = "raysim"

Mode = Literal["bars", "lines", "off"]


def mode(progress: bool | None) -> Mode:
    """How progress shows: ``"bars"``, ``"lines"`` or ``"off"`` (see the module docstring)."""
    if progress is False:
        return "off"
    if progress is True:
        return "bars"
    isatty = getattr(sys.stderr, "isatty", None)
    return "bars" if isatty is not None and isatty() else "lines"


def bars(progress: bool | None) -> bool:
    """Whether the stages draw their own tqdm bars (the ``progress`` flag the renderers take)."""
    return mode(progress) == "bars"


@dataclass
class Stage:
    """A running stage: what it does and how long it took.

    Attributes
    ----------
    name : str
        Stage name (``"lidar"``, ``"rosbag"``, ...).
    what : str
        What it does, e.g. ``"59 revolutions"``; the body may change or extend it (``done``).
    done : str
        Set by the body: what it made, shown at the end instead of ``what`` (e.g. ``"6 pictures"``).
    elapsed_s : float
        Wall time of the stage, s (set when it ends).
    """

    name: str
    what: str = ""
    done: str = ""
    elapsed_s: float = 0.0
    _started: float = field(default_factory=time.perf_counter, repr=False)

    def label(self, text: str) -> str:
        return f"{PREFIX}: {self.name}: {text}" if text else f"{PREFIX}: {self.name}"


def _say(line: str) -> None:
    print(line, file=sys.stderr, flush=True)


class _Clock:
    """A transient tqdm line ``desc ... 00:12`` whose clock a daemon thread refreshes every second."""

    def __init__(self, desc: str):
        from tqdm import tqdm

        self._bar = tqdm(total=None, desc=desc, bar_format="{desc} ... {elapsed}", leave=False, file=sys.stderr)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._tick, daemon=True)
        self._thread.start()

    def _tick(self) -> None:
        while not self._stop.wait(1.0):
            self._bar.refresh()

    def close(self) -> None:
        self._stop.set()
        self._thread.join()
        self._bar.close()


@contextmanager
def stage(name: str, progress: bool | None, what: str = "", *, bar: bool = False) -> Iterator[Stage]:
    """Run the body of a ``with`` block as stage ``name`` and report it (module docstring).

    Parameters
    ----------
    name : str
        Stage name.
    progress : bool or None
        ``None``: bars on a terminal, lines otherwise; ``True``: bars; ``False``: silent.
    what : str
        What the stage does (shown at its start, and at its end unless the body sets ``done``).
    bar : bool
        The body draws its own tqdm bar (with bars nothing else is shown then).

    Yields
    ------
    Stage
        Its ``done`` may be set by the body; ``elapsed_s`` is set on the way out.
    """
    how = mode(progress)
    current = Stage(name, what)
    clock = None
    if how == "lines":
        _say(current.label(f"{what} ..." if what else "..."))
    elif how == "bars" and not bar:
        clock = _Clock(f"{name}: {what}" if what else name)
    try:
        yield current
    except BaseException:
        current.elapsed_s = time.perf_counter() - current._started
        if how == "lines":
            _say(current.label(f"failed after {current.elapsed_s:.1f} s"))
        raise
    finally:
        if clock is not None:
            clock.close()
    current.elapsed_s = time.perf_counter() - current._started
    if how == "lines":
        text = current.done or current.what
        took = f"done in {current.elapsed_s:.1f} s"
        _say(current.label(f"{text} ... {took}" if text else took))

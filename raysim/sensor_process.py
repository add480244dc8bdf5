"""One sensor rendered in a second process while this process renders the others.

The LiDAR takes the longest of a recording's sensors (on busy_open_sea about twice the radar's time;
benchmarks/results/lidar.md, radar.md), and each renderer runs on one core. On a machine with two or
more cores, :func:`raysim.render.render` (with ``sensor_processes=2``, as ``raysim run`` and ``raysim
render`` call it) starts a child process that renders the LiDAR into the staged directory while the
parent renders the radar, AIS and navigation. Each sensor draws only on its own named random streams
(:mod:`raysim.random_streams`) and writes only its own files, so the recording is the same bytes as
when the sensors run one after another (tests/raysim/test_sensor_process.py).

The child is *spawned* (a fresh interpreter that gets the world by pickle), not forked: a process
that has cast rays before holds Embree's thread pool, which does not survive a fork (the forked
child hangs in its first cast). What the child made (its counts and wall time) comes back through
a pipe; an error in it is raised again here, and the staged directory is then removed as for any
error (nothing partial on disk). A child still running when the parent fails is terminated.
"""

from __future__ import annotations

import dataclasses
import multiprocessing
import time
from typing import Callable

__all__ = ["SensorProcess", "can_start"]


def can_start() -> bool:
    """Whether this process may start a child (a daemonic process, such as a Dask worker's, may not)."""
    return not multiprocessing.current_process().daemon


class SensorProcess:
    """A sensor's renderer running in a spawned child.

    Parameters
    ----------
    name : str
        The sensor (for messages).
    renderer : callable
        ``renderer(ctx)`` (:data:`raysim.render.SENSOR_RENDERERS`): a module-level function (it is
        pickled by name).
    ctx : raysim.render.RenderContext
        The render's context; the child works on a copy (pickled) without progress bars and with no
        ray engine (it builds its own).
    """

    def __init__(self, name: str, renderer: Callable, ctx):
        spawn = multiprocessing.get_context("spawn")
        self.name = name
        self._receive, send = spawn.Pipe(duplex=False)
        child_ctx = dataclasses.replace(ctx, progress=False, counts={}, wall_time_s={}, _scene=None)
        self._process = spawn.Process(target=_run, args=(renderer, child_ctx, send), name=f"raysim-{name}")
        self._process.start()
        send.close()

    def join(self) -> tuple[dict, float]:
        """Wait for the child: the counts it made and its renderer's wall time, s.

        Raises
        ------
        Exception
            The child's own error, or RuntimeError when it ended without a word (killed).
        """
        try:
            kind, payload = self._receive.recv()
        except EOFError:
            kind, payload = "died", None
        finally:
            self._receive.close()
            self._process.join()
        if kind == "died":
            raise RuntimeError(f"the {self.name} renderer's process ended with exit code {self._process.exitcode}")
        if kind == "error":
            raise payload
        return payload

    def stop(self) -> None:
        """Terminate the child if it still runs (the parent failed)."""
        if self._process.is_alive():
            self._process.terminate()
            self._process.join()


def _run(renderer: Callable, ctx, send) -> None:
    """The child: render, then send ("ok", (counts, wall time s)) or ("error", exception)."""
    started = time.perf_counter()
    try:
        renderer(ctx)
        message = ("ok", (dict(ctx.counts), time.perf_counter() - started))
    except BaseException as exc:  # noqa: BLE001 - every failure goes back to the parent
        message = ("error", exc)
    try:
        send.send(message)
    except Exception as exc:  # an exception that does not pickle: its text
        send.send(("error", RuntimeError(f"{type(message[1]).__name__}: {message[1]} ({exc})")))
    finally:
        send.close()

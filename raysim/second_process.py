"""Work of a render done in a second process while this process does other work.

Each renderer and writer runs on one core, and a render has two pieces of work that take long and
share nothing: the LiDAR and the other sensors (on busy_open_sea the LiDAR takes about as long as
the radar, AIS and navigation together; benchmarks/results/lidar.md, radar.md), and, once the TDM
has run, the ROS 2 bag and the TDM's evaluation and the pictures. On a machine with two or more
cores, :func:`raysim.render.render` (``processes=2``, as ``raysim run`` and ``raysim render`` call
it, for a scenario of at least :data:`MIN_SCENARIO_S`) starts a child process for the LiDAR while it renders the other sensors, and one for the bag
while it evaluates and draws. Each sensor draws only on its own named random streams
(:mod:`raysim.random_streams`) and every piece writes only its own files, so the recording is the
same bytes as when everything runs one after another (tests/raysim/test_second_process.py).

The child is *spawned* (a fresh interpreter that gets the render's context by pickle), not forked:
a process that has cast rays before holds Embree's thread pool, which does not survive a fork (the
forked child hangs in its first cast). What the child made (its counts and wall time) comes back
through a pipe; an error in it is raised again here, and the staged directory is then removed as
for any error (nothing partial on disk). A child still running when the parent fails is terminated.
"""

from __future__ import annotations

import contextlib
import dataclasses
import multiprocessing
import os
import signal
import threading
import time
from typing import Callable

__all__ = ["MIN_SCENARIO_S", "SecondProcess", "can_start"]


#: Shortest scenario given second processes, s: a spawned child takes 1-2 s to start (a fresh interpreter
#: importing numpy and Open3D, and the world by pickle), more than a shorter render's LiDAR or bag saves.
MIN_SCENARIO_S = 30.0


def can_start(duration_s: float) -> bool:
    """Whether a render of ``duration_s`` s of scenario gains from a second process here: at least
    :data:`MIN_SCENARIO_S` long, and this process may have children (a daemonic process, such as a Dask
    worker's, may not)."""
    return duration_s >= MIN_SCENARIO_S and not multiprocessing.current_process().daemon


class SecondProcess:
    """A renderer or writer running in a spawned child.

    Parameters
    ----------
    name : str
        What it makes (for messages).
    renderer : callable
        ``renderer(ctx)``, which records what it made in ``ctx.counts`` (:data:`raysim.render.SENSOR_RENDERERS`,
        :func:`raysim.render.write_bag`): a module-level function (it is pickled by name).
    ctx : raysim.render.RenderContext
        The render's context; the child works on a copy (pickled) without progress bars and with no
        ray engine (it builds its own).
    claims : multiprocessing Array, optional
        The chunks of a LiDAR run the child may render (:class:`raysim.sensors.lidar_run.ChunkClaims`),
        inherited by the child as its context's ``lidar_claims`` (a shared array cannot go down a pipe).
    """

    def __init__(self, name: str, renderer: Callable, ctx, claims=None):
        spawn = multiprocessing.get_context("spawn")
        self.name = name
        self._pipe, child_end = spawn.Pipe(duplex=True)
        self._process = spawn.Process(target=_run, args=(renderer, child_end, claims), name=f"raysim-{name}")
        with _interrupts_ignored():  # inherited: Ctrl-C reaches the parent alone, which stops the child
            self._process.start()
        child_end.close()
        try:  # the context goes down the pipe: a parent stopped half-way leaves the child a quiet end
            self._pipe.send(dataclasses.replace(ctx, progress=False, counts={}, wall_time_s={}, _scene=None))
        except BaseException:
            self.stop()
            raise

    def join(self) -> tuple[dict, float]:
        """Wait for the child: the counts it made and its renderer's wall time, s.

        Raises
        ------
        Exception
            The child's own error, or RuntimeError when it ended without a word (killed).
        """
        try:
            kind, payload = self._pipe.recv()
        except EOFError:
            kind, payload = "died", None
        finally:
            self._pipe.close()
            self._process.join()
        if kind == "died":
            raise RuntimeError(f"the {self.name} process ended with exit code {self._process.exitcode}")
        if kind == "error":
            raise payload
        return payload

    def stop(self) -> None:
        """Terminate the child if it still runs (the parent failed)."""
        if self._process.is_alive():
            self._process.terminate()
            self._process.join()


@contextlib.contextmanager
def _interrupts_ignored():
    """SIGINT ignored while a child starts, so that the child ignores it for good (a disposition to
    ignore survives exec, and Python then installs no KeyboardInterrupt handler): Ctrl-C, which a
    terminal sends to the whole process group, interrupts the parent, whose clean-up stops the child,
    and no child prints a traceback. Only in the main thread (where signals can be set)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def _run(renderer: Callable, pipe, claims=None) -> None:
    """The child: the context from the pipe, render, then send back ("ok", (counts, wall time s)) or
    ("error", exception). A parent gone (stopped, killed) ends it quietly."""
    try:
        ctx = pipe.recv()
    except BaseException:  # noqa: BLE001 - the parent is gone: nothing to say, no one to say it to
        os._exit(1)
    started = time.perf_counter()
    try:
        if claims is not None:
            ctx.lidar_claims = claims
        renderer(ctx)
        message = ("ok", (dict(ctx.counts), time.perf_counter() - started))
    except BaseException as exc:  # noqa: BLE001 - every failure goes back to the parent
        message = ("error", exc)
    try:
        pipe.send(message)
    except BaseException as exc:  # noqa: BLE001 - an exception that does not pickle: its text
        try:
            pipe.send(("error", RuntimeError(f"{type(message[1]).__name__}: {message[1]} ({exc})")))
        except BaseException:  # noqa: BLE001 - the parent is gone
            os._exit(1)
    finally:
        pipe.close()

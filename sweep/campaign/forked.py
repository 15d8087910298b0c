"""Worker processes forked from the sweep's own process: the local backend's workers where a
fork is safe.

A loky worker is a new interpreter: before its first scene it imports numpy, scipy, numba and
the engine and loads the compiled kernels, 0.85-1.15 s on a 2-core machine, which is a third
of a warm 200-scene campaign's wall (docs/performance.md). A worker forked from the parent
after the parent loaded them starts in milliseconds, with the kernels, the imports and the
parent's in-memory caches already there (caches save time, never change a number: the rows
are the same to the bit as loky's, tests/campaign/test_forked.py).

The scenes are not sent to the workers: they are in the parent's memory when it forks, and
each task names its call by index (:class:`ForkedWorkers`); only the rows come back, pickled.
A worker that dies (a segfault, ``os._exit``) breaks the pool: the parent gets
``BrokenProcessPool`` for the calls left, never a hang. The workers ignore SIGINT (a Ctrl-C
reaches the whole process group): the parent handles it and kills them. A worker whose parent
was killed ends with it (:func:`sweep.threads.exit_with_parent`, as a loky worker does).

A fork copies only the calling thread, so a lock held by another thread at that moment stays
held in the child forever: :func:`usable` is True only on Linux and in a process running a
single thread (a Jupyter kernel, a dask client or a live loky executor has more); elsewhere the
local backend starts loky workers, as before.
"""
from __future__ import annotations

import multiprocessing
import signal
import sys
import threading
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, as_completed, wait

#: the calls of the pool being started, (function, [argument tuples]): read by the forked
#: workers (their copy of the parent's memory), cleared in the parent once they are forked
_CALLS = None


def usable() -> bool:
    """Whether this process may fork its workers: Linux, the fork start method, and no
    thread but the main one."""
    return (sys.platform.startswith("linux")
            and "fork" in multiprocessing.get_all_start_methods()
            and threading.active_count() == 1)


def _worker_signals() -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    # the parent's `sweep run` turns SIGTERM into an interrupt; a worker ends on it
    signal.signal(signal.SIGTERM, signal.SIG_DFL)


def _call(index: int):
    function, arguments = _CALLS
    return function(*arguments[index])


class ForkedWorkers:
    """``function(*args)`` for each ``args`` of ``calls`` on ``workers`` processes forked now.

    Iterate for the results in completion order; :meth:`close` ends the workers (killing them
    when the results were not all read: an interrupted or failed sweep).
    """

    def __init__(self, function, calls, workers: int):
        global _CALLS
        if not usable():
            raise RuntimeError("forked workers need Linux and a single-threaded process")
        _CALLS = (function, list(calls))
        try:
            self._executor = ProcessPoolExecutor(
                workers, mp_context=multiprocessing.get_context("fork"),
                initializer=_worker_signals)
            # the first submit forks every worker (the fork start method starts them all at
            # once, before the executor's own threads): they inherit _CALLS as it is now
            futures = [self._executor.submit(_call, i) for i in range(len(_CALLS[1]))]
        finally:
            _CALLS = None
        #: the calls whose results are not read yet (a result read is dropped here, so a
        #: long sweep's rows and trajectories are not all held until its end)
        self.pending = set(futures)

    def __iter__(self):
        for future in as_completed(list(self.pending)):
            self.pending.discard(future)
            yield future.result()           # BrokenProcessPool if a worker died

    def ticking(self, seconds: float):
        """As iterating, but yield ``None`` each time ``seconds`` pass without a result (a
        caller's moment to look at what the workers write meanwhile)."""
        while self.pending:
            done, _ = wait(self.pending, timeout=seconds, return_when=FIRST_COMPLETED)
            if not done:
                yield None
            for future in done:
                self.pending.discard(future)
                yield future.result()       # BrokenProcessPool if a worker died

    def close(self) -> None:
        """End the workers: at once (SIGKILL) if results are still unread, else when idle."""
        if self.pending:
            for future in self.pending:
                future.cancel()
            for process in list((getattr(self._executor, "_processes", None) or {}).values()):
                try:
                    process.kill()
                except Exception:  # pragma: no cover - already gone
                    pass
        self._executor.shutdown(wait=True, cancel_futures=True)

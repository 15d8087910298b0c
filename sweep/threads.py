"""One thread per process for BLAS, OpenMP and Numba: the one place that sets these limits;
and a worker process that ends with its parent (:func:`exit_with_parent`).

A dense BEM step is a matrix-vector product of size N ~ 500, and a sweep runs one scene per
core, so more threads per process only oversubscribe the cores (docs/design.md section 6).
Environment variables act only if they are set before the library that reads them is loaded;
:func:`limit_loaded_pools` also limits BLAS/OpenMP pools that are already running, and
:func:`limit_preloaded` does so when ``sweep`` is imported after them (``import scipy.linalg``
first): the kernels' matrix-vector products and factorizations go through scipy's BLAS, and a
multi-threaded BLAS sums in another order, so a scene's last digits, and on a scene at the
edge of convergence whether its Newton solve converges at all, depended on what the process
had imported before ``sweep`` (measured on n 0.8, k 0.1, mu 3.24, a0 3, rate 10, pz_v0 0.1:
386 factorizations and pull-off 11.422780570270085 either way with one thread; 350 and
11.422780570092314 with scipy.linalg imported first on a 2-core machine).
"""
from __future__ import annotations

import os
import sys
import threading
import time

#: BLAS/OpenMP variables set (unless the user set them) when ``sweep`` is imported.
BLAS_VARS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")

#: Every variable set in a sweep worker process (before it imports numpy or numba).
THREAD_VARS = BLAS_VARS + ("BLIS_NUM_THREADS", "VECLIB_MAXIMUM_THREADS",
                           "NUMEXPR_NUM_THREADS", "NUMBA_NUM_THREADS")


def limit_env(names=THREAD_VARS) -> None:
    """Set each variable of ``names`` to 1 unless it is already set."""
    for var in names:
        os.environ.setdefault(var, "1")


def limit_loaded_pools():
    """Limit the BLAS/OpenMP pools already loaded to one thread.

    Returns the ``threadpoolctl`` limiter (call ``restore_original_limits()`` on it to undo),
    or None if threadpoolctl (a dependency) is unavailable.
    """
    try:
        from threadpoolctl import threadpool_limits

        return threadpool_limits(limits=1)
    except Exception:  # pragma: no cover - threadpoolctl is a dependency
        return None


def limit_preloaded(names=BLAS_VARS):
    """At ``import sweep``: where numpy or scipy were imported before it and the user set none
    of ``names``, limit the pools they loaded to one thread (:func:`limit_loaded_pools`), as
    :func:`limit_env` does for the pools loaded after. Call before :func:`limit_env`. Returns
    the limiter, or None where there was nothing to limit."""
    if any(var in os.environ for var in names):
        return None                     # the user's own choice, kept
    if not any(mod in sys.modules for mod in ("numpy", "scipy")):
        return None                     # nothing loaded yet: the variables will do
    return limit_loaded_pools()


#: how often (s) a worker looks whether the process that started it is still there
PARENT_POLL_S = 1.0


def exit_with_parent(poll_s: float = PARENT_POLL_S) -> threading.Thread:
    """End this process as soon as its parent is gone (a ``sweep run`` killed with SIGKILL,
    whose loky workers would otherwise compute their scenes on, orphaned, holding the cores):
    a daemon thread compares ``os.getppid()`` with the parent's pid at the start every
    ``poll_s`` seconds and ends the process (``os._exit``) when the parent changed. It runs
    between the engine's compiled calls (one Newton solve or one chunk of unloading steps,
    ``sweep.engine.budget.CHECK_SLACK_S`` at most), so an orphan stops within seconds."""
    parent = os.getppid()

    def watch():
        while True:
            time.sleep(poll_s)
            if os.getppid() != parent:
                os._exit(70)       # EX_SOFTWARE: nothing of the parent's is left to report to

    thread = threading.Thread(target=watch, name="sweep-exit-with-parent", daemon=True)
    thread.start()
    return thread

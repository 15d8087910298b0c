"""One thread per process for BLAS, OpenMP and Numba: the one place that sets these limits.

A dense BEM step is a matrix-vector product of size N ~ 500, and a sweep runs one scene per
core, so more threads per process only oversubscribe the cores (docs/design.md section 6).
Environment variables act only if they are set before the library that reads them is loaded;
:func:`limit_loaded_pools` also limits BLAS/OpenMP pools that are already running.
"""
from __future__ import annotations

import os

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
    or None if threadpoolctl (a joblib dependency) is unavailable.
    """
    try:
        from threadpoolctl import threadpool_limits

        return threadpool_limits(limits=1)
    except Exception:  # pragma: no cover - threadpoolctl is a joblib dependency
        return None

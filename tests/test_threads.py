"""One BLAS thread per process whatever was imported before ``sweep`` (sweep/threads.py).

The kernels' products and factorizations go through scipy's BLAS; a multi-threaded one sums in
another order, so a scene's last digits depended on whether the process imported scipy.linalg
before ``sweep`` (on a 2-core machine: 386 against 350 factorizations of a process-zone scene,
pull-offs 1.6e-11 apart). Each check runs in a fresh interpreter, the BLAS variables cleared.
"""
import json
import os
import subprocess
import sys

from sweep.threads import BLAS_VARS

POOLS = ("from threadpoolctl import threadpool_info; import json; "
         "print(json.dumps(sorted(p['num_threads'] for p in threadpool_info())))")
SCENE = ("from sweep import Scene, Numerics, simulate; "
         "r = simulate(Scene(n=0.8, k=0.1, mu=3.24, a0=2.0, rate=100.0, model='bem'), "
         "Numerics.preset('fast')); print(repr(float(r.pull_off)), r.factorizations)")


def _run(code: str, **env) -> str:
    clean = {k: v for k, v in os.environ.items() if k not in BLAS_VARS}
    out = subprocess.run([sys.executable, "-c", code], env={**clean, **env}, check=True,
                         capture_output=True, text=True, timeout=600)
    return out.stdout.strip().splitlines()[-1]


def test_pools_loaded_before_sweep_are_limited_to_one_thread():
    pools = json.loads(_run("import scipy.linalg, sweep; " + POOLS))
    assert pools and set(pools) == {1}


def test_a_users_own_thread_setting_is_kept():
    # OPENBLAS_NUM_THREADS set by the user: sweep leaves the pools as they were without it
    alone = _run("import scipy.linalg; " + POOLS, OPENBLAS_NUM_THREADS="2")
    with_sweep = _run("import scipy.linalg, sweep; " + POOLS, OPENBLAS_NUM_THREADS="2")
    assert with_sweep == alone


def test_a_scene_is_bitwise_the_same_whatever_was_imported_before_sweep():
    first = _run(SCENE)
    after_scipy = _run("import scipy.linalg, numpy; " + SCENE)
    assert after_scipy == first

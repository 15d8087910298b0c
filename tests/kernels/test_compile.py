"""What a cold compile compiles (docs/performance.md, "The first run"): structural checks in
fresh interpreters, no timing."""
import json
import os
import subprocess
import sys

import pytest

# the modules a BEM scene must not import: plotting, tables and storage, and the scipy
# subpackages of the other models and of a Prony fit (disk-cached on a scene's path)
NOT_ON_A_SCENES_PATH = ("pandas", "h5py", "matplotlib", "joblib", "scipy.special",
                        "scipy.optimize", "scipy.integrate", "scipy.interpolate")


def test_a_bem_scene_imports_no_plotting_storage_or_other_models_scipy(tmp_path):
    """With its Prony series on disk (a first process fits it into a fresh SWEEP_CACHE_DIR),
    a BEM scene in a new process imports none of NOT_ON_A_SCENES_PATH: whatever the
    machine's cache held before."""
    code = ("import sys\n"
            "from sweep.engine import models\n"
            "from sweep import Scene, Numerics\n"
            "res = models.simulate(Scene(n=0.8, k=0.5, mu=3.24, a0=1.5, rate=10.0),\n"
            "                      Numerics(nodes=80, domain=3.0, mesh='uniform', step=0.5,\n"
            "                               da_max=2.0, pull_off_rtol=0.0))\n"
            "assert res.ok, res.reason\n"
            f"print([m for m in {NOT_ON_A_SCENES_PATH!r} if m in sys.modules])\n")
    env = dict(os.environ, SWEEP_CACHE_DIR=str(tmp_path / "cache"))
    subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                   env=env)                                  # fits and keeps the series
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True, env=env)
    assert out.stdout.strip().splitlines()[-1] == "[]"


COUNT_COMPILES = """
import collections, json
from numba.core import event
seen = collections.defaultdict(list)
class Listener(event.Listener):
    def on_start(self, ev):
        d = ev.data["dispatcher"]
        if d.py_func.__module__.startswith("sweep.kernels"):
            seen[d.py_func.__module__ + "." + d.py_func.__name__].append(str(ev.data["args"]))
        else:
            seen["numba:" + d.py_func.__qualname__].append(str(ev.data["args"]))
    def on_end(self, ev):
        pass
event.register("numba:compile", Listener())
from sweep.engine.bem import warm_up
warm_up()
print(json.dumps(seen))
"""


@pytest.mark.slow
def test_a_cold_warm_up_compiles_each_kernel_once(tmp_path):
    """On an empty Numba cache, warm_up() compiles each kernel for one signature (gemv_rows:
    float64 and float32, the single-precision factorization; lu_factor and lu_solve:
    float32 there and float64 in the pseudo-transient fallback; a literal argument would add
    one per value) and none of the parts inlined into newton and unload (inline='always')."""
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path)}
    out = subprocess.run([sys.executable, "-c", COUNT_COMPILES], capture_output=True,
                         text=True, check=True, env=env)
    seen = json.loads(out.stdout.strip().splitlines()[-1])
    assert "sweep.kernels.solve.unload" in seen and "sweep.kernels.solve.newton" in seen
    # Numba's own heavy implementations: np.linalg.solve (about 5 s with its checks and
    # messages) and the shape-mismatch message of a slice assignment (about 2 s)
    others = [name for name in seen if name.startswith("numba:")]
    assert not [n for n in others if "solve_impl" in n or "raise_with_shape_context" in n]
    for name, sigs in seen.items():
        if name.startswith("numba:"):
            continue
        two = name in ("sweep.kernels.blas." + f for f in ("gemv_rows", "lu_factor", "lu_solve"))
        assert len(sigs) <= (2 if two else 1), (name, sigs)
    for inlined in ("solve_step", "predict_step", "snap", "relax", "relax_machine",
                    "machine_residual", "machine_direction", "_refactorize", "_copy"):
        assert "sweep.kernels.solve." + inlined not in seen
    assert "sweep.kernels.blas._gemv" not in seen and "sweep.kernels.blas._ints" not in seen

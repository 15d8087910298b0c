"""visco-sweep: viscoelastic adhesive contact of a rigid sphere, as a parameter-sweep engine.

Public API (units and conventions: see ``sweep.units`` and docs/design.md section 2)::

    from sweep import Scene, Numerics, simulate
    result = simulate(Scene(n=0.8, k=0.1, mu=3.24, a0=3.61, rate=316.2), Numerics.preset("balanced"))

The root is lazy (PEP 562): ``import sweep`` loads the vocabulary (errors, scene) only; the
machinery behind ``simulate``, ``run_sweep``, ``load`` ... (numba, scipy, h5py, pandas) is
imported on first access of the name, so that ``sweep --help`` starts at once.
"""
from importlib import import_module

from . import threads as _threads
from ._version import __version__

# One BLAS thread per process unless the user says otherwise (see sweep.threads): the pools
# loaded before sweep (scipy.linalg imported first) limited now, the others by the variables,
# set before numpy is imported by the modules below.
_threads.limit_preloaded()
_threads.limit_env(_threads.BLAS_VARS)

from .errors import InputError  # noqa: E402
from .scene import PRESETS, Numerics, Result, Scene, scene_id  # noqa: E402

#: Public name -> "module:attribute", imported on first access. The one table to change when
#: a name moves.
_LAZY = {
    "simulate": "sweep.engine.models:simulate",  # the one entry for one scene
    "warm_up": "sweep.engine.bem:warm_up",
    "load": "sweep.campaign.store:load",                # results files of sweeps
    "load_trajectory": "sweep.campaign.store:load_trajectory",
    "run_sweep": "sweep.campaign.scheduler:run_sweep",  # the Python entry point of `sweep run`
}

__all__ = ["InputError", "PRESETS", "Numerics", "Result", "Scene", "scene_id", "simulate",
           "warm_up", "load", "load_trajectory", "run_sweep", "__version__"]


def __getattr__(name):
    """Import a name of :data:`_LAZY` on its first access (then it is a plain attribute)."""
    target = _LAZY.get(name)
    if target is None:
        raise AttributeError(f"module 'sweep' has no attribute {name!r}")
    module, attr = target.split(":")
    value = getattr(import_module(module), attr)
    globals()[name] = value
    return value


def __dir__():
    return sorted({*globals(), *_LAZY})

"""visco-sweep: viscoelastic adhesive contact of a rigid sphere, as a parameter-sweep engine.

Public API (units and conventions: see ``sweep.units`` and docs/design.md section 2)::

    from . import Scene, Numerics, simulate
    result = simulate(Scene(n=0.8, k=0.1, mu=3.24, a0=3.61, rate=316.2), Numerics.preset("balanced"))
"""
from . import threads as _threads

from ._version import __version__  # noqa: E402,F401

# One BLAS thread per process unless the user says otherwise (see sweep.threads); before
# numpy is imported by the modules below.
_threads.limit_env(_threads.BLAS_VARS)

from .errors import InputError  # noqa: E402
from .scene import PRESETS, Numerics, Result, Scene, scene_id  # noqa: E402
from .engine.models import simulate  # noqa: E402  (the one entry for one scene)
from .engine.bem import warm_up  # noqa: E402
from .campaign.store import load, load_trajectory  # noqa: E402  (results files of sweeps)
from .campaign.scheduler import run_sweep  # noqa: E402  (the Python entry point of `sweep run`)

__all__ = ["InputError", "PRESETS", "Numerics", "Result", "Scene", "scene_id", "simulate",
           "warm_up", "load", "load_trajectory", "run_sweep", "__version__"]

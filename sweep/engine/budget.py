"""The time budget of one scene (``Numerics.time_budget_s``): one deadline for all of it.

:func:`sweep.engine.models.simulate`, the front door, opens the scene's budget
(:func:`scene_budget`); every model, retry and stage of the scene then reads the same deadline
(:func:`deadline`) and checks it (:func:`check`): the auto chooser's fallbacks, the error
estimate's coarser solve, the relaxed start's Newton solves, the tip-following mesh's
re-meshings, the unloading kernel (between its chunks, and within them: it reads the
deadline before every Newton iteration) and the crack-front integrator. A scene that runs
past it ends as a failed row whose reason starts ``time budget:``, within the budget plus the
longest stretch between two checks (:data:`CHECK_SLACK_S`, measured by
``tests/engine/test_budget.py`` on the scene that hung a sweep before).

Called outside :func:`scene_budget` (a model's simulate function called directly), each
function that reads the deadline starts a budget of its own, as before.

The budget ends computations, never changes one: where a check passes, the solve goes on
exactly as without it, so a scene's numbers do not depend on the machine's speed.

A solve may also be held to a count of factorizations (:func:`work_cap`, read by
:func:`check_work` at the unloading's chunks and re-meshings): the error estimate's cheaper
solves are (``sweep.engine.resolution.COARSE_WORK_FACTOR``). Counts, unlike seconds, stop a
solve at the same place on every machine.
"""
from __future__ import annotations

import math
import time
from contextlib import contextmanager
from contextvars import ContextVar

from ..kernels.jacobian import set_deadline

__all__ = ["OverBudget", "scene_budget", "deadline", "remaining", "budget_seconds", "check",
           "arm", "CHECK_SLACK_S", "OverWork", "work_cap", "check_work"]

#: (deadline in time.perf_counter() seconds, the budget in seconds) of the scene being run
_BUDGET: ContextVar[tuple[float, float] | None] = ContextVar("scene_budget", default=None)

#: the slack a scene may run past its budget: the longest stretch between two checks. The
#: unloading kernel reads the deadline itself before every Newton iteration
#: (kernels.jacobian.set_deadline): one chunk of its steps (sweep.engine.bem.CHUNK_STEPS)
#: lasted 1.5-4.8 s on 1019-1175 nodes (2026-11-26, a 2-core machine under a load of 3) and
#: 105 s on a process-zone scene's 2301 nodes (2026-11-27). The Newton solves of the
#: relaxed start, of the protocol's first contact and march, and of the tip-following
#: mesh's re-equilibration read it too. What is left is one Newton iteration (a
#: factorization: a fraction of a second at 2500 nodes) and the LU of a re-meshing's
#: influence matrix. Scenes asked for 1e-3 with 5 s budgets ended 0.01-0.04 s past them on
#: 1038-1065 nodes (docs/numerics.md).
#: tests/engine/test_budget.py asserts it on the scene of issue 33 and on that scene.
CHECK_SLACK_S = 10.0


class OverBudget(RuntimeError):
    """The scene's time budget ran out; the message is the failed row's reason."""


def _deadline_of(seconds: float) -> float:
    return time.perf_counter() + seconds if seconds > 0 else math.inf


@contextmanager
def scene_budget(seconds: float):
    """The budget of one scene: ``seconds`` from now (0: none). Nested, the earlier deadline
    holds (a model run inside a scene never gets more time than the scene has left).

    Yields
    ------
    float
        The deadline (``time.perf_counter()`` seconds; ``inf`` without a budget).
    """
    outer = _BUDGET.get()
    mine = (_deadline_of(seconds), float(seconds))
    if outer is not None and outer[0] <= mine[0]:
        mine = outer
    token = _BUDGET.set(mine)
    try:
        yield mine[0]
    finally:
        _BUDGET.reset(token)


def deadline(seconds: float) -> float:
    """The deadline of the running scene, or ``seconds`` from now where no scene budget is
    open (a model's simulate function called directly); the earlier of the two otherwise."""
    own = _deadline_of(seconds)
    outer = _BUDGET.get()
    return own if outer is None else min(own, outer[0])


def remaining() -> float:
    """Seconds left of the running scene's budget (``inf`` without one)."""
    outer = _BUDGET.get()
    return math.inf if outer is None else outer[0] - time.perf_counter()


def budget_seconds(default: float = 0.0) -> float:
    """The running scene's budget in seconds (``default`` outside a scene)."""
    outer = _BUDGET.get()
    return default if outer is None else outer[1]


def check(where: str) -> None:
    """Raise :class:`OverBudget` naming ``where`` when the running scene's deadline passed."""
    outer = _BUDGET.get()
    if outer is not None and time.perf_counter() > outer[0]:
        raise OverBudget(f"time budget: {outer[1]:g} s spent in {where}; give it more "
                         f"(numerics time_budget_s) or cheaper numerics (preset fast, lower "
                         f"band_resolution)")


def arm(cache) -> None:
    """Give the Newton solves that use the Jacobian ``cache`` the running scene's deadline
    (none outside a scene): past it they give up (:func:`sweep.kernels.jacobian.set_deadline`)
    and the caller's :func:`check` after the failed solve raises :class:`OverBudget`."""
    set_deadline(cache, remaining())


#: the factorization count a solve may reach (:func:`work_cap`), None: no cap
_WORK_CAP: ContextVar[int | None] = ContextVar("work_cap", default=None)


class OverWork(Exception):
    """A solve under :func:`work_cap` did more factorizations than it was allowed; the
    message is its reason. Not a RuntimeError: no solver's numerical-failure handler takes
    it for its own, and it reaches the :func:`work_cap` block's caller."""


@contextmanager
def work_cap(factorizations: int | None):
    """Cap the factorizations of the solves run in this block (None: no cap): past it, the
    next :func:`check_work` raises :class:`OverWork`. Counts, not seconds: where a cap is met
    does not depend on the machine, so a row does not either."""
    token = _WORK_CAP.set(None if factorizations is None else int(factorizations))
    try:
        yield
    finally:
        _WORK_CAP.reset(token)


def check_work(factorizations: int, where: str) -> None:
    """Raise :class:`OverWork` where ``factorizations`` (a run's count so far, since the
    stage ``where`` started) exceed the running :func:`work_cap`."""
    cap = _WORK_CAP.get()
    if cap is not None and factorizations > cap:
        raise OverWork(f"{factorizations} factorizations in {where}, past the cap of {cap}")

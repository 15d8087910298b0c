"""A bug is not a result (issue 21 item 4): the engine reports numerical failures as failed
rows with a reason and lets programming errors (TypeError, IndexError, ...) raise."""
from __future__ import annotations

import numpy as np
import pytest

from sweep.engine import bem, crack_front, models
from sweep.errors import InputError, is_internal_error
from sweep.scene import Numerics, Scene

SCENE = Scene(n=0.8, k=0.5, mu=3.24, a0=1.5, rate=10.0)
FAST = Numerics.preset("fast")


@pytest.mark.parametrize("exc, internal", [
    (TypeError("x"), True), (IndexError("x"), True), (KeyError("x"), True),
    (AttributeError("x"), True), (ValueError("x"), True), (NotImplementedError("x"), True),
    (RecursionError("x"), True), (np.linalg.LinAlgError("singular"), False),
    (FloatingPointError("x"), False), (ZeroDivisionError("x"), False),
    (OverflowError("x"), False), (RuntimeError("no convergence"), False),
    (InputError("a0 must be >= 0.5"), False), (MemoryError(), False)])
def test_classification(exc, internal):
    assert is_internal_error(exc) is internal


def _raiser(exc):
    def run(*args, **kwargs):
        raise exc
    return run


def test_bem_bug_raises_numerical_failure_is_a_row(monkeypatch):
    monkeypatch.setattr(bem, "_simulate", _raiser(TypeError("'<=' not supported")))
    with pytest.raises(TypeError, match="not supported"):
        bem.simulate(SCENE, FAST)
    with pytest.raises(TypeError):
        models.simulate(SCENE, FAST)
    monkeypatch.setattr(bem, "_simulate", _raiser(np.linalg.LinAlgError("Singular matrix")))
    res = models.simulate(SCENE, FAST)
    assert res.status == "failed" and res.reason == "LinAlgError: Singular matrix"


def test_crack_front_bug_raises(monkeypatch):
    scene = Scene(n=0.8, k=0.5, mu=3.24, a0=1.5, rate=10.0, model="crack")
    monkeypatch.setattr(crack_front, "unload", _raiser(IndexError("list index out of range")))
    with pytest.raises(IndexError):
        models.simulate(scene, FAST)
    monkeypatch.setattr(crack_front, "unload", _raiser(InputError("a0 must be >= 0.5")))
    res = models.simulate(scene, FAST)
    assert res.status == "failed" and res.reason == "InputError: a0 must be >= 0.5"


def test_front_door_turns_numerical_errors_of_any_model_into_rows(monkeypatch):
    monkeypatch.setitem(models.MODELS, "pb", _raiser(OverflowError("math range error")))
    res = models.simulate(Scene(n=0.8, k=0.5, mu=3.24, a0=1.5, rate=10.0, model="pb"), FAST)
    assert (res.status, res.reason, res.model_used) == ("failed",
                                                        "OverflowError: math range error", "pb")
    monkeypatch.setitem(models.MODELS, "pb", _raiser(KeyError("gamma")))
    with pytest.raises(KeyError):
        models.simulate(Scene(n=0.8, k=0.5, mu=3.24, a0=1.5, rate=10.0, model="pb"), FAST)

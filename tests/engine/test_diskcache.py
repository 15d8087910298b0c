"""The on-disk cache (sweep.engine.diskcache) of Prony series: written once, read back identical,
never used across a change of the fitting code, harmless when damaged or switched off.
(The unit-spacing influence matrix's use of it: tests/test_mesh.py.)"""
import numpy as np
import pytest

from sweep.engine import diskcache
from sweep.engine import problem


@pytest.fixture
def cache(tmp_path, monkeypatch):
    monkeypatch.setenv(diskcache.CACHE_ENV, str(tmp_path))
    problem.prony_series.cache_clear()
    yield tmp_path
    problem.prony_series.cache_clear()


ARGS = ("mpl", 0.8, 0.1, 1e-4, 1e2, 1e-3)


def _same(a, b):
    np.testing.assert_array_equal(a.weights, b.weights)
    np.testing.assert_array_equal(a.times, b.times)
    assert (a.max_rel_error, a.rtol, a.converged, a.k, a.t_min, a.t_max) == \
        (b.max_rel_error, b.rtol, b.converged, b.k, b.t_min, b.t_max)


def test_prony_fit_is_cached_on_disk_and_read_back_identical(cache, monkeypatch):
    fitted = problem.prony_series(*ARGS)
    assert len(list(cache.glob("prony_*.npz"))) == 1
    problem.prony_series.cache_clear()                 # a new process: memory empty
    monkeypatch.setattr(problem, "material", lambda *a: pytest.fail("fitted again"))
    _same(problem.prony_series(*ARGS), fitted)
    # the series is the material's own fit (an independent fit, no cache involved)
    from sweep.materials import MPLRetardation
    _same(MPLRetardation(1.0, 10.0, 0.8, 1.0).prony(1e-4, 1e2, 1e-3), fitted)


def test_prony_cache_is_not_used_after_the_fitting_code_changed(cache, monkeypatch):
    problem.prony_series(*ARGS)
    problem.prony_series.cache_clear()
    monkeypatch.setattr(problem, "_materials_tag", lambda: "000000000000")
    calls = []
    real = problem.material
    monkeypatch.setattr(problem, "material", lambda *a: calls.append(a) or real(*a))
    problem.prony_series(*ARGS)
    assert len(calls) == 1 and len(list(cache.glob("prony_*.npz"))) == 2


def test_damaged_or_switched_off_cache_falls_back_to_fitting(cache, monkeypatch):
    fitted = problem.prony_series(*ARGS)
    (path,) = cache.glob("prony_*.npz")
    path.write_bytes(b"\x00garbage")
    problem.prony_series.cache_clear()
    _same(problem.prony_series(*ARGS), fitted)          # fitted again, file rewritten
    assert diskcache.load(path) is not None
    monkeypatch.setenv(diskcache.CACHE_ENV, "off")
    problem.prony_series.cache_clear()
    path.unlink()
    _same(problem.prony_series(*ARGS), fitted)
    assert not list(cache.glob("prony_*.npz"))

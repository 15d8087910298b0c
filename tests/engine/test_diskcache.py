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
#: the cache's files of Prony series and of relaxed starts
PRONY = f"prony_*{diskcache.RECORD_SUFFIX}"
RELAXED = f"relaxed_*{diskcache.RECORD_SUFFIX}"


def _same(a, b):
    np.testing.assert_array_equal(a.weights, b.weights)
    np.testing.assert_array_equal(a.times, b.times)
    assert (a.max_rel_error, a.rtol, a.converged, a.k, a.t_min, a.t_max) == \
        (b.max_rel_error, b.rtol, b.converged, b.k, b.t_min, b.t_max)


def test_prony_fit_is_cached_on_disk_and_read_back_identical(cache, monkeypatch):
    fitted = problem.prony_series(*ARGS)
    assert len(list(cache.glob(PRONY))) == 1
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
    assert len(calls) == 1 and len(list(cache.glob(PRONY))) == 2


def test_damaged_or_switched_off_cache_falls_back_to_fitting(cache, monkeypatch):
    fitted = problem.prony_series(*ARGS)
    (path,) = cache.glob(PRONY)
    path.write_bytes(b"\x00garbage")
    problem.prony_series.cache_clear()
    _same(problem.prony_series(*ARGS), fitted)          # fitted again, file rewritten
    assert diskcache.load(path) is not None
    monkeypatch.setenv(diskcache.CACHE_ENV, "off")
    problem.prony_series.cache_clear()
    path.unlink()
    _same(problem.prony_series(*ARGS), fitted)
    assert not list(cache.glob(PRONY))


# --- relaxed starts (sweep.engine.initial.cached_state) ---------------------------------

RELAXED_SCENE = dict(n=0.8, k=0.1, mu=3.24, a0=2.0, rate=10.0)


def _relaxed_run():
    from sweep import Numerics, Scene
    from sweep.engine import bem

    return bem.simulate(Scene(**RELAXED_SCENE), Numerics.preset("fast"))


def test_relaxed_start_is_kept_on_disk_and_read_back_bit_for_bit(cache, monkeypatch):
    """A relaxed start solved once is read back by a process that has not solved it (its
    memory cleared): the same gap, indentation and solver counters, so the row is the one
    solved (every number; the second method: the row of a run with the disk cache off)."""
    from sweep.engine import initial

    initial.clear_relaxed_cache()
    solved = _relaxed_run()
    files = sorted(cache.glob(RELAXED))
    assert files                                        # the row's solve and its estimate's
    initial.clear_relaxed_cache()                       # a new worker: memory empty
    monkeypatch.setattr(initial, "_solve_relaxed",
                        lambda *a, **kw: pytest.fail("solved again, not read from disk"))
    read = _relaxed_run()
    monkeypatch.undo()
    monkeypatch.setenv(diskcache.CACHE_ENV, "off")
    initial.clear_relaxed_cache()
    fresh = _relaxed_run()
    for res in (read, fresh):
        assert res.ok and (res.pull_off, res.delta0_result, res.a0_result, res.error_estimate,
                           res.newton_iterations, res.factorizations, res.steps) == \
            (solved.pull_off, solved.delta0_result, solved.a0_result, solved.error_estimate,
             solved.newton_iterations, solved.factorizations, solved.steps)
    np.testing.assert_array_equal(read.trajectory["P"], solved.trajectory["P"])
    np.testing.assert_array_equal(fresh.trajectory["P"], solved.trajectory["P"])
    initial.clear_relaxed_cache()


def test_relaxed_start_on_disk_checks_its_key_and_survives_damage(cache, monkeypatch):
    """A file of another key under the same name, a damaged file and another version of the
    engine's code are not read: the state is solved again (and the file rewritten)."""
    from sweep.engine import initial

    h = np.linspace(1.0, 2.0, 5)
    initial.cached_state(("a", 1.0), lambda: (h, 0.5))
    (path,) = cache.glob(RELAXED)
    initial.clear_relaxed_cache()
    assert initial._from_disk(("a", 1.0))[1] == 0.5
    moved = diskcache.record_path("relaxed", initial._code_tag, ("b", 2.0))
    path.rename(moved)                                  # a digest collision, as it were
    assert initial._from_disk(("b", 2.0)) is None
    moved.write_bytes(b"\x00garbage")
    assert initial._from_disk(("b", 2.0)) is None
    calls = []
    h2, d2 = initial.cached_state(("b", 2.0), lambda: calls.append(1) or (2.0 * h, 0.25))
    assert calls == [1] and d2 == 0.25 and initial._from_disk(("b", 2.0))[1] == 0.25
    initial.clear_relaxed_cache()
    monkeypatch.setattr(initial, "_code_tag", lambda: "000000000000")
    assert initial._from_disk(("b", 2.0)) is None       # solved by other code: not used
    initial.clear_relaxed_cache()


def test_a_record_file_reads_back_every_array_to_the_bit(tmp_path):
    """diskcache's record format (a .rec path): floats, integers, booleans, strings, 0-d and
    2-d arrays come back equal to the bit, with their dtypes and shapes, and writable."""
    arrays = {"h": np.random.default_rng(0).standard_normal(37),
              "m": np.arange(12, dtype=np.int64).reshape(3, 4), "flag": np.array(True),
              "key": np.array(repr(("graded", 0.1, (1, 2)))), "x": np.array(1e-300),
              "empty": np.zeros(0)}
    path = tmp_path / f"a{diskcache.RECORD_SUFFIX}"
    assert diskcache.save(path, arrays)
    got = diskcache.load(path)
    assert list(got) == list(arrays)
    for name, a in arrays.items():
        assert got[name].dtype == a.dtype and got[name].shape == a.shape, name
        np.testing.assert_array_equal(got[name], a)
        assert got[name].flags.writeable
    assert got["h"].tobytes() == arrays["h"].tobytes()


@pytest.mark.parametrize("damage", ["truncate", "extend", "magic", "header"])
def test_a_damaged_record_reads_as_missing(tmp_path, damage):
    """A record cut short, grown, with another first line or a garbled layout reads as
    None (the cache then computes the entry again); object arrays are never written."""
    path = tmp_path / f"a{diskcache.RECORD_SUFFIX}"
    assert diskcache.save(path, {"h": np.arange(5.0), "key": np.array("k")})
    raw = path.read_bytes()
    first = raw.index(b"\n") + 1
    damaged = {"truncate": raw[:-3], "extend": raw + b"\x00",
               "magic": b"x" + raw[1:],
               "header": raw[:first] + b'[["h","<zz",[5],40]]' + raw[raw.index(b"\n", first):]}
    path.write_bytes(damaged[damage])
    assert diskcache.load(path) is None
    with pytest.raises(ValueError, match="object"):
        diskcache._record_bytes({"o": np.array([object()])})


def test_a_failed_relaxed_start_is_kept_and_fails_again_without_solving(cache):
    """A start that fails is as much a function of its key as a state: kept in memory and on
    disk with its reason and counters, it raises again at once (the solver's counters grow by
    what the failed solve counted, as if it ran); a start stopped by the time budget is not
    kept."""
    from sweep.engine import budget, initial
    from sweep.kernels.solve import N_STATS

    initial.clear_relaxed_cache()
    calls = []

    def failing(stats):
        def solve():
            calls.append(1)
            stats[0] += 7                               # what the solver counted
            raise RuntimeError("no converged relaxed state at delta0=9.7")
        return solve

    for memory in (True, True, False):                  # solved, then memory, then disk
        if not memory:
            initial.clear_relaxed_cache()
        stats = np.zeros(N_STATS, dtype=np.int64)
        with pytest.raises(RuntimeError, match="no converged relaxed state at delta0=9.7"):
            initial.cached_state(("fail", 1.0), failing(stats), stats)
        assert stats[0] == 7
    assert calls == [1] and len(list(cache.glob(RELAXED))) == 1
    assert initial._from_disk(("fail", 1.0))[:2] == (None, "no converged relaxed state at "
                                                           "delta0=9.7")

    def over_budget():
        calls.append(2)
        raise budget.OverBudget("time budget")
    for _ in range(2):
        with pytest.raises(budget.OverBudget):
            initial.cached_state(("slow", 1.0), over_budget)
    assert calls == [1, 2, 2] and len(list(cache.glob(RELAXED))) == 1
    initial.clear_relaxed_cache()

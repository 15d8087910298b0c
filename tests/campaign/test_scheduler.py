"""The scheduler: joblib/loky and dask backends, streaming writes, resume, worker set-up.

Most tests inject a cheap module-level ``simulate`` (it pickles to workers by reference);
``test_real_solver_sequential_and_parallel_agree`` runs the real solver on tiny scenes.
"""
from __future__ import annotations

import io
import json
import math
import os
import time

import numpy as np
import pytest

from sweep.campaign import scheduler
from sweep.campaign.config import config_from_dict
from sweep.errors import InputError
from sweep.scene import Numerics, Result, Scene
from sweep.campaign.scheduler import Progress, SweepRuntimeError, run_scene, run_sweep
from sweep.engine.bem import simulate
from sweep.campaign.store import load, load_trajectory, parts_dir, read_attrs

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def fake_simulate(scene, numerics):
    """Deterministic stand-in for the solver: a short sleep, fails for n > 1 at high rates."""
    time.sleep(0.05)
    if scene.n > 1 and scene.rate > 50:
        return Result(scene=scene, numerics=numerics, status="failed", reason="fake: no pull-off")
    t = np.linspace(0.0, 1.0, 5)
    return Result(scene=scene, numerics=numerics, status="ok",
                  pull_off=scene.n * math.log10(scene.rate + 1.0) + 1.0, steps=4, wall_s=0.05,
                  trajectory={"t": t, "delta": -t, "P": -t * scene.n, "a": 2 - t,
                              "a_inner": 1.5 - t})


def sleepy_simulate(scene, numerics):
    """A scene that takes two minutes; it first writes its process id into the directory
    ``$SWEEP_TEST_PID_DIR`` (the test of orphaned workers finds the workers there)."""
    d = os.environ["SWEEP_TEST_PID_DIR"]
    with open(os.path.join(d, f"{os.getpid()}.pid"), "w") as fh:
        fh.write(str(os.getpid()))
    for _ in range(1200):
        time.sleep(0.1)
    return fake_simulate(scene, numerics)


def raising_simulate(scene, numerics):
    if scene.n > 1:
        raise ZeroDivisionError("boom\nsecond line")
    return fake_simulate(scene, numerics)


def thread_probe(scene, numerics):
    """Report the worker's thread settings in the reason field."""
    import numba

    info = {v: os.environ.get(v) for v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS",
                                           "MKL_NUM_THREADS", "NUMBA_NUM_THREADS")}
    info["numba"] = numba.config.NUMBA_NUM_THREADS
    info["pid"] = os.getpid()
    return Result(scene=scene, numerics=numerics, status="ok", reason=json.dumps(info))


def cfg(n=(0.4, 1.6), rate=(1, 100), a0=2.0, trajectories=False, name="t", nodes=60):
    return config_from_dict({"name": name, "grid": {"n": list(n), "rate": list(rate), "a0": a0},
                             "numerics": {"preset": "fast", "nodes": nodes},
                             "store": {"trajectories": trajectories}})


def test_loky_two_workers_all_rows(tmp_path):
    c = cfg(n=(0.4, 0.8, 1.6), rate=(1, 10, 100), trajectories=True)
    out = tmp_path / "r.h5"
    rep = run_sweep(c, jobs=2, out=out, simulate=fake_simulate, progress="none")
    assert (rep.total, rep.ran, rep.skipped, rep.failed) == (9, 9, 0, 1)
    df = load(out)
    assert sorted(df.scene_id) == sorted(sid for sid, _ in c.tasks())
    assert df["worker"].nunique() == 2                # both processes did work
    assert (df["task_wall_s"] >= 0.05).all()
    bad = df[df.status == "failed"]
    assert list(bad.reason) == ["fake: no pull-off"] and np.isnan(bad.pull_off).all()
    ok = df[df.status == "ok"].iloc[0]
    np.testing.assert_allclose(ok.pull_off, ok.n * math.log10(ok.rate + 1) + 1)
    assert len(load_trajectory(out, ok.scene_id)["P"]) == 5
    assert not parts_dir(out).exists() and read_attrs(out)["complete"]


def test_rerun_skips_everything_and_keeps_file(tmp_path):
    c, out = cfg(), tmp_path / "r.h5"
    run_sweep(c, jobs=1, out=out, simulate=fake_simulate, progress="none")
    before = load(out)
    mtime = os.stat(out).st_mtime_ns
    rep = run_sweep(c, jobs=2, out=out, simulate=raising_simulate, progress="none")
    assert (rep.ran, rep.skipped) == (0, 4)
    assert os.stat(out).st_mtime_ns == mtime          # nothing to do: file not rewritten
    assert load(out).equals(before)


def test_interrupted_sweep_resumes_without_rerunning(tmp_path):
    c = cfg(n=(0.4, 0.6, 0.8), rate=(1, 3, 10, 30))
    out = tmp_path / "r.h5"
    seen = []

    def stop_after_five(info):
        seen.append(info["row"]["scene_id"])
        if info["done"] == 5:
            raise RuntimeError("simulated crash of the parent loop")
    with pytest.raises(SweepRuntimeError, match="after 5 of 12 scenes.*run the same command"):
        run_sweep(c, jobs=2, out=out, simulate=fake_simulate, progress=stop_after_five)
    # the five it saw, and any other scene a worker had finished (sweep.campaign.spool)
    kept = set(load(out).scene_id)
    assert set(seen) <= kept and len(load(out)) == len(kept)
    rest = []
    rep = run_sweep(c, jobs=2, out=out, simulate=fake_simulate,
                    progress=lambda info: rest.append(info["row"]["scene_id"]))
    assert (rep.ran, rep.skipped) == (12 - len(kept), len(kept))
    assert not set(rest) & kept
    assert sorted(load(out).scene_id) == sorted(sid for sid, _ in c.tasks())


def test_exception_in_a_scene_is_an_internal_error(tmp_path):
    """A bug is not a result: an exception escaping simulate is status "error" (not counted
    as failed), logged with its traceback beside the results; the other scenes are stored."""
    out = tmp_path / "r.h5"
    rep = run_sweep(cfg(), jobs=2, out=out, simulate=raising_simulate, progress="none")
    df = load(out)
    assert (rep.failed, rep.errors, len(df)) == (0, 2, 4)
    bad = df[df.n > 1]
    assert (bad.status == "error").all() and (df[df.n < 1].status == "ok").all()
    assert all(r == "internal error ZeroDivisionError: boom second line" for r in bad.reason)
    assert (bad.wall_s > 0).all()
    assert "_traceback" not in df.columns
    assert sorted(rep.error_ids) == sorted(bad.scene_id)
    assert rep.error_log == tmp_path / "r.h5.errors.log"
    log = rep.error_log.read_text()
    for sid in bad.scene_id:
        assert f"scene {sid} model bem" in log
    assert log.count("Traceback (most recent call last)") == 2
    assert "ZeroDivisionError: boom" in log and "raising_simulate" in log
    assert rep.error_line() == f"2 scenes hit an internal error (a bug, not a result; " \
                               f"status \"error\"), see {rep.error_log}"


def typeerror_simulate(scene, numerics):
    """The real front door, with a bug in one scene's path (n > 1 at rate 100)."""
    if scene.n > 1 and scene.rate > 50:
        return None + 1
    return fake_simulate(scene, numerics)


def test_typeerror_in_one_scene_sequential(tmp_path):
    out = tmp_path / "r.h5"
    rep = run_sweep(cfg(), jobs=1, out=out, simulate=typeerror_simulate, progress="none")
    df = load(out).set_index("n")
    assert (rep.ran, rep.failed, rep.errors) == (4, 0, 1)
    err = df[df.status == "error"]
    assert len(err) == 1 and err.reason.iloc[0].startswith("internal error TypeError: ")
    assert (df[df.status == "ok"].pull_off > 0).all() and (df.status == "ok").sum() == 3
    assert "TypeError" in (tmp_path / "r.h5.errors.log").read_text()


def test_fresh_moves_the_error_log_aside_with_its_file(tmp_path):
    """--fresh moves the old file to .bak: its internal errors' log goes with it, so the new
    file's log holds only the new file's errors."""
    out = tmp_path / "r.h5"
    run_sweep(cfg(), jobs=1, out=out, simulate=typeerror_simulate, progress="none")
    assert "TypeError" in (tmp_path / "r.h5.errors.log").read_text()
    rep = run_sweep(cfg(), jobs=1, out=out, simulate=fake_simulate, progress="none",
                    resume=False)
    assert rep.errors == 0 and not (tmp_path / "r.h5.errors.log").exists()
    assert "TypeError" in (tmp_path / "r.h5.bak.errors.log").read_text()
    assert (load(tmp_path / "r.h5.bak").status == "error").sum() == 1


def test_a_grid_over_n_crossed_with_sls_says_its_copies(tmp_path):
    import io

    stream = io.StringIO()
    run_sweep({"name": "x", "grid": {"material": ["mpl", "sls"], "n": [0.4, 0.8],
                                     "rate": 1, "a0": 2.0}},
              jobs=1, out=tmp_path / "r.h5", simulate=fake_simulate, progress="log",
              stream=stream)
    said = [ln for ln in stream.getvalue().splitlines() if ln.startswith("note:")]
    assert len(said) == 1 and said[0].startswith("note: 1 of the scenes differ from another "
                                                 "only in n")


def test_no_error_log_without_errors(tmp_path):
    rep = run_sweep(cfg(), jobs=1, out=tmp_path / "r.h5", simulate=fake_simulate,
                    progress="none")
    assert rep.errors == 0 and rep.error_log is None and rep.error_line() == ""
    assert not (tmp_path / "r.h5.errors.log").exists()


def test_one_thread_per_worker(tmp_path, monkeypatch):
    for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS",
                "NUMBA_NUM_THREADS"):
        monkeypatch.delenv(var, raising=False)         # not inherited from `make test`
    out = tmp_path / "r.h5"
    run_sweep(cfg(), jobs=2, out=out, simulate=thread_probe, progress="none")
    infos = [json.loads(r) for r in load(out).reason]
    assert all(i["pid"] != os.getpid() for i in infos)  # ran in worker processes
    for info in infos:
        assert info["OMP_NUM_THREADS"] == info["NUMBA_NUM_THREADS"] == "1", info
        assert info["OPENBLAS_NUM_THREADS"] == info["MKL_NUM_THREADS"] == "1", info
        assert info["numba"] == 1, info


def _warm_up_calls(monkeypatch, kernels_loaded: bool, scenes: int) -> list:
    """run_scene ``scenes`` times in this process as a fresh worker would (the parent having
    loaded the kernels before forking it, or not); the warm_up calls it made."""
    import sweep.engine.bem as solver
    calls = []
    monkeypatch.setattr(solver, "warm_up", lambda: calls.append(1) or 0.0, raising=False)
    monkeypatch.setattr(solver, "simulate", fake_simulate)
    monkeypatch.setattr(scheduler, "_WORKER_READY", False)
    monkeypatch.setattr(scheduler, "_KERNELS_LOADED", kernels_loaded)
    for var in scheduler.THREAD_VARS:                   # run_scene sets these if unset
        monkeypatch.setenv(var, os.environ.get(var, "1"))
    for _ in range(scenes):
        row, traj = run_scene(Scene(n=0.4, rate=1, a0=2), Numerics.preset("fast"))
        assert row["status"] == "ok" and traj is None
    return calls


def test_worker_warms_numba_cache_once(monkeypatch):
    assert _warm_up_calls(monkeypatch, kernels_loaded=False, scenes=3) == [1]


def test_a_forked_worker_does_not_load_the_kernels_its_parent_loaded(monkeypatch):
    """A worker forked after the parent's warm-up (_KERNELS_LOADED inherited) loads nothing."""
    assert _warm_up_calls(monkeypatch, kernels_loaded=True, scenes=2) == []


def test_a_grid_without_bem_scenes_compiles_no_kernels_on_a_cold_cache(monkeypatch):
    """On a cold Numba cache the parent warms (compiles) the BEM kernels only where a scene
    needs them: model bem (not the elastic branch), or auto choosing the BEM; a crack-front
    or PB grid compiles nothing, and its workers are told not to. On a warm cache it loads
    them where the scenes run in this process, and leaves them to the workers where they
    run there."""
    import sweep.engine.bem as solver
    calls, cached = [], [False]
    monkeypatch.setattr(solver, "warm_up", lambda: calls.append(1) or 0.0)
    monkeypatch.setattr(solver, "kernels_cached", lambda: cached[0])
    num = Numerics.preset("balanced")
    crack = [Scene(n=0.8, k=0.1, mu=3.24, a0=2.0, rate=r, model="crack") for r in (1, 100)]
    pb = [Scene(n=0.8, k=0.1, mu=3.24, a0=2.0, rate=1.0, model="pb")]
    elastic = [Scene(n=0.8, k=1.0, mu=3.24, a0=2.0, rate=1.0)]       # bem -> elastic branch
    far = [Scene(n=0.8, k=0.1, mu=1e4, a0=2.0, rate=1.0, model="auto")]  # auto -> crack
    bem = [Scene(n=0.8, k=0.1, mu=3.24, a0=2.0, rate=1.0)]
    auto_bem = [Scene(n=0.8, k=0.1, mu=3.24, a0=2.0, rate=1.0, model="auto")]
    assert not scheduler._warm_parent(None, crack + pb + elastic + far, num) and calls == []
    assert scheduler._warm_parent(None, crack + bem, num) and calls == [1]
    assert scheduler._warm_parent(None, pb + auto_bem, num) and calls == [1, 1]
    cached[0] = True
    assert scheduler._warm_parent(None, crack, num) and calls == [1, 1, 1]
    # a current cache, the scenes in workers: they load the kernels, the parent does not
    assert scheduler._warm_parent(None, bem, num, in_workers=True) and calls == [1, 1, 1]
    cached[0] = False          # a cold cache is compiled once, in the parent, all the same
    assert scheduler._warm_parent(None, bem, num, in_workers=True) and calls == [1, 1, 1, 1]


def test_dask_local_cluster_matches_loky(tmp_path):
    distributed = pytest.importorskip("distributed")
    c = cfg(n=(0.4, 0.8, 1.6), rate=(1, 100))
    run_sweep(c, jobs=2, out=tmp_path / "loky.h5", simulate=fake_simulate, progress="none")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        rep = run_sweep(c, backend="dask", scheduler=cluster.scheduler_address,
                        out=tmp_path / "dask.h5", simulate=fake_simulate, progress="none")
    assert rep.ran == 6
    a = load(tmp_path / "loky.h5").set_index("scene_id").sort_index()
    b = load(tmp_path / "dask.h5").set_index("scene_id").sort_index()
    assert list(a.index) == list(b.index)
    np.testing.assert_array_equal(a.pull_off.values, b.pull_off.values)
    assert b.worker.nunique() == 2
    assert not set(a.worker) & set(b.worker)


def test_unreachable_scheduler_fails_fast_and_writes_nothing(tmp_path):
    out = tmp_path / "sub" / "r.h5"
    t0 = time.monotonic()
    with pytest.raises(SweepRuntimeError, match="cannot connect to the dask scheduler at "
                                                "tcp://127.0.0.1:1"):
        run_sweep(cfg(), backend="dask", scheduler="tcp://127.0.0.1:1", out=out,
                  simulate=fake_simulate, connect_timeout=1.0, progress="none")
    assert time.monotonic() - t0 < 15
    assert not out.exists() and not parts_dir(out).exists()
    assert not (out.parent / "r.h5.lock").exists()


@pytest.mark.parametrize("kw, needle", [
    ({"backend": "spark"}, "backend must be one of local, loky, dask"),
    ({"jobs": 0}, "jobs must be an integer in [1, 4096]"),
    ({"scheduler": "tcp://x:1"}, "only used with backend dask"),
    ({"progress": "fancy"}, "progress must be one of"),
    # a malformed address: one line at once (it had waited out the timeout, then 20 s of
    # dask's client cleanup, with a traceback)
    ({"backend": "dask", "scheduler": "notanaddress"},
     "scheduler must be an address such as tcp://host:8786, host and port (got "
     "'notanaddress')"),
    ({"backend": "dask", "scheduler": "tcp://host/8786"}, "scheduler must be an address"),
])
def test_bad_options(tmp_path, kw, needle):
    with pytest.raises(InputError) as info:
        run_sweep(cfg(), out=tmp_path / "r.h5", simulate=fake_simulate, **kw)
    assert needle in str(info.value)
    assert not (tmp_path / "r.h5").exists()


@pytest.mark.parametrize("address", ["tcp://127.0.0.1:8786", "node7:8786", "tls://a.b.org:1",
                                     "[::1]:8786", "tcp://[fe80::1]:8786", "inproc://10.0.0.1/1/2"])
def test_a_dask_address_is_checked_before_connecting(address):
    assert scheduler.check_scheduler_address(address) == address


def test_one_job_runs_in_this_process(tmp_path):
    """-j 1 runs the scenes in the sweep's own process: the first line says so (it had said
    "on 1 loky worker")."""
    buf = io.StringIO()
    run_sweep(cfg(), jobs=1, out=tmp_path / "r.h5", simulate=fake_simulate, progress="log",
              stream=buf)
    first = buf.getvalue().splitlines()[0]
    assert "4 to run in this process ->" in first, first


def test_unwritable_output(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    with pytest.raises(InputError, match="cannot create directory"):
        run_sweep(cfg(), out=blocker / "r.h5", simulate=fake_simulate)
    with pytest.raises(InputError, match="is a directory"):
        run_sweep(cfg(), out=tmp_path, simulate=fake_simulate)


def test_progress_bar_and_log_lines():
    buf = io.StringIO()
    p = Progress("bar", total=40, already=10, stream=buf)
    p.start()
    p.update({"scene_id": "a", "status": "ok"})
    p.update({"scene_id": "b", "status": "failed"})
    p.close()
    text = buf.getvalue()
    # a tqdm bar: starts at the scenes already done, counts failures, ends with a newline
    assert "10/40" in text and "12/40" in text and "1 failed" in text and text.endswith("\n")
    class Tty(io.StringIO):
        def isatty(self):
            return True
    assert Progress("auto", total=3, already=0, stream=Tty()).mode == "bar"
    buf = io.StringIO()
    p = Progress("auto", total=3, already=0, stream=buf)   # not a TTY -> log lines
    assert p.mode == "log"
    p.update({"scene_id": "abc", "status": "ok", "pull_off": 1.23456789, "wall_s": 0.5})
    p.update({"scene_id": "def", "status": "failed", "pull_off": math.nan, "wall_s": 0.25,
              "reason": "why"})
    p.update({"scene_id": "ghi", "status": "ok", "pull_off": 2.0, "wall_s": 0.5, "n": 0.8,
              "k": 0.5, "mu": 3.24, "a0": math.nan, "delta0": 1.5, "rate": 1e6,
              "material": "sls", "model": "bem"})
    lines = buf.getvalue().splitlines()
    assert lines == ["[1/3] abc ok pull_off=1.2346 wall=0.5s",
                     "[2/3] def failed pull_off=nan wall=0.25s reason: why",
                     "[3/3] ghi ok n=0.8 k=0.5 mu=3.24 delta0=1.5 rate=1e+06 material=sls "
                     "pull_off=2 wall=0.5s"]


def test_real_solver_sequential_and_parallel_agree(tmp_path):
    """The real solver through both paths (fast preset, small mesh): identical rows, and
    the values of a direct simulate() (60 nodes would be refused as unresolved)."""
    c = cfg(n=(0.4, 1.6), rate=(1, 100), nodes=200)
    r1 = run_sweep(c, jobs=1, out=tmp_path / "j1.h5", progress="none")
    r2 = run_sweep(c, jobs=2, out=tmp_path / "j2.h5", progress="none")
    assert r1.ran == r2.ran == 4
    a = load(tmp_path / "j1.h5").set_index("scene_id").sort_index()
    b = load(tmp_path / "j2.h5").set_index("scene_id").sort_index()
    assert list(a.status) == list(b.status)
    assert (a.status == "ok").all(), a[["n", "rate", "status", "reason"]]
    np.testing.assert_array_equal(a.pull_off.values, b.pull_off.values)
    np.testing.assert_array_equal(a.steps.values, b.steps.values)
    sid, scene = c.tasks()[0]
    direct = simulate(scene, c.numerics)
    assert a.loc[sid, "pull_off"] == direct.pull_off and a.loc[sid, "steps"] == direct.steps
    assert a.loc[sid, "error_estimate"] < c.numerics.pull_off_rtol


def crashing_simulate(scene, numerics):
    """Kills its worker process outright for one scene (like a segfault)."""
    if scene.n > 1 and scene.rate > 50:
        time.sleep(0.3)                                  # let the other scenes finish first
        os._exit(3)
    return fake_simulate(scene, numerics)


def test_worker_crash_stops_sweep_keeps_results(tmp_path):
    c = cfg(n=(0.4, 0.8, 1.6), rate=(1, 100))
    out = tmp_path / "r.h5"
    with pytest.raises(SweepRuntimeError, match="sweep stopped after .* run the same command"):
        run_sweep(c, jobs=2, out=out, simulate=crashing_simulate, progress="none")
    df = load(out)
    assert 1 <= len(df) <= 5
    assert not ((df.n > 1) & (df.rate > 50)).any()       # the crashed scene has no row
    assert not parts_dir(out).exists()                   # consolidated before stopping
    rep = run_sweep(c, jobs=2, out=out, simulate=fake_simulate, progress="none")
    assert rep.skipped == len(df) and rep.ran == 6 - len(df)
    assert len(load(out)) == 6


def _alive(pid: int) -> bool:
    """Whether process ``pid`` runs (a zombie, waiting to be reaped, does not)."""
    try:
        with open(f"/proc/{pid}/status") as fh:
            return not any(line.startswith("State:") and "Z" in line.split()[1] for line in fh)
    except FileNotFoundError:
        return False


_PARENT = """
import sys
from sweep.campaign.scheduler import run_sweep
from tests.campaign.test_scheduler import cfg, sleepy_simulate
run_sweep(cfg(), jobs=2, out=sys.argv[1], simulate=sleepy_simulate, progress="none")
"""


@pytest.mark.skipif(not os.path.isdir("/proc/self"), reason="reads /proc (Linux)")
def test_a_killed_sweep_leaves_no_worker(tmp_path):
    """SIGKILL the process of a running sweep: its loky workers, busy with two-minute
    scenes, end within seconds (sweep.threads.exit_with_parent) instead of computing on,
    orphaned (issue 33 item 3). 30 s allowed; without the watch they live 120 s."""
    import signal
    import subprocess
    import sys

    pids_dir = tmp_path / "pids"
    pids_dir.mkdir()
    env = dict(os.environ, SWEEP_TEST_PID_DIR=str(pids_dir),
               PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))
    parent = subprocess.Popen([sys.executable, "-c", _PARENT, str(tmp_path / "r.h5")],
                              env=env, cwd=ROOT)
    try:
        t0 = time.monotonic()
        while len(list(pids_dir.glob("*.pid"))) < 2:
            assert parent.poll() is None, "the sweep ended before its workers started"
            assert time.monotonic() - t0 < 240, "the workers did not start"
            time.sleep(0.2)
        workers = [int(p.stem) for p in pids_dir.glob("*.pid")]
        assert parent.pid not in workers
        os.kill(parent.pid, signal.SIGKILL)
        parent.wait()
        t0 = time.monotonic()
        while any(_alive(w) for w in workers) and time.monotonic() - t0 < 30:
            time.sleep(0.2)
        left = [w for w in workers if _alive(w)]
    finally:
        if parent.poll() is None:
            parent.kill()
        for w in [int(p.stem) for p in pids_dir.glob("*.pid")]:
            if _alive(w):
                os.kill(w, signal.SIGKILL)
    assert not left, f"workers {left} outlived their killed sweep by 30 s"


def test_dask_without_address_starts_local_cluster(tmp_path):
    pytest.importorskip("distributed")
    out = tmp_path / "r.h5"
    rep = run_sweep(cfg(), backend="dask", jobs=2, out=out, simulate=fake_simulate,
                    progress="none")
    assert rep.ran == 4 and load(out).worker.nunique() >= 1
    assert all(w.split(":")[1] != str(os.getpid()) for w in load(out).worker)


def test_consolidation_interval(tmp_path):
    """With a zero interval the main file follows every scene; with a long one only the end."""
    for interval, expect_mid in ((0.0, True), (1e6, False)):
        out = tmp_path / f"r{interval}.h5"
        sizes = []

        def watch(info, out=out):
            import h5py
            with h5py.File(out, "r") as f:
                sizes.append(len(f["runs/scene_id"]))
        run_sweep(cfg(n=(0.4, 0.6, 0.8), rate=(1, 10)), jobs=1, out=out,
                  simulate=fake_simulate, progress=watch, consolidate_every=interval)
        assert (max(sizes) > 0) is expect_mid, sizes
        assert len(load(out)) == 6


def test_grid_is_expanded_and_hashed_once_per_run(tmp_path, monkeypatch):
    import sweep.campaign.config as config_module
    calls = []
    real = config_module.scene_id
    monkeypatch.setattr(config_module, "scene_id", lambda s, n: calls.append(1) or real(s, n))
    c = cfg()
    rep = run_sweep(c, jobs=1, out=tmp_path / "r.h5", simulate=fake_simulate, progress="none")
    assert rep.total == len(calls) == 4


def test_dispatch_order_runs_the_largest_scenes_first():
    """Longest-processing-time first: a permutation of the grid, ordered by the cost
    estimate (larger initial contact, then slower rate, first); the estimate follows the
    campaign's measured costs (a0 = 8 about 16x a0 = 2, rate 1 about 3x rate 1e6)."""
    num = Numerics.preset("fast")
    todo = [(f"s{i}", Scene(n=0.8, k=0.1, mu=3.24, a0=a0, rate=rate))
            for i, (a0, rate) in enumerate([(1.0, 1e6), (8.0, 1e6), (2.0, 1.0), (8.0, 1.0),
                                            (4.0, 10.0), (1.0, 1.0)])]
    ordered = scheduler.dispatch_order(todo, num)
    assert sorted(sid for sid, _ in ordered) == sorted(sid for sid, _ in todo)
    assert [sid for sid, _ in ordered][:2] == ["s3", "s1"]
    assert ordered[-1][0] == "s0"
    costs = [scheduler.estimated_cost(s, num) for _, s in ordered]
    assert costs == sorted(costs, reverse=True)
    big = scheduler.estimated_cost(Scene(n=0.8, k=0.1, mu=3.24, a0=8.0, rate=1e6), num)
    small = scheduler.estimated_cost(Scene(n=0.8, k=0.1, mu=3.24, a0=2.0, rate=1e6), num)
    assert 5.0 < big / small < 50.0
    # a scene given by its indentation is sized from the JKR estimate of its contact radius
    deep = scheduler.estimated_cost(Scene(n=0.8, k=0.1, mu=3.24, delta0=11.0, rate=1.0), num)
    shallow = scheduler.estimated_cost(Scene(n=0.8, k=0.1, mu=3.24, delta0=1.0, rate=1.0), num)
    assert deep > shallow > 0.0


def test_dispatch_chunks_keep_start_groups_together_and_balance():
    """Each chunk holds scenes of one start group (one relaxed start per chunk), the chunks
    are a permutation of the grid, no chunk exceeds its scene cap or (unless it is one
    scene) a quarter of a worker's share of the cost, and they run largest first."""
    num = Numerics.preset("fast")
    todo = [(f"s{i}", Scene(n=n, k=0.1, mu=3.24, a0=a0, rate=rate))
            for i, (n, a0, rate) in enumerate(
                (n, a0, rate) for n in (0.4, 0.8) for a0 in (1.0, 2.0, 8.0)
                for rate in (1.0, 10.0, 1e2, 1e3, 1e4, 1e6))]
    chunks = scheduler.dispatch_chunks(todo, num, n_jobs=2)
    flat = [sid for chunk in chunks for sid, _ in chunk]
    assert sorted(flat) == sorted(sid for sid, _ in todo)
    assert all(len({scheduler.start_group(s) for _, s in chunk}) == 1 for chunk in chunks)
    cost = {sid: scheduler.estimated_cost(s, num) for sid, s in todo}
    cap = scheduler.CHUNK_COST_FRACTION * sum(cost.values()) / 2
    totals = [sum(cost[sid] for sid, _ in chunk) for chunk in chunks]
    assert all(t <= cap * (1 + 1e-12) or len(c) == 1 for t, c in zip(totals, chunks))
    assert all(len(c) <= scheduler.CHUNK_SCENES for c in chunks)
    assert totals == sorted(totals, reverse=True)
    # the three a0 = 8 groups' scenes are the largest: the first chunk is one of them
    assert chunks[0][0][1].a0 == 8.0
    # fewer chunks than scenes: small groups travel together
    assert len(chunks) < len(todo)
    assert scheduler.dispatch_chunks([], num, 2) == []


def test_resume_runs_the_scenes_that_hit_an_internal_error_again(tmp_path):
    """After the bug is fixed, the same command reruns only the "error" scenes; their rows
    are replaced, the log of the first run is kept."""
    out = tmp_path / "r.h5"
    first = run_sweep(cfg(), jobs=1, out=out, simulate=raising_simulate, progress="none")
    assert first.errors == 2
    again = run_sweep(cfg(), jobs=1, out=out, simulate=fake_simulate, progress="none")
    assert (again.ran, again.skipped, again.errors) == (2, 2, 0)
    df = load(out)
    assert len(df) == 4 and set(df.status) <= {"ok", "failed"}
    assert (tmp_path / "r.h5.errors.log").read_text().count("ZeroDivisionError: boom") == 2


def _fake_simulate(scene, numerics):
    from sweep.scene import Result
    return Result(scene=scene, numerics=numerics, status="ok", pull_off=scene.n + scene.rate)


def test_a_log10_grid_is_correctly_rounded():
    """Its powers of ten are the correctly rounded ones (exact decimal arithmetic), so that a
    config gives the same scenes (and ids) on every machine: numpy's logspace gave
    10^2.5 = 316.2277660168379 on one machine, 316.22776601683796 on another."""
    from decimal import Decimal, localcontext

    from sweep.campaign.config import powers_of_ten

    values = powers_of_ten(-1.0, 8.0, 19)
    with localcontext() as ctx:
        ctx.prec = 60
        for i, v in enumerate(values):
            exact = Decimal(10) ** (Decimal(-1) + Decimal(i) / 2)
            below, above = np.nextafter(v, 0.0), np.nextafter(v, np.inf)
            assert abs(Decimal(v) - exact) <= abs(Decimal(below) - exact)
            assert abs(Decimal(v) - exact) <= abs(Decimal(above) - exact)
    assert values[7] == 316.22776601683796 and values[2] == 1.0 and values[-1] == 1e8


@pytest.mark.parametrize("form", ["yaml", "dict"])
def test_a_file_whose_grid_came_out_otherwise_resumes(tmp_path, monkeypatch, form):
    """A file written where the log10 grid's powers of ten came out one unit in the last place
    otherwise (another machine's numpy, before they were correctly rounded) resumes under the
    same config, a YAML file's (the same text) or a mapping's: its scenes count as the
    config's, none runs again, nothing is lost, and a scene the config adds still runs."""
    import yaml

    from sweep.campaign import config as config_module
    from sweep.campaign.store import load, read_attrs

    spec = {"name": "g", "grid": {"n": [0.4, 0.8], "rate": {"log10": [0, 2, 5]}, "a0": 2.0},
            "numerics": {"preset": "fast", "nodes": 60}}
    path = tmp_path / "g.yaml"
    path.write_text(yaml.safe_dump(spec))

    def config(s=spec):
        return config_module.as_config(path) if form == "yaml" and s is spec else \
            config_module.config_from_dict(s)

    right = config_module.powers_of_ten
    monkeypatch.setattr(config_module, "powers_of_ten", lambda *a: [
        float(np.nextafter(v, np.inf)) if v != round(v) else v for v in right(*a)])
    old = config()
    out = tmp_path / "g.h5"
    assert run_sweep(old, jobs=1, out=out, simulate=_fake_simulate, progress="none").ran == 10
    monkeypatch.setattr(config_module, "powers_of_ten", right)
    new = config()
    assert new.config_hash != old.config_hash            # two scenes' rates moved by an ulp
    again = run_sweep(new, jobs=1, out=out, simulate=_fake_simulate, progress="none")
    assert again.ran == 0 and again.skipped == 10
    df = load(out)
    assert len(df) == 10 and read_attrs(out)["complete"]
    # a scene the config adds still runs
    grown = config({**spec, "grid": {**spec["grid"], "n": [0.4, 0.8, 1.6]}})
    assert run_sweep(grown, jobs=1, out=out, simulate=_fake_simulate, progress="none").ran == 5

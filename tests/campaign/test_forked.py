"""Forked workers (sweep.campaign.forked): the local backend's workers where a fork is safe.

The rows are loky's to the bit; a thread in the parent makes the local backend start loky
workers instead; an interrupted sweep leaves no forked worker; a worker that dies ends the
sweep. Each runs in a new interpreter: this one may hold threads of earlier tests (a dask
client's), beside which the local backend rightly forks nothing.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import time

import pytest

from sweep.campaign.store import load
from tests.campaign.test_scheduler import ROOT, cfg, fake_simulate
from tests.test_cli_sweep import _default_sigint

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"),
                                reason="forked workers are used on Linux only")


def _pid_simulate(scene, numerics):
    res = fake_simulate(scene, numerics)
    res.reason = str(os.getpid())
    return res


def _fresh_python(code: str, *args: str, timeout: float = 300.0) -> str:
    """Run ``code`` in a new interpreter (this test process may run threads left by other
    tests, a dask client's for one, in which no fork is made); its stdout."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([ROOT, os.environ.get("PYTHONPATH", "")]))
    done = subprocess.run([sys.executable, "-c", code, *args], env=env, cwd=ROOT,
                          capture_output=True, text=True, timeout=timeout)
    assert done.returncode == 0, done.stderr[-3000:]
    return done.stdout


_USABLE = """
import threading
from sweep.campaign import forked
print(threading.active_count(), forked.usable())
stop = threading.Event()
extra = threading.Thread(target=stop.wait)
extra.start()
print(threading.active_count(), forked.usable())
stop.set()
extra.join()
print(threading.active_count(), forked.usable())
"""


def test_usable_only_in_a_single_threaded_process():
    assert _fresh_python(_USABLE).split("\n")[:3] == ["1 True", "2 False", "1 True"]


_BACKENDS = """
import json, multiprocessing, os, sys, threading
from pathlib import Path
from sweep.campaign.scheduler import run_sweep
from tests.campaign.test_forked import cfg, _pid_simulate
out = Path(sys.argv[1])
fork = run_sweep(cfg(), jobs=2, out=out / "f.h5", simulate=_pid_simulate, progress="bar")
left = len(multiprocessing.active_children())
again = run_sweep(cfg(), jobs=2, out=out / "g.h5", simulate=_pid_simulate, progress="bar")
stop = threading.Event()
extra = threading.Thread(target=stop.wait)
extra.start()
loky = run_sweep(cfg(), jobs=2, out=out / "l.h5", simulate=_pid_simulate, progress="none")
stop.set()
extra.join()
print(json.dumps({"parent": os.getpid(), "fork": [fork.backend, fork.ran], "left": left,
                  "again": again.backend, "loky": [loky.backend, loky.ran]}))
"""


def test_the_local_backend_forks_its_workers_and_falls_back_to_loky_beside_a_thread(tmp_path):
    """Forked workers, ended with their sweep; a second sweep in the same process (after a
    progress bar) forks again; beside another thread, loky workers."""
    got = json.loads(_fresh_python(_BACKENDS, str(tmp_path)).strip().splitlines()[-1])
    assert got["fork"] == ["fork", 4] and got["left"] == 0 and got["again"] == "fork"
    assert got["loky"] == ["loky", 4]
    pids = {int(p) for p in load(tmp_path / "f.h5").reason}
    assert got["parent"] not in pids and 1 <= len(pids) <= 2


_BOTH = """
import sys
from pathlib import Path
from sweep.campaign.scheduler import run_sweep
from tests.campaign.test_forked import cfg
out = Path(sys.argv[1])
c = cfg(n=(0.4, 1.6), rate=(1, 100), nodes=200)
a = run_sweep(c, jobs=2, out=out / "fork.h5", progress="none")
b = run_sweep(c, jobs=2, backend="loky", out=out / "loky.h5", progress="none")
print(a.backend, b.backend, a.ran, b.ran)
"""


def test_forked_and_loky_rows_are_the_same_to_the_bit(tmp_path):
    """The real solver (fast preset, small mesh) on forked and on loky workers."""
    assert _fresh_python(_BOTH, str(tmp_path)).split("\n")[-2] == "fork loky 4 4"
    x = load(tmp_path / "fork.h5").set_index("scene_id").sort_index()
    y = load(tmp_path / "loky.h5").set_index("scene_id").sort_index()
    assert (x.status == "ok").all(), x[["status", "reason"]]
    timing = {"wall_s", "task_wall_s", "task_cpu_s", "worker", "finished_at"}
    for col in sorted(set(x.columns) - timing):
        assert list(x[col].astype(str)) == list(y[col].astype(str)), col   # every digit


_INTERRUPTED = """
import multiprocessing, sys, time
from sweep.campaign.scheduler import SweepRuntimeError, run_sweep
from tests.campaign.test_forked import cfg, _slow_simulate


def stop_after_three(info):
    if info["done"] == 3:
        raise RuntimeError("simulated crash of the parent loop")


t0 = time.monotonic()
try:
    run_sweep(cfg(n=(0.4, 0.6, 0.8), rate=(1, 3, 10, 30)), jobs=2, out=sys.argv[1],
              simulate=_slow_simulate, progress=stop_after_three)
except SweepRuntimeError as exc:
    print(str(exc).split("(")[0].strip())
print(round(time.monotonic() - t0), len(multiprocessing.active_children()))
"""


def test_an_interrupted_sweep_leaves_no_forked_worker(tmp_path):
    """An exception in the parent's loop: the workers, busy with one-minute scenes, are
    killed at once (not waited for) and the finished rows kept: the three the loop saw, and
    the fourth quick scene where a worker had spooled it by then (sweep.campaign.spool)."""
    lines = _fresh_python(_INTERRUPTED, str(tmp_path / "r.h5")).strip().splitlines()
    assert lines[-2] == "sweep stopped after 3 of 12 scenes"
    seconds, children = map(int, lines[-1].split())
    assert seconds < 30 and children == 0
    assert 3 <= len(load(tmp_path / "r.h5")) <= 4


_CRASH = """
import sys
from sweep.campaign.scheduler import SweepRuntimeError, run_sweep
from tests.campaign.test_scheduler import cfg, crashing_simulate
try:
    run_sweep(cfg(n=(0.4, 0.8, 1.6), rate=(1, 100)), jobs=2, out=sys.argv[1],
              simulate=crashing_simulate, progress="none")
except SweepRuntimeError as exc:
    print(exc)
"""


def test_a_dead_forked_worker_stops_the_sweep_and_keeps_the_rows(tmp_path):
    out = _fresh_python(_CRASH, str(tmp_path / "r.h5"), timeout=120)
    assert "sweep stopped after" in out and "BrokenProcessPool" in out, out
    df = load(tmp_path / "r.h5")
    assert 1 <= len(df) <= 5 and not ((df.n > 1) & (df.rate > 50)).any()


_DONE_HERE = []


def _slow_simulate(scene, numerics):
    """Quick for a worker's first two scenes, a minute for the others."""
    _DONE_HERE.append(1)
    if len(_DONE_HERE) > 2:
        time.sleep(60)
    return fake_simulate(scene, numerics)


_CTRL_C = """
import sys
from sweep.campaign.scheduler import run_sweep
from tests.campaign.test_forked import cfg, _slow_simulate
rep = run_sweep(cfg(n=(0.4, 0.6, 0.8), rate=(1, 3, 10, 30)), jobs=2, out=sys.argv[1],
                simulate=_slow_simulate, progress="log")
"""


def test_ctrl_c_reaches_the_parent_which_keeps_the_rows_and_ends_its_workers(tmp_path):
    """SIGINT to the whole process group (a Ctrl-C in a terminal): the forked workers ignore
    it, the parent stops the sweep as SweepInterrupted, keeps the finished rows, and its
    workers end with it. The parent starts with SIGINT at its default, as in a terminal
    (tests/test_cli_sweep.py's ``_default_sigint``): a suite run as a background job of a
    non-interactive shell (``make test &``) inherits SIGINT ignored, and then the parent never
    saw the Ctrl-C and the test waited 60 s for a sweep that went on."""
    import signal

    env = dict(os.environ, PYTHONPATH=os.pathsep.join([ROOT, os.environ.get("PYTHONPATH", "")]))
    proc = subprocess.Popen([sys.executable, "-c", _CTRL_C, str(tmp_path / "r.h5")], env=env,
                            cwd=ROOT, stderr=subprocess.PIPE, text=True,
                            start_new_session=True, preexec_fn=_default_sigint)
    try:
        t0 = time.monotonic()
        log = ""
        while time.monotonic() - t0 < 120:
            time.sleep(0.5)
            kids = subprocess.run(["pgrep", "-P", str(proc.pid)], capture_output=True,
                                  text=True).stdout.split()
            if len(kids) >= 2 and (tmp_path / "r.h5").exists():
                break
        time.sleep(2.0)                          # the quick scenes are done
        os.killpg(proc.pid, signal.SIGINT)
        _, log = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    assert proc.returncode != 0
    assert "SweepInterrupted" in log or "interrupted" in log, log[-2000:]
    left = subprocess.run(["pgrep", "-g", str(proc.pid)], capture_output=True, text=True)
    assert not left.stdout.split(), "workers outlived the interrupted sweep"
    assert 1 <= len(load(tmp_path / "r.h5")) <= 4


def _square(x):
    return x * x


_POOL = """
import gc, weakref
from sweep.campaign.forked import ForkedWorkers
from tests.campaign.test_forked import _square
workers = ForkedWorkers(_square, [(i,) for i in range(40)], 2)
got = []
for value in workers:
    got.append(value)
    assert len(workers.pending) == 40 - len(got)
workers.close()
print(sorted(got) == [i * i for i in range(40)], len(workers.pending))
"""


def test_forked_workers_return_every_result_and_keep_none_read():
    """Every call's result, in completion order; a result read is no longer held by the
    pool (a long sweep's rows are not all kept until its end)."""
    assert _fresh_python(_POOL).split() == ["True", "0"]


_INTERRUPTED_CHUNK = """
import sys
from sweep.campaign.scheduler import dispatch_chunks, run_sweep
from tests.campaign.test_forked import cfg, _slow_simulate
c = cfg(n=(0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0), rate=(1, 2, 3, 5, 10, 20, 30, 50))
assert min(len(ch) for ch in dispatch_chunks(c.tasks(), c.numerics, 2)[:2]) > 2
print("started", flush=True)
run_sweep(c, jobs=2, backend=sys.argv[2], out=sys.argv[1], simulate=_slow_simulate,
          progress="none")
"""


def _interrupt_after_quick_scenes(tmp_path, backend, sig):
    """Run _INTERRUPTED_CHUNK (64 scenes of one start group: dispatch chunks of several
    scenes, of which each worker finishes its first two at once and then sleeps a minute in
    the third) and send ``sig`` to its process group once both workers have run theirs."""
    import signal

    env = dict(os.environ, PYTHONPATH=os.pathsep.join([ROOT, os.environ.get("PYTHONPATH", "")]))
    out = tmp_path / "r.h5"
    proc = subprocess.Popen([sys.executable, "-c", _INTERRUPTED_CHUNK, str(out), backend],
                            env=env, cwd=ROOT, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, start_new_session=True,
                            preexec_fn=_default_sigint)
    try:
        assert proc.stdout.readline().strip() == "started"
        t0 = time.monotonic()
        while time.monotonic() - t0 < 120:
            time.sleep(0.5)
            kids = subprocess.run(["pgrep", "-P", str(proc.pid)], capture_output=True,
                                  text=True).stdout.split()
            if len(kids) >= 2 and out.exists():
                break
        time.sleep(4.0)                          # each worker's two quick scenes are done
        os.killpg(proc.pid, getattr(signal, sig))
        proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    t0 = time.monotonic()          # the workers end with their parent, within seconds
    while time.monotonic() - t0 < 20:
        left = subprocess.run(["pgrep", "-g", str(proc.pid)], capture_output=True, text=True)
        if not left.stdout.split():
            break
        time.sleep(0.5)
    assert not left.stdout.split(), "workers outlived the interrupted sweep"
    return out


@pytest.mark.parametrize("backend", ["local", "loky"])
def test_an_interrupt_keeps_the_scenes_of_chunks_it_cut(tmp_path, backend):
    """Ctrl-C while both workers are inside their first dispatch chunk: the scenes they had
    finished are kept (sweep.campaign.spool); the rows came back only with a whole chunk,
    and "0 of 64 scenes are kept" after each worker had finished two."""
    out = _interrupt_after_quick_scenes(tmp_path, backend, "SIGINT")
    assert len(load(out)) == 4


def test_a_killed_sweeps_finished_scenes_are_kept_on_resume(tmp_path):
    """SIGKILL to the sweep and its workers inside their first chunks: the scenes the
    workers had finished are in the spool, and the resume stores them instead of running
    them again."""
    from sweep.campaign.scheduler import run_sweep

    out = _interrupt_after_quick_scenes(tmp_path, "local", "SIGKILL")
    ran = []

    def progress(info):
        ran.append(info["row"]["scene_id"])

    c = cfg(n=(0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0), rate=(1, 2, 3, 5, 10, 20, 30, 50))
    rep = run_sweep(c, jobs=1, out=out, simulate=fake_simulate, progress=progress)
    assert (rep.skipped, rep.ran) == (4, 60) and len(ran) == 60
    assert len(load(out)) == 64 and not (out.parent / "r.h5.parts" / "spool").exists()

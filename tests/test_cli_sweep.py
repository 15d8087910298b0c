"""`sweep run` / `sweep info` end to end, bad input, and SIGKILL at several moments + resume."""
from __future__ import annotations

import json

import os
import queue
import re
import signal
import subprocess
import sys
import threading
import time
from collections import Counter
from pathlib import Path

import h5py
import numpy as np
import pytest

from sweep import simulate
from sweep.cli import main
from sweep.campaign.config import load_config
from sweep.campaign.scheduler import run_sweep
from sweep.campaign.store import load, parts_dir, read_attrs

ROOT = Path(__file__).resolve().parents[1]
SWEEP = [sys.executable, "-m", "sweep.cli"]
LOG_RE = re.compile(r"^\[\s*\d+/\d+\] ([0-9a-f]{16}) (ok|failed) ")

TINY = """\
name: tiny
grid:
  n: [0.4, 1.6]
  rate: [1, 100]
  a0: 2.0
numerics: {preset: fast, nodes: 60}
output: out/tiny.h5
"""


def write(path: Path, text: str) -> Path:
    path.write_text(text)
    return path


def fake_simulate(scene, numerics):
    from sweep.scene import Result
    return Result(scene=scene, numerics=numerics, status="ok", pull_off=scene.n)


def run_cli(args, cwd, timeout=240):
    env = {**os.environ, "PYTHONUNBUFFERED": "1"}
    return subprocess.run(SWEEP + list(args), cwd=cwd, capture_output=True, text=True,
                          timeout=timeout, env=env)


def one_error_line(err: str) -> str:
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1, err
    assert lines[0].startswith("error: "), err
    return lines[0]


# ----------------------------------------------------------------------------- happy path
def test_run_then_info_real_solver(tmp_path):
    cfg = write(tmp_path / "tiny.yaml", TINY)
    res = run_cli(["run", str(cfg), "-j", "2"], cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    out = tmp_path / "out" / "tiny.h5"                 # relative to the working directory
    assert "tiny: 4 scenes (4 ran, 0 already done" in res.stdout
    assert str(out) in res.stdout
    logged = [LOG_RE.match(ln).group(1) for ln in res.stderr.splitlines() if LOG_RE.match(ln)]
    assert len(logged) == 4                             # not a TTY: one line per scene
    df = load(out)
    assert sorted(df.scene_id) == sorted(logged)
    # every stored row is what simulate() gives for that scene in this process (second path:
    # no scheduler, no worker, no store); the solver is deterministic, so equal to 1e-12
    direct = {sid: simulate(scene, load_config(cfg).numerics)
              for sid, scene in load_config(cfg).tasks()}
    for row in df.itertuples():
        res = direct[row.scene_id]
        assert (row.status, row.reason, row.steps) == (res.status, res.reason, res.steps)
        assert row.pull_off == pytest.approx(res.pull_off, rel=1e-12, nan_ok=True)
        assert row.a_pulloff == pytest.approx(res.a_pulloff, rel=1e-12, nan_ok=True)
    attrs = read_attrs(out)
    assert attrs["config_text"] == TINY and attrs["complete"]
    assert attrs["numba_version"] and attrs["git_commit"]
    info = run_cli(["info", str(out)], cwd=tmp_path)
    assert info.returncode == 0, info.stderr
    assert "scenes: 4 finished of 4" in info.stdout and "status:" in info.stdout
    assert "n: 2 values in [0.4, 1.6]" in info.stdout and "slowest 4:" in info.stdout
    # a negative count had listed all but the last (pandas' head(-1))
    neg = run_cli(["info", str(out), "--slowest", "-1"], cwd=tmp_path)
    assert neg.returncode == 2 and "'--slowest': -1 is not in the range x>=0" in neg.stderr
    again = run_cli(["run", str(cfg)], cwd=tmp_path)   # resume: nothing left to do
    assert again.returncode == 0 and "(0 ran, 4 already done" in again.stdout


def test_fresh_keeps_old_file_as_backup(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    cfg = write(tmp_path / "tiny.yaml", TINY)
    run_sweep(cfg, jobs=1, simulate=fake_simulate, progress="none")
    other = write(tmp_path / "other.yaml", TINY.replace("rate: [1, 100]", "rate: [1, 10]")
                  .replace("nodes: 60", "nodes: 80"))
    before = (tmp_path / "out/tiny.h5").read_bytes()
    # other numerics into the same output: refused with the reason, file untouched, exit 2
    assert main(["run", str(other), "--progress", "none"]) == 2
    assert (tmp_path / "out/tiny.h5").read_bytes() == before
    # --fresh moves the old file aside before writing the new one
    run_sweep(other, jobs=1, simulate=fake_simulate, progress="none", resume=False)
    assert (tmp_path / "out/tiny.h5.bak").read_bytes() == before
    assert sorted(load("out/tiny.h5").rate.unique()) == [1.0, 10.0]


# ----------------------------------------------------------------------------- growing
def _must_not_run(scene, numerics):
    raise AssertionError(f"scene recomputed: {scene}")


def test_grow_a_sweep_runs_only_the_new_scenes(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    cfg = write(tmp_path / "tiny.yaml", TINY)
    run_sweep(cfg, jobs=1, simulate=fake_simulate, progress="none")
    before = load("out/tiny.h5").set_index("scene_id").finished_at.to_dict()
    grown = write(tmp_path / "grown.yaml", TINY.replace("rate: [1, 100]", "rate: [1, 100, 1e4]")
                  .replace("n: [0.4, 1.6]", "n: [0.4, 1.0, 1.6]"))
    seen = []

    def progress(info):
        seen.append(info["row"]["scene_id"])

    report = run_sweep(grown, jobs=1, simulate=fake_simulate, progress=progress)
    new_ids = {sid for sid, _ in load_config(grown).tasks()} - set(before)
    assert (report.total, report.skipped, report.ran) == (9, 4, 5)
    assert set(seen) == new_ids and len(seen) == 5              # only the new scenes ran
    df = load("out/tiny.h5")
    assert len(df) == 9 and df.scene_id.is_unique
    for sid, fin in before.items():                              # old rows untouched
        assert df.set_index("scene_id").finished_at[sid] == fin
    attrs = read_attrs("out/tiny.h5")
    assert attrs["complete"] and attrs["n_scenes"] == 9
    assert attrs["config_hash"] == load_config(grown).config_hash
    assert main(["info", "out/tiny.h5"]) == 0
    out = capsys.readouterr().out
    assert "scenes: 9 finished of 9" in out and "grown: the grid is the union" in out
    assert "rate: 3 values in [1, 1e+04]" in out
    # the smaller config again: nothing recomputed, nothing dropped, the file stays complete;
    # no "growing" line, and its own hash is not among the earlier configs (it had been)
    lines = []
    again = run_sweep(cfg, jobs=1, simulate=_must_not_run, progress="log",
                      stream=_Lines(lines))
    assert (again.ran, again.skipped) == (0, 4)
    assert len(load("out/tiny.h5")) == 9 and read_attrs("out/tiny.h5")["n_scenes"] == 9
    assert not any("growing" in ln for ln in lines), lines
    history = json.loads(read_attrs("out/tiny.h5")["config_history"])
    assert [e["config_hash"] for e in history] == [load_config(grown).config_hash]
    capsys.readouterr()
    assert main(["info", "out/tiny.h5"]) == 0
    assert "union of this config and 1 earlier one" in capsys.readouterr().out


class _Lines:
    """A stream that keeps what is written to it, line by line."""

    def __init__(self, lines):
        self.lines = lines

    def write(self, text):
        self.lines.extend(ln for ln in text.splitlines() if ln.strip())

    def flush(self):
        pass

    def isatty(self):
        return False


@pytest.mark.parametrize("change, needle", [
    (("nodes: 60", "nodes: 80"), "numerics differ (nodes 60 -> 80)"),
    (("output:", "store: {trajectories: true}\noutput:"),
     "store.trajectories differs (file false, this config true)"),
])
def test_grow_refused_when_numerics_or_trajectories_change(tmp_path, monkeypatch, capsys,
                                                           change, needle):
    monkeypatch.chdir(tmp_path)
    cfg = write(tmp_path / "tiny.yaml", TINY)
    run_sweep(cfg, jobs=1, simulate=fake_simulate, progress="none")
    before = (tmp_path / "out/tiny.h5").read_bytes()
    text = TINY.replace("rate: [1, 100]", "rate: [1, 100, 1e4]").replace(*change)
    other = write(tmp_path / "other.yaml", text)
    assert main(["run", str(other), "--progress", "none"]) == 2
    line = one_error_line(capsys.readouterr().err)
    assert needle in line and "--fresh" in line and "--out" in line
    assert (tmp_path / "out/tiny.h5").read_bytes() == before


# ----------------------------------------------------------------------------- bad input
BAD_CONFIGS = {
    "malformed": ("name: x\ngrid: {n: [0.4, 1.6\n", "not valid YAML at line"),
    "types": ("name: x\ngrid: {n: abc, rate: [1], a0: 2}\nstore: {trajectories: 3}\n",
              "2 problems: grid.n must be a number (got 'abc'); store.trajectories"),
    "range": ("name: x\ngrid: {n: 0.8, rate: 1, a0: 2, mu: 2e6}\n",
              "grid.mu must be in [0.01, 1e+06] (got 2e+06)"),
    "unknown": ("name: x\ngrid: {n: 0.8, rate: 1, a0: 2, speed: 3}\n",
                "grid.speed: unknown axis (allowed:"),
    "code": ("name: !!python/object/apply:os.getcwd []\ngrid: {n: 0.8, rate: 1, a0: 2}\n",
             "not valid YAML"),
    "si_nu": ("name: x\nunits: si\ngrid: {R: 5e-3, E0: 1e6, Einf: 1e9, nu: 0.7, n: 0.2, "
              "tau0: 0.02, dg: 0.15, h0: 3e-8, preload: 1e-3, speed: 1e-6}\n",
              "grid.nu must be in [0, 0.5] (got 0.7)"),
    "prony_file": ("name: x\ngrid: {material: {prony: nope.csv}, n: 0.8, rate: 1, a0: 2}\n",
                   "grid.material: nope.csv: cannot read the Prony table (No such file"),
    "prony_liquid": ("name: x\ngrid: {material: [{tau: [1], c: [1.2], E0: 1}], n: 0.8, "
                     "rate: 1, a0: 2}\n", "grid.material[0]: "),
    "si_missing": ("name: x\nunits: si\ngrid: {R: 5e-3, E0: 1e6, Einf: 1e9, nu: 0.5, n: 0.2, "
                   "tau0: 0.02, h0: 3e-8, preload: 1e-3, speed: 1e-6}\n",
                   "grid.dg: required SI field is missing (work of adhesion, J/m^2)"),
}


@pytest.mark.parametrize("case", sorted(BAD_CONFIGS))
def test_bad_config_exit_2_one_line(tmp_path, capsys, case):
    text, needle = BAD_CONFIGS[case]
    cfg = write(tmp_path / "bad.yaml", text)
    assert main(["run", str(cfg), "--out", str(tmp_path / "r.h5")]) == 2
    line = one_error_line(capsys.readouterr().err)
    assert needle in line
    assert not (tmp_path / "r.h5").exists()


@pytest.mark.parametrize("args, needle, code", [
    (["--out", "{tmp}/afile/r.h5"], "cannot create directory", 2),
    (["--out", "{tmp}"], "is a directory", 2),
    (["--scheduler", "tcp://127.0.0.1:1"], "only used with backend dask", 2),
    (["--backend", "spark"], "'spark' is not one of 'local', 'loky', 'dask'", 2),
    (["-j", "0"], "jobs must be an integer in [1, 4096] (got 0)", 2),
    (["-j", "two"], "'two' is not a valid integer", 2),
    (["--backend", "dask", "--scheduler", "tcp://127.0.0.1:1", "--connect-timeout", "1"],
     "cannot connect to the dask scheduler at tcp://127.0.0.1:1", 1),
])
def test_bad_options_exit_code_one_line(tmp_path, capsys, args, needle, code):
    (tmp_path / "afile").write_text("x")
    cfg = write(tmp_path / "tiny.yaml", TINY)
    args = [a.replace("{tmp}", str(tmp_path)) for a in args]
    if "--out" not in args:
        args += ["--out", str(tmp_path / "r.h5")]
    t0 = time.monotonic()
    assert main(["run", str(cfg), *args]) == code
    assert time.monotonic() - t0 < 15
    assert needle in one_error_line(capsys.readouterr().err)
    assert not (tmp_path / "r.h5").exists()


def test_missing_config_and_bad_results_file(tmp_path, capsys):
    assert main(["run", str(tmp_path / "nope.yaml")]) == 2
    assert "no such file" in one_error_line(capsys.readouterr().err)
    assert main(["info", str(tmp_path / "nope.h5")]) == 2
    assert "no results at" in one_error_line(capsys.readouterr().err)
    junk = tmp_path / "junk.h5"
    junk.write_bytes(b"not hdf5")
    assert main(["info", str(junk)]) == 2
    assert "not a readable HDF5 results file" in one_error_line(capsys.readouterr().err)
    cfg = write(tmp_path / "tiny.yaml", TINY)
    assert main(["run", str(cfg), "--out", str(junk)]) == 2     # never overwritten
    assert "refusing to overwrite" in one_error_line(capsys.readouterr().err)
    assert junk.read_bytes() == b"not hdf5"


def test_dask_backend_cli_matches_loky(tmp_path):
    distributed = pytest.importorskip("distributed")
    cfg = write(tmp_path / "tiny.yaml", TINY)
    res = run_cli(["run", str(cfg), "-j", "2", "--out", "loky.h5"], cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        res = run_cli(["run", str(cfg), "--backend", "dask", "--scheduler",
                       cluster.scheduler_address, "--out", "dask.h5"], cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    a = load(tmp_path / "loky.h5").set_index("scene_id").sort_index()
    b = load(tmp_path / "dask.h5").set_index("scene_id").sort_index()
    assert list(a.index) == list(b.index) and len(a) == 4
    assert list(a.status) == list(b.status)
    np.testing.assert_array_equal(a.pull_off.values, b.pull_off.values)


# ----------------------------------------------------------------------------- SIGKILL
KILL_CFG = """\
name: killme
grid:
  n: [0.4, 0.8, 1.6]
  rate: [1, 10, 100, 1000]
  a0: [2.0, 2.5]
numerics: {preset: fast, nodes: 60}
output: kill.h5
"""


def _default_sigint():
    """In the child before exec: SIGINT to its default, as in a user's terminal. A disposition
    of "ignore" is inherited across exec, and then Python never raises KeyboardInterrupt (the
    sigint test passed alone and failed inside the whole suite: the pytest process's SIGINT
    disposition is not the terminal's)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


class Sweep:
    """A `sweep run` subprocess whose stderr lines are collected by a thread."""

    def __init__(self, cwd, args):
        self.p = subprocess.Popen(SWEEP + args, cwd=cwd, stderr=subprocess.PIPE,
                                  stdout=subprocess.PIPE, text=True, start_new_session=True,
                                  env={**os.environ, "PYTHONUNBUFFERED": "1"},
                                  preexec_fn=_default_sigint)
        self.lines: queue.Queue = queue.Queue()
        self.ids: list[str] = []
        self.times: list[float] = []
        self.raw: list[str] = []                     # every stderr line, in order
        self.pump = threading.Thread(target=self._pump, daemon=True)
        self.pump.start()

    def _pump(self):
        for line in self.p.stderr:
            self.raw.append(line)
            self.lines.put((time.monotonic(), line))

    def _take(self, item):
        t, line = item
        m = LOG_RE.match(line)
        if m:
            self.ids.append(m.group(1))
            self.times.append(t)

    def scene_interval(self, default=0.05):
        """Mean time between two logged scenes in this run (to scale the kill delays)."""
        if len(self.times) < 2:
            return default
        return (self.times[-1] - self.times[0]) / (len(self.times) - 1)

    def wait_lines(self, n, timeout=120):
        """Block until ``n`` scene lines were logged in this run (or the process ended)."""
        deadline = time.monotonic() + timeout
        while len(self.ids) < n and time.monotonic() < deadline:
            try:
                item = self.lines.get(timeout=0.005)
            except queue.Empty:
                if self.p.poll() is not None and self.lines.empty():
                    return
                continue
            self._take(item)

    def drain(self):
        while True:
            try:
                item = self.lines.get_nowait()
            except queue.Empty:
                return
            self._take(item)

    def kill(self):
        self.p.send_signal(signal.SIGKILL)           # the parent, mid-whatever-it-does
        self.p.wait(timeout=30)
        time.sleep(0.05)
        self.drain()
        try:
            os.killpg(self.p.pid, signal.SIGKILL)    # then its orphaned workers
        except ProcessLookupError:
            pass
        return self.p.returncode


def test_sigkill_at_several_moments_then_resume(tmp_path):
    # the accurate preset (0.1-0.5 s a scene): a kill loses no scene a worker had finished
    # (sweep.campaign.spool), and on 60 fast nodes (5-40 ms) the workers finished the 24
    # before the fourth kill
    cfg = write(tmp_path / "kill.yaml", KILL_CFG.replace("{preset: fast, nodes: 60}",
                                                         "{preset: accurate}"))
    tasks = [sid for sid, _ in load_config(cfg).tasks()]
    assert len(tasks) == 24
    out = tmp_path / "kill.h5"
    args = ["run", str(cfg), "-j", "2", "--progress", "log", "--consolidate-every", "0"]
    logged: Counter = Counter()
    snapshot: dict[str, float] = {}                  # scene id -> finished_at at kill time
    # moments: during start-up, right after the 1st scene of a run, and after a few scenes
    # plus a fraction of the time per scene (so that kills land between and during scene
    # writes and consolidations, which happen after every scene here), whatever the speed
    plan = [("time", 0.4), ("lines", 1, 0.0), ("lines", 2, 0.15), ("lines", 3, 0.5),
            ("lines", 2, 0.8)]
    kills = 0
    for step in plan:
        run = Sweep(tmp_path, args)
        if step[0] == "time":
            time.sleep(step[1])
        else:
            run.wait_lines(step[1])
            time.sleep(step[2] * run.scene_interval())
        if run.p.poll() is not None:                 # finished before the kill: too fast
            run.drain()
            logged.update(run.ids)
            break
        rc = run.kill()
        assert rc == -signal.SIGKILL
        kills += 1
        logged.update(run.ids)
        if not run.ids and not out.exists() and not parts_dir(out).exists():
            continue                                 # killed before the store existed
        df = load(out)                               # readable right after the kill
        assert df.scene_id.is_unique
        assert set(run.ids) <= set(df.scene_id)      # every logged scene is on disk
        for sid, fin in zip(df.scene_id, df.finished_at):
            assert snapshot.setdefault(sid, fin) == fin   # earlier rows never recomputed
        if out.exists():                             # the main file itself is never torn
            with h5py.File(out, "r") as f:
                assert len(f["runs/scene_id"]) <= len(df)
    assert kills >= 4, "sweep finished too quickly to be killed several times"
    final = run_cli(args, cwd=tmp_path)
    assert final.returncode == 0, final.stderr
    final_ids = [LOG_RE.match(ln).group(1) for ln in final.stderr.splitlines()
                 if LOG_RE.match(ln)]
    logged.update(final_ids)
    df = load(out)
    assert sorted(df.scene_id) == sorted(tasks)      # complete
    assert max(logged.values()) == 1, logged.most_common(3)   # no scene ran twice
    assert not set(final_ids) & set(snapshot)        # the rerun skipped finished scenes
    for sid, fin in zip(df.scene_id, df.finished_at):
        if sid in snapshot:
            assert snapshot[sid] == fin
    assert not parts_dir(out).exists() and read_attrs(out)["complete"]
    assert f"{len(tasks) - len(final_ids)} already done" in final.stdout


def test_info_on_a_directory_is_one_line(tmp_path, capsys):
    # h5py's message for a directory spans two lines; the CLI prints one
    assert main(["info", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "is a directory" in err


def test_sigkill_while_growing_then_resume(tmp_path):
    """Grow a finished sweep (rates 1, 10 -> 1, 10, 100, 1000), SIGKILL the growing run at
    several moments: the first grid's rows are never lost or recomputed, and the resumed run
    completes the union with every scene run once."""
    small = write(tmp_path / "small.yaml", KILL_CFG.replace("rate: [1, 10, 100, 1000]",
                                                            "rate: [1, 10]"))
    cfg = write(tmp_path / "kill.yaml", KILL_CFG)
    out = tmp_path / "kill.h5"
    first = run_cli(["run", str(small), "-j", "2", "--progress", "log"], cwd=tmp_path)
    assert first.returncode == 0, first.stderr
    old = load(out).set_index("scene_id").finished_at.to_dict()
    assert len(old) == 12
    tasks = [sid for sid, _ in load_config(cfg).tasks()]
    args = ["run", str(cfg), "-j", "2", "--progress", "log", "--consolidate-every", "0"]
    logged: Counter = Counter()
    snapshot: dict[str, float] = dict(old)
    kills = 0
    for step in [("time", 0.5), ("lines", 1, 0.0), ("lines", 2, 0.5)]:
        run = Sweep(tmp_path, args)
        if step[0] == "time":
            time.sleep(step[1])
        else:
            run.wait_lines(step[1])
            time.sleep(step[2] * run.scene_interval())
        if run.p.poll() is not None:
            run.drain()
            logged.update(run.ids)
            break
        assert run.kill() == -signal.SIGKILL
        kills += 1
        logged.update(run.ids)
        df = load(out)                               # readable right after the kill
        assert df.scene_id.is_unique
        assert set(old) <= set(df.scene_id)          # the first grid is never lost
        assert set(run.ids) <= set(df.scene_id)
        for sid, fin in zip(df.scene_id, df.finished_at):
            assert snapshot.setdefault(sid, fin) == fin   # never recomputed
    assert kills >= 2, "sweep finished too quickly to be killed"
    final = run_cli(args, cwd=tmp_path)
    assert final.returncode == 0, final.stderr
    logged.update(LOG_RE.match(ln).group(1) for ln in final.stderr.splitlines()
                  if LOG_RE.match(ln))
    df = load(out)
    assert sorted(df.scene_id) == sorted(tasks)
    assert not set(logged) & set(old)                # no scene of the first grid ran again
    assert max(logged.values()) == 1, logged.most_common(3)
    for sid, fin in zip(df.scene_id, df.finished_at):
        if sid in snapshot:
            assert snapshot[sid] == fin
    attrs = read_attrs(out)
    assert attrs["complete"] and attrs["n_scenes"] == 24 and not parts_dir(out).exists()


# ----------------------------------------------------------------------------- what is said
def test_log_lines_name_the_scene_inputs(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    cfg = write(tmp_path / "tiny.yaml", TINY)
    run_sweep(cfg, jobs=1, simulate=fake_simulate, progress="log")
    lines = [ln for ln in capsys.readouterr().err.splitlines() if LOG_RE.match(ln)]
    assert len(lines) == 4
    for sid, scene in load_config(cfg).tasks():
        line = next(ln for ln in lines if LOG_RE.match(ln).group(1) == sid)
        assert (f" ok n={scene.n:g} k={scene.k:g} mu={scene.mu:g} a0={scene.a0:g} "
                f"rate={scene.rate:g} pull_off=") in line


def test_log_lines_tell_apart_scenes_that_differ_in_their_protocol_or_zone():
    """A grid over dwell, dwell_hold or a process zone printed four identical lines ("ok n=0.5
    k=0.2 mu=5 rate=1"): the fields a scene has are named, the defaults left out."""
    from sweep.campaign.scheduler import scene_inputs

    plain = dict(n=0.8, k=0.1, mu=3.24, a0=2.0, rate=10.0, material="mpl", model="bem",
                 stop="pulloff", pz_law="none", dwell_hold="force")
    assert scene_inputs(plain) == "n=0.8 k=0.1 mu=3.24 a0=2 rate=10"
    protocol = {**plain, "a0": None, "approach_rate": 1.0, "preload": 2.0, "dwell": 10.0}
    assert scene_inputs({**protocol, "dwell_hold": "depth"}) == (
        "n=0.8 k=0.1 mu=3.24 rate=10 approach_rate=1 preload=2 dwell=10 dwell_hold=depth")
    assert scene_inputs(protocol).endswith("dwell=10")
    zone = {**plain, "pz_law": "gent-schultz", "pz_v0": 0.1, "pz_xi": 0.4, "stop": "separation"}
    assert scene_inputs(zone) == ("n=0.8 k=0.1 mu=3.24 a0=2 rate=10 pz_v0=0.1 pz_xi=0.4 "
                                  "pz_law=gent-schultz stop=separation")


def test_first_run_says_it_compiles(monkeypatch):
    from sweep.campaign import scheduler
    from sweep.engine import bem

    said = []

    class Prog:
        def message(self, text):
            said.append(text)

    from sweep import Numerics, Scene

    grid = [Scene(n=0.8, k=0.1, mu=3.24, a0=2.0, rate=1.0)], Numerics.preset("balanced")
    monkeypatch.setattr(bem, "warm_up", lambda: 42.25)
    monkeypatch.setattr(bem, "kernels_cached", lambda: False)
    scheduler._warm_parent(Prog(), *grid)
    assert said == ["compiling kernels (first run only) ...",
                    "compiling kernels (first run only): done in 42.2 s"]
    said.clear()
    monkeypatch.setattr(bem, "kernels_cached", lambda: True)
    scheduler._warm_parent(Prog(), *grid)
    assert said == []                                  # a warm cache: nothing to say


def test_kernels_cached_looks_at_the_numba_cache(tmp_path, monkeypatch):
    from sweep.engine import bem

    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    assert not bem.kernels_cached()                     # an empty cache: cold


_CALLS = []


def _interrupt_after_3(scene, numerics):
    _CALLS.append(scene)
    if len(_CALLS) > 3:
        raise KeyboardInterrupt
    return fake_simulate(scene, numerics)


def test_sigint_says_what_is_kept_and_how_to_resume(tmp_path, monkeypatch, capsys):
    from sweep.campaign import scheduler

    monkeypatch.chdir(tmp_path)
    cfg = write(tmp_path / "tiny.yaml", TINY)
    real = scheduler.run_sweep

    def interrupted(*args, **kw):
        kw.update(jobs=1, simulate=_interrupt_after_3)
        return real(*args, **kw)

    _CALLS.clear()
    monkeypatch.setattr(scheduler, "run_sweep", interrupted)
    assert main(["run", str(cfg), "--progress", "none"]) == 130
    err = [ln for ln in capsys.readouterr().err.splitlines() if ln.strip()]
    out = tmp_path / "out" / "tiny.h5"
    assert err == [f"interrupted: 3 of 4 scenes are kept in {out}; to resume, run: "
                   f"sweep run {cfg}"]
    assert len(load(out)) == 3
    monkeypatch.setattr(scheduler, "run_sweep", real)
    report = run_sweep(cfg, jobs=1, simulate=fake_simulate, progress="none")
    assert (report.ran, report.skipped) == (1, 3)


@pytest.mark.parametrize("sig, jobs, group, code, word", [
    (signal.SIGINT, 2, True, 130, "interrupted"),
    (signal.SIGTERM, 1, False, 143, "terminated"),
])
def test_a_signal_keeps_scenes_and_says_how_to_resume(tmp_path, sig, jobs, group, code, word):
    """Ctrl-C in a terminal signals the parent and its workers; SIGTERM (what `timeout` or a
    batch system's time limit sends) the parent alone. Either ends the sweep with the
    finished scenes stored and one line saying how many are kept (as many as the file holds)
    and the command that resumes; exit 130 and 143."""
    cfg = write(tmp_path / "big.yaml", KILL_CFG.replace("{preset: fast, nodes: 60}",
                                                        "{preset: balanced}")
                .replace("a0: [2.0, 2.5]", "a0: [3.0, 4.0, 5.0]"))
    run = Sweep(tmp_path, ["run", str(cfg), "-j", str(jobs), "--progress", "log"])
    run.wait_lines(2)
    assert run.p.poll() is None, "sweep finished before the signal"
    if group:
        os.killpg(run.p.pid, sig)
    else:
        run.p.send_signal(sig)
    assert run.p.wait(timeout=60) == code, "".join(run.raw)[-2000:]
    run.pump.join(timeout=30)                        # stderr read to its end
    text = "".join(run.raw)
    m = re.search(rf"^{word}: (\d+) of 36 scenes are kept in (\S+); to resume, run: "
                  r"sweep run \S+big.yaml$", text, re.M)
    assert m, text
    assert int(m.group(1)) == len(load(tmp_path / "kill.h5")) >= 2
    assert "Traceback" not in text


def test_run_exits_nonzero_after_an_internal_error(tmp_path, monkeypatch, capsys):
    """`sweep run` finishes the sweep, stores every scene, prints the count of internal errors
    with the log's path and exits 3 (a bug is not a result)."""
    import sweep.engine.models as models

    real = models.simulate

    def buggy(scene, numerics=None):
        if scene.n > 1 and scene.rate > 50:
            raise IndexError("index 7 is out of bounds")
        return real(scene, numerics)

    monkeypatch.setattr(models, "simulate", buggy)
    monkeypatch.chdir(tmp_path)
    cfg = write(tmp_path / "tiny.yaml", TINY)
    assert main(["run", str(cfg), "-j", "1", "--progress", "none"]) == 3
    cap = capsys.readouterr()
    out = tmp_path / "out" / "tiny.h5"
    assert "tiny: 4 scenes (4 ran" in cap.out
    assert f"1 scene hit an internal error (a bug, not a result; status \"error\"), see " \
           f"{out}.errors.log" in cap.err
    df = load(out)
    assert len(df) == 4 and list(df.status).count("error") == 1
    log = (tmp_path / "out" / "tiny.h5.errors.log").read_text()
    assert "IndexError: index 7 is out of bounds" in log and "in buggy" in log

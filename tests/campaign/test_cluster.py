"""A dask cluster whose worker dies mid-scene (issue 25 item 7, docs/cluster.md): nothing is
lost, every scene is in the results file once."""
from __future__ import annotations

import os
import signal
from pathlib import Path

import pytest

from sweep.campaign.config import config_from_dict
from sweep.campaign.scheduler import run_sweep
from sweep.campaign.store import load, read_attrs
from sweep.scene import Result

MARK_ENV = "SWEEP_TEST_KILL_MARK"


def die_once_simulate(scene, numerics):
    """Stand-in solver: the first worker to reach the scene n = 0.8, rate = 100 kills itself
    (SIGKILL, mid-scene, as a crashed or preempted machine); every later call succeeds."""
    mark = Path(os.environ[MARK_ENV])
    if scene.n == 0.8 and scene.rate == 100:
        try:
            fd = os.open(mark, os.O_CREAT | os.O_EXCL | os.O_WRONLY)
        except FileExistsError:
            pass
        else:
            os.write(fd, str(os.getpid()).encode())
            os.close(fd)
            os.kill(os.getpid(), signal.SIGKILL)
    return Result(scene=scene, numerics=numerics, status="ok", pull_off=scene.n + scene.rate)


def test_a_worker_killed_mid_scene_loses_nothing(tmp_path, monkeypatch):
    distributed = pytest.importorskip("distributed")
    mark = tmp_path / "killed.pid"
    monkeypatch.setenv(MARK_ENV, str(mark))          # inherited by the worker processes
    cfg = config_from_dict({"name": "c", "grid": {"n": [0.4, 0.8, 1.6],
                                                  "rate": [1, 10, 100, 1000], "a0": 2.0},
                            "numerics": {"preset": "fast", "nodes": 60}})
    out = tmp_path / "c.h5"
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        rep = run_sweep(cfg, backend="dask", scheduler=cluster.scheduler_address, out=out,
                        simulate=die_once_simulate, progress="none")
    assert mark.exists()                             # a worker did die mid-scene
    killed = int(mark.read_text())
    df = load(out)
    assert sorted(df.scene_id) == sorted(sid for sid, _ in cfg.tasks())   # nothing lost
    assert df.scene_id.is_unique and len(df) == 12 and rep.ran == 12     # each once
    assert (df.status == "ok").all() and read_attrs(out)["complete"]
    # the scene the worker died in ran again elsewhere (the dead worker may have finished
    # earlier chunks before: their rows rightly name it)
    [fatal] = df.worker[(df.n == 0.8) & (df.rate == 100)]
    assert fatal.rsplit(":", 1)[1] != str(killed)

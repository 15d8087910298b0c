"""`sweep plot`: failed scenes are marked, never dropped silently."""
from __future__ import annotations

from sweep.analysis.plots import mark_failed, pyplot
from sweep.campaign.scheduler import run_sweep
from sweep.campaign.store import load
from sweep.cli import main
from sweep.scene import Result

CFG = {"name": "p", "grid": {"n": [0.4, 0.8], "rate": [1, 10, 100], "a0": 2.0},
       "numerics": {"preset": "fast", "nodes": 60}}


def _some_fail(scene, numerics):
    if scene.rate == 1:           # failed without a pull-off
        return Result(scene=scene, numerics=numerics, status="failed", reason="no pull-off")
    if scene.rate == 10 and scene.n == 0.8:   # failed with one
        return Result(scene=scene, numerics=numerics, status="failed", reason="unresolved",
                      pull_off=3.0)
    return Result(scene=scene, numerics=numerics, status="ok", pull_off=1.5 + scene.n)


def test_failed_scenes_are_marked(tmp_path):
    out = tmp_path / "p.h5"
    run_sweep({**CFG, "output": str(out)}, jobs=1, simulate=_some_fail, progress="none")
    df = load(out)
    assert (df.status != "ok").sum() == 3
    plt = pyplot()
    fig, ax = plt.subplots()
    assert mark_failed(ax, df) == 3
    crosses = [ln for ln in ax.get_lines() if ln.get_marker() == "x"]
    xs = sorted(float(x) for ln in crosses for x in ln.get_xdata())
    assert xs == [1.0, 1.0, 10.0]                    # every failed scene, at its rate
    with_po = [ln for ln in crosses if ln.get_label() == "failed (3)"]
    assert len(with_po) == 1 and list(with_po[0].get_ydata()) == [3.0]
    plt.close(fig)
    png = tmp_path / "p.png"
    assert main(["plot", str(out), "--out", str(png)]) == 0
    assert png.read_bytes()[:4] == b"\x89PNG"


def test_no_failures_nothing_marked(tmp_path):
    out = tmp_path / "q.h5"
    run_sweep({**CFG, "output": str(out)}, jobs=1, simulate=_ok, progress="none")
    plt = pyplot()
    fig, ax = plt.subplots()
    assert mark_failed(ax, load(out)) == 0 and not ax.get_lines()
    plt.close(fig)


def _ok(scene, numerics):
    return Result(scene=scene, numerics=numerics, status="ok", pull_off=2.0)

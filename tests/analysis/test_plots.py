"""`sweep plot`: failed scenes are marked, never dropped silently; the figure of every campaign
in configs/ reads at a glance (issue 34 item 6): no matplotlib warning, the legend outside the
panels and inside the figure, the colour on one axis, the reference lines inside the range."""
from __future__ import annotations

import io
import math
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from sweep.analysis.plots import (JKR_PULL_OFF, mark_failed, plot_layout, plot_sweep,
                                  pyplot, sweep_figure)
from sweep.campaign.config import load_config
from sweep.campaign.scheduler import run_sweep
from sweep.campaign.store import load, load_trajectory
from sweep.cli import main
from sweep.scene import Result
from sweep.theory import jkr_contact_radius, jkr_load

CONFIGS = Path(__file__).resolve().parents[2] / "configs"

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


# ------------------------------------------------------------------ figures that read

def synthetic_frame(config: Path) -> pd.DataFrame:
    """A results frame with the scenes of ``config`` (its axes, as :func:`sweep.load` gives
    them) and synthetic pull-offs of the right shape: 1.5 at slow unloading, rising with the
    rate towards 1.5/k, less for small a0 (a protocol's: its preload's JKR radius); every
    37th scene failed (alternately with and without a pull-off)."""
    rows = []
    for i, (sid, sc) in enumerate(load_config(config).tasks()):
        if sc.a0 is not None:
            a0 = sc.a0
        elif sc.delta0 is not None:
            a0 = 1.0 + math.sqrt(max(sc.delta0, 0.0))
        else:
            a0 = float(jkr_contact_radius(load=sc.preload))
        reach = 1.0 - math.exp(-(a0 / 3.0) ** 2)
        rise = sc.rate ** 0.4 / (sc.rate ** 0.4 + 10.0)
        po = 1.5 + (1.5 / sc.k - 1.5) * reach * rise * (0.7 + 0.2 * min(sc.n, 1.5))
        status = "failed" if i % 37 == 36 else "ok"
        rows.append({"scene_id": sid, **sc.to_dict(), "status": status,
                     "pull_off": po if status == "ok" or i % 74 == 36 else math.nan,
                     "a0_result": a0})
    return pd.DataFrame(rows)


def synthetic_trajectory(scene_id: str) -> dict:
    a = np.linspace(2.5, 1.0, 40)
    return {"a": a, "P": jkr_load(a) - 2.0 * (2.5 - a)}


def render(df, trajectory=None):
    """The figure of ``df``, drawn and saved with every warning an error; returns it."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fig = sweep_figure(df, "synthetic", trajectory)
        fig.savefig(io.BytesIO(), format="png", dpi=50)     # lays the figure out
    return fig


def all_axes(fig) -> list:
    """The visible axes of ``fig`` and of its subfigures (panels and colour bars)."""
    found = list(fig.axes)
    for sub in fig.subfigs:
        found += all_axes(sub)
    return [ax for ax in found if ax.get_visible()]


def assert_legend_outside_the_data_inside_the_figure(fig):
    renderer = fig.canvas.get_renderer()
    (legend,) = fig.legends
    box = legend.get_window_extent(renderer)
    page = fig.bbox
    assert page.x0 <= box.x0 and box.x1 <= page.x1 and page.y0 <= box.y0 and box.y1 <= page.y1
    for ax in all_axes(fig):
        assert not box.overlaps(ax.get_window_extent(renderer)), ax.get_title()


def reference_lines(ax) -> list:
    """The horizontal reference lines of a pull-off panel (axhline: black, dashed or dotted)."""
    return [ln for ln in ax.get_lines() if ln.get_color() == "black"
            and len(set(ln.get_ydata())) == 1 and ln.get_linestyle() in ("--", ":")]


def test_the_threshold_campaign_reads_at_a_glance():
    """936 scenes over n, a0 and rate: a panel per n, a0 on a colour bar, so each panel has
    18 lines (one per a0) instead of 72 series in a 10-colour cycle on one plot."""
    df = synthetic_frame(CONFIGS / "threshold.yaml")
    assert len(df) == 936
    lay = plot_layout(df)
    assert (lay.x, lay.colour, lay.panels, lay.styles) == ("rate", "a0", ("n",), ())
    fig = render(df)
    assert_legend_outside_the_data_inside_the_figure(fig)
    panels = [ax for ax in all_axes(fig) if ax.get_title().startswith("n = ")]
    assert sorted(ax.get_title() for ax in panels) == [f"n = {n}" for n in
                                                        ("0.4", "0.6", "0.8", "1.6")]
    for ax in panels:
        data = [ln for ln in ax.get_lines() if ln.get_marker() == "o"]
        assert len(data) == 18                           # one line per a0
        assert len({ln.get_color() for ln in data}) == 18
    (bar,) = [ax for ax in all_axes(fig) if ax not in panels]
    assert len(bar.get_yticklabels()) == 18 and bar.get_ylabel() == r"$\hat a_0$"
    pyplot().close(fig)


@pytest.mark.parametrize("name", ["threshold.yaml", "demo.yaml"])
def test_the_reference_lines_lie_inside_the_plotted_range(name):
    """The JKR line at 1.5 sits inside the y range with a margin, not on the frame (the demo
    figure's pull-offs all lie above 1.5), and is named in the legend."""
    df = synthetic_frame(CONFIGS / name)
    assert df["pull_off"].min() > JKR_PULL_OFF
    fig = render(df, synthetic_trajectory if load_config(CONFIGS / name).trajectories else None)
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    assert [x for x in labels if x.startswith("JKR relaxed") and "pull-off" in x and "1.5" in x]
    panels = [ax for ax in all_axes(fig) if reference_lines(ax)]
    assert panels
    for ax in panels:
        lo, hi = ax.get_ylim()
        for line in reference_lines(ax):
            y = line.get_ydata()[0]
            assert lo + 0.02 * (hi - lo) < y < hi - 0.02 * (hi - lo), (y, lo, hi)
    pyplot().close(fig)


#: every sweep config in configs/ (configs/calibrate/ holds calibration configs, no sweeps)
SWEEP_CONFIGS = [p for folder in ("", "quick/", "random/")
                 for p in sorted(CONFIGS.glob(folder + "*.yaml"))]


@pytest.mark.parametrize("config", SWEEP_CONFIGS, ids=lambda p: str(p.relative_to(CONFIGS)))
def test_every_campaign_renders_without_warning(config):
    cfg = load_config(config)
    df = synthetic_frame(config)
    fig = render(df, synthetic_trajectory if cfg.trajectories else None)
    assert_legend_outside_the_data_inside_the_figure(fig)
    n_failed = int((df["status"] != "ok").sum())
    bare = int((df["status"] != "ok").sum() - np.isfinite(
        df.loc[df["status"] != "ok", "pull_off"].astype(float)).sum())
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    # a failure without a pull-off is drawn on the x axis, and the legend says so
    want = f"failed ({n_failed}" + (f"; {bare} without a pull-off, on the x axis" if bare
                                    else "") + ")"
    assert (want in labels) == (n_failed > 0), labels
    pyplot().close(fig)


def test_an_older_results_file_plots(tmp_path):
    """tests/data/results_v1.h5 (visco-sweep 0.1.0: a0 and delta0 scenes, mpl and sls, with
    trajectories) plots without warning; no title names a missing value."""
    v1 = Path(__file__).resolve().parents[1] / "data" / "results_v1.h5"
    df = load(v1)
    lay = plot_layout(df)
    assert (lay.colour, lay.styles) == ("n", ("material",))
    fig = render(df, lambda sid: load_trajectory(v1, sid))
    assert_legend_outside_the_data_inside_the_figure(fig)
    assert not [ax.get_title() for ax in all_axes(fig) if "nan" in ax.get_title()]
    pyplot().close(fig)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        png = plot_sweep(v1, tmp_path / "v1.png")
    assert png.read_bytes()[:4] == b"\x89PNG"


def test_a_protocol_campaign_draws_its_load_cycles(tmp_path):
    """Scenes with a test protocol (issue 36): the trajectory panel draws P(delta), the
    approach and the dwell dotted, the retraction solid, every phase of every scene. (Rates 1
    and 10: at 0.1 and 0.3 the fast preset's estimate of these scenes is 0.026-0.030, at its
    tolerance, and whether the row is ok there is not what this test checks.)"""
    from sweep.scene import Numerics

    out = tmp_path / "cycles.h5"
    run_sweep({"name": "cycles", "output": str(out), "store": {"trajectories": True},
               "grid": {"material": "sls", "n": 0.5, "k": 0.1, "mu": 5, "preload": 1.0,
                        "dwell": 1.0, "approach_rate": 1.0, "rate": [1.0, 10.0]},
               "numerics": {"preset": "fast"}}, jobs=1, progress="none")
    df = load(out)
    assert (df.status == "ok").all() and len(df) == 2
    ok = df[df.status == "ok"]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fig = sweep_figure(ok, "cycles", lambda sid: load_trajectory(out, sid))
    (cycles,) = {ax for ax in all_axes(fig) if ax.get_xlabel().startswith("indentation")}
    lines = cycles.get_lines()
    assert len(lines) == 4                                  # two phases' lines a scene
    assert sorted(ln.get_linestyle() for ln in lines) == ["-", "-", ":", ":"]
    traj = load_trajectory(out, str(ok.scene_id.iloc[0]))
    drawn = sum(len(ln.get_xdata()) for ln in lines[:2])
    assert drawn == len(traj["P"])                          # every record, every phase
    pyplot().close(fig)


def test_the_figure_names_what_was_held_constant():
    """A reader of `sweep plot`'s figure could not tell k, mu or a0 (`sweep info` lists them
    as fixed): the suptitle names each scene axis with one value, n not for a table's scenes
    (unused), a category at its default not at all."""
    import pandas as pd

    from sweep.analysis.plots import constant_axes

    df = pd.DataFrame({"n": [0.4, 0.8], "k": [0.1, 0.1], "mu": [3.24, 3.24], "a0": [2.5, 2.5],
                       "rate": [1.0, 10.0], "material": ["mpl", "mpl"], "model": ["bem", "bem"],
                       "stop": ["pulloff", "pulloff"], "pz_law": ["none", "none"]})
    assert constant_axes(df) == ["model = bem", "material = mpl", "k = 0.1", "mu = 3.24",
                                 "a0 = 2.5"]
    table = df.assign(material="prony:gmm:a06e69d9b019ec0e", n=1.0)
    assert "n = 1" not in constant_axes(table)
    assert "material = prony:gmm:a06e69d9b019ec0e" in constant_axes(table)


def test_a_long_title_is_wrapped_inside_the_figure():
    """A results file's title with many constant axes ran past the figure's edge: it is
    wrapped, every line inside the figure."""
    df = synthetic_frame(CONFIGS / "demo.yaml")
    title = "results.h5: 12 ok, 0 failed\n" + ", ".join(f"axis{i} = {i}.12345" for i in range(30))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fig = sweep_figure(df, title)
        fig.savefig(io.BytesIO(), format="png", dpi=50)
    text = fig._suptitle
    lines = text.get_text().split("\n")
    assert len(lines) >= 3 and lines[0] == "results.h5: 12 ok, 0 failed"   # its own break kept
    assert " ".join(lines[1:]) == title.split("\n")[1]
    box = text.get_window_extent(fig.canvas.get_renderer())
    assert fig.bbox.x0 <= box.x0 and box.x1 <= fig.bbox.x1


def test_an_abscissa_says_what_it_is_and_in_what():
    """With a0 as the abscissa its label had been a bare symbol (no name, no unit)."""
    from sweep.analysis.plots import axis_label

    assert axis_label("a0") == r"initial contact radius $\hat a_0$ (a_ref)"
    assert axis_label("preload") == r"preload $\hat P_0$ (pi dg R)"
    assert axis_label("rate") == r"unloading rate $\hat r = r\tau_0/h_0$"


def test_each_panel_has_its_own_trajectory_axes():
    """The trajectory panel had drawn the scenes of every pull-off panel on one axes in the
    same colours (test D of session 48: the load cycles of n 0.4 and 0.8 could not be told
    apart): up to TRAJECTORY_PANELS panels, each has an axes of its own, titled with the
    panel's value and holding its scenes' lines only; beyond, one axes says "together"."""
    import pandas as pd

    from sweep.analysis.plots import TRAJECTORY_PANELS
    from sweep.scene import Scene

    def frame(a0s, ns=(0.4, 0.8)):          # x: rate; colour: n, a panel per a0
        rows = []
        for a0 in a0s:
            for n in ns:
                for rate in (1.0, 10.0):
                    sc = Scene(n=n, k=0.1, mu=3.24, a0=a0, rate=rate)
                    rows.append({"scene_id": f"{a0}-{n}-{rate}", **sc.to_dict(),
                                 "status": "ok", "pull_off": 2.0 + n, "a0_result": a0})
        return pd.DataFrame(rows)

    def trajectory_axes(fig):
        found = [ax for ax in all_axes(fig) if ax.get_ylabel().startswith("load")]
        return list(dict.fromkeys(found))   # a subfigure's axes are also the figure's

    fig = render(frame([2.0, 3.0]), synthetic_trajectory)
    traj = trajectory_axes(fig)
    assert [ax.get_title().splitlines()[-1] for ax in traj] == ["a0 = 2", "a0 = 3"]
    for ax in traj:                         # four scenes' lines and the JKR curve
        assert len(ax.get_lines()) == 5
    assert traj[-1].get_xlabel().startswith("contact radius")
    pyplot().close(fig)

    ns = [0.4 + 0.2 * i for i in range(TRAJECTORY_PANELS + 1)]     # a panel per n
    a0s = [2.0 + 0.5 * i for i in range(TRAJECTORY_PANELS + 2)]    # colour: a0
    fig = render(frame(a0s, ns), synthetic_trajectory)
    (one,) = trajectory_axes(fig)
    assert "every n together" in one.get_title()
    assert len(one.get_lines()) == 2 * len(ns) * len(a0s) + 1
    pyplot().close(fig)

"""Figures of a sweep's results (matplotlib, the optional ``plot`` extra).

``plot_sweep(path, out)`` draws what a user checks first after a run: the pull-off force
against the unloading rate (one line per (n, k, a0) group; failed scenes as red crosses, at
the bottom edge when they have no pull-off) and, when the sweep stored
trajectories, the load against the contact radius P(a) with the JKR curve for reference.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..campaign.config import AXES
from ..campaign.store import load, load_trajectory
from ..errors import InputError
from ..scene import AXES as AXIS_INFO
from ..theory import jkr_load


def pyplot():
    """matplotlib.pyplot on the Agg backend (matplotlib is the optional ``plot`` extra,
    imported here on first use), or an InputError saying how to install it."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:  # pragma: no cover - the extra is installed by make demo/test
        raise InputError("plot needs matplotlib: pip install 'visco-sweep[plot]'") from None
    return plt


def mark_failed(ax, df) -> int:
    """Mark the failed scenes of ``df`` on the pull-off-against-rate axes ``ax``: a red cross
    at their pull-off when they have one, else at the bottom of the axes at their rate (they
    are never dropped silently). Returns how many were marked."""
    failed = df[df["status"] != "ok"]
    if not len(failed):
        return 0
    rate = failed["rate"].astype(float).to_numpy()
    po = failed["pull_off"].astype(float).to_numpy()
    has = np.isfinite(po) & np.isfinite(rate)
    label = f"failed ({len(failed)})"
    if has.any():
        ax.plot(rate[has], po[has], "x", color="red", ms=7, mew=1.5, ls="none", label=label)
        label = None
    if (~has).any():
        # no pull-off: at the bottom edge, x in data units (the rate), y in axes units
        ax.plot(rate[~has], np.full((~has).sum(), 0.03), "x", color="red", ms=7, mew=1.5,
                ls="none", transform=ax.get_xaxis_transform(), clip_on=False,
                label=label or "_failed_no_pull_off")
    return len(failed)


def plot_sweep(path, out=None) -> Path:
    """Write a PNG summary of the results file ``path``; returns the figure's path.

    Parameters
    ----------
    path : str or Path
        HDF5 results file of ``sweep run``.
    out : str or Path, optional
        Output PNG; default: the results file with the suffix ``.png``.
    """
    plt = pyplot()
    path = Path(path)
    df = load(path)
    if df.empty:
        raise InputError(f"results: {path} holds no finished scene")
    ok = df[df["status"] == "ok"]
    out = Path(out) if out is not None else path.with_suffix(".png")
    has_traj = False
    try:
        load_trajectory(path, str(ok["scene_id"].iloc[0])) if len(ok) else None
        has_traj = len(ok) > 0
    except (KeyError, InputError, OSError):
        has_traj = False
    ncols = 2 if has_traj else 1
    fig, axes = plt.subplots(1, ncols, figsize=(6.0 * ncols, 4.5), squeeze=False)
    ax = axes[0, 0]
    # one line per combination of the scene axes that vary (rate is the abscissa)
    keys = [c for c in AXES if AXIS_INFO[c].plot_group and c in ok and ok[c].nunique() > 1]
    groups = ok.groupby(keys, dropna=False) if keys else [((), ok)]
    for key, g in groups:
        g = g.sort_values("rate")
        key = key if isinstance(key, tuple) else (key,)
        label = ", ".join(f"{k}={v:g}" if isinstance(v, float) else f"{k}={v}" for k, v in zip(keys, key))
        ax.plot(g["rate"], g["pull_off"], "o-", label=label or None)
    mark_failed(ax, df)
    ax.axhline(1.5, color="0.6", ls=":", lw=1, label="JKR elastic, 1.5")
    ax.set_xscale("log")
    ax.set_xlabel(AXIS_INFO["rate"].label)
    ax.set_ylabel(r"pull-off force $\hat P_{po}$  ($\pi\Delta\gamma_0 R$)")
    ax.set_title(f"{path.name}: {len(ok)} ok, {len(df) - len(ok)} failed")
    ax.legend(fontsize=7)
    if has_traj:
        ax2 = axes[0, 1]
        # one colour per group of the left panel, darker for faster unloading
        color_of = {}
        for line in ax.get_lines():
            if line.get_label() and not line.get_label().startswith("JKR"):
                color_of[line.get_label()] = line.get_color()
        rates = np.log10(ok["rate"].astype(float))
        span = max(float(rates.max() - rates.min()), 1e-12)
        for _, row in ok.sort_values([*keys, "rate"] if keys else "rate").iterrows():
            tr = load_trajectory(path, str(row["scene_id"]))
            label = ", ".join(f"{k}={row[k]:g}" if isinstance(row[k], float) else f"{k}={row[k]}"
                              for k in keys)
            shade = 0.35 + 0.65 * (np.log10(float(row["rate"])) - float(rates.min())) / span
            ax2.plot(tr["a"], tr["P"], lw=1, color=color_of.get(label, "C0"), alpha=shade,
                     label=f"{label + ', ' if label else ''}rate={row['rate']:g}")
        a = np.linspace(0.5, max(3.0, float(ok["a0_result"].max())), 200)
        ax2.plot(a, jkr_load(a), "k--", lw=1, label="JKR (relaxed)")
        ax2.set_xlabel(r"contact radius $\hat a$")
        ax2.set_ylabel(r"load $\hat P$")
        ax2.set_title("trajectories P(a)")
        ax2.legend(fontsize=6)
    fig.tight_layout()
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=120)
    plt.close(fig)
    return out

"""Figures of a sweep's results (matplotlib, the optional ``plot`` extra).

``plot_sweep(path, out)`` draws what a user checks first after a run: the pull-off force
against the unloading rate and, when the sweep stored trajectories, the load against the
contact radius P(a) with the JKR curve for reference. :func:`sweep_figure` draws the same
from a results frame (:func:`sweep.load`).

A campaign varies several axes at once (the threshold campaign: n, a0 and the rate, 936
scenes), so one line per group in a colour cycle does not read. :func:`plot_layout` gives each
varying axis one role: the abscissa (the rate, or the numeric axis with the most values when
the rate is fixed); the colour (the numeric axis with the most values, on a colour bar with a
labelled band per value, or a continuous scale beyond :data:`BANDS_MAX` values; a categorical
axis such as the model gets legend entries instead); the panels (up to two further axes: a
row of panels, or rows x columns); line styles for a category or any axis left that still
splits the lines. A number fixed by the others (a0 by k in configs/v_vs_r.yaml) splits nothing
and is named in the panel titles. The legend sits below the panels, outside every plot; the
reference lines (JKR's relaxed pull-off 1.5 dashed, and the glassy 1.5/k dotted where the
data reach half of it) lie inside the plotted range, in black, and are labelled. Panels of one
k share their y range; pull-offs over :data:`LOG_PULL_OFF` times apart are drawn on a
logarithmic axis. Failed scenes are red crosses, at the bottom edge when they have no
pull-off (never dropped).
"""
from __future__ import annotations

import math
import textwrap
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..campaign.config import AXES
from ..campaign.store import load, load_trajectory
from ..errors import InputError, writing
from ..scene import AXES as AXIS_INFO
from ..theory import jkr_load

#: the relaxed (elastic) JKR pull-off, pi dg R: the floor of every amplified pull-off
JKR_PULL_OFF = 1.5
#: at most this many panels (a further axis that would exceed it gets line styles instead)
MAX_PANELS = 64
#: line styles of an axis beyond the colour and the panels (cycled if it has more values)
STYLES = (("-", "o"), ("--", "s"), (":", "^"), ("-.", "D"))


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


def figure_path(name: str, out) -> Path:
    """The path a figure given to option ``name`` is written to, checked before drawing.

    Parameters
    ----------
    name : str
        The option that gave the path (``out``, ``plot``), named in the error.
    out : str or Path
        The output file; its suffix is the format.

    Returns
    -------
    Path
        ``out``, with ``.png`` added when it has no suffix (what matplotlib writes then).

    Raises
    ------
    InputError
        When matplotlib cannot write the format of the suffix (one line with the formats
        it can write).
    """
    given = str(out)
    out = Path(out)
    if given.endswith(("/", "\\")):        # Path drops the slash: DIR.png beside DIR
        raise InputError(f"{name}: {given} names a directory; give a file in it, such as "
                         f"{out / 'figure.png'} (a name without a suffix is a .png)")
    if not out.suffix:
        out = out.with_name(out.name + ".png")
    fmt = out.suffix[1:].lower()
    pyplot()                                    # matplotlib, or how to install it
    from matplotlib.backend_bases import FigureCanvasBase

    formats = FigureCanvasBase.get_supported_filetypes()
    if fmt not in formats:
        raise InputError(f"{name}: cannot write a figure as {out.suffix!r} (got {str(out)!r}; "
                         f"suffixes: {', '.join('.' + f for f in sorted(formats))})")
    return out


def save_figure(fig, out, name: str = "out", dpi: int = 120) -> Path:
    """Write ``fig`` to ``out`` (creating its directory) and close it; one-line errors.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
    out : str or Path
        The output file (:func:`figure_path`).
    name : str, optional
        The option that gave the path, named in an error.
    dpi : int, optional

    Returns
    -------
    Path
        The path written.

    Raises
    ------
    InputError
        An unknown format, or a path that cannot be written (a missing or read-only
        directory, a parent that is a file, a directory; :func:`sweep.errors.writing`).
    """
    plt = pyplot()
    try:
        out = figure_path(name, out)
        with writing(name, out):
            out.parent.mkdir(parents=True, exist_ok=True)
            fig.savefig(out, dpi=dpi)
    finally:
        plt.close(fig)
    return out


def mark_failed(ax, df) -> int:
    """Mark the failed scenes of ``df`` on the pull-off-against-rate axes ``ax``: a red cross
    at their pull-off when they have one, else at the bottom of the axes at their rate (they
    are never dropped silently). Returns how many were marked."""
    return _mark_failed(ax, df, "rate")


def _mark_failed(ax, df, x: str) -> int:
    failed = df[df["status"] != "ok"]
    if not len(failed):
        return 0
    xs = failed[x].astype(float).to_numpy()
    po = failed["pull_off"].astype(float).to_numpy()
    has = np.isfinite(po) & np.isfinite(xs)
    label = f"failed ({len(failed)})"
    if has.any():
        ax.plot(xs[has], po[has], "x", color="red", ms=7, mew=1.5, ls="none", label=label)
        label = None
    if (~has).any():
        # no pull-off: on the x axis itself (not a load), x in data units, y in axes units
        ax.plot(xs[~has], np.zeros((~has).sum()), "x", color="red", ms=7, mew=1.5,
                ls="none", transform=ax.get_xaxis_transform(), clip_on=False,
                label=label or "_failed_no_pull_off")
    return len(failed)


def _distinct(series) -> list:
    """The distinct values of ``series``, sorted, a missing value (NaN/None) last."""
    present = series.dropna().unique().tolist()
    return sorted(present) + ([None] if series.isna().any() else [])


def _is_numeric(axis: str) -> bool:
    return AXIS_INFO[axis].numeric


#: short names of the axes whose help text is long or technical (the others: their help's
#: first words)
_AXIS_NAMES = {"a0": "initial contact radius", "delta0": "initial indentation",
               "k": "modulus ratio E0/Einf", "preload": "preload", "pz_v0": "process-zone speed",
               "pz_xi": "process-zone exponent", "machine_stiffness": "machine stiffness"}


def axis_label(axis: str) -> str:
    """An axis's label for an abscissa: its name, symbol and unit (``initial contact radius
    $\\hat a_0$ (a_ref)``); the short symbol of a colour bar or legend alone (``$\\hat
    a_0$``) had said neither what nor in what."""
    info = AXIS_INFO[axis]
    label = info.label
    if label.startswith("$") and label.endswith("$"):       # a bare symbol: name it
        name = _AXIS_NAMES.get(axis) or info.help.split(";")[0].split("(")[0].strip()
        label = f"{name} {label}"
    if info.unit and info.unit not in label:
        label += f" ({info.unit})"
    return label


def _text(axis: str, value) -> str:
    """``n = 0.4``, ``model = crack`` (a plain name: panel titles and legend entries)."""
    return f"{axis} = {value:g}" if isinstance(value, (float, int)) and not isinstance(
        value, bool) else f"{axis} = {value}"


@dataclass(frozen=True)
class PlotLayout:
    """The role of each scene axis that varies in a results frame (:func:`plot_layout`).

    Attributes
    ----------
    x : str
        The abscissa.
    colour : str or None
        The axis shown by colour (None when only the abscissa varies).
    panels : tuple of str
        The axes with a panel per combination of their values (at most two).
    styles : tuple of str
        The axes left that still split the lines: a line style (and marker) per combination.
    fixed : tuple of str
        Varying axes determined by the others (named in the panel titles).
    """

    x: str
    colour: str | None
    panels: tuple
    styles: tuple
    fixed: tuple


def _splits(df, keys: list, axis: str) -> bool:
    """Whether ``axis`` takes more than one value at some combination of ``keys``."""
    if not keys:
        return df[axis].nunique(dropna=False) > 1
    counts = df.groupby(keys, dropna=False)[axis].nunique(dropna=False)
    return bool((counts > 1).any())


def plot_layout(df) -> PlotLayout:
    """Which varying axis of the results frame ``df`` is the abscissa, the colour, the panels
    and the line styles (see the module's docstring)."""
    varying = [a for a in AXES if a in df and a != "rate" and AXIS_INFO[a].plot_group
               and df[a].nunique(dropna=False) > 1]
    count = {a: df[a].nunique(dropna=False) for a in varying}
    numeric = [a for a in varying if _is_numeric(a)]
    x = "rate"
    if df["rate"].nunique() <= 1 and numeric:
        x = max(numeric, key=lambda a: count[a])      # first of the most values, AXES order
        varying.remove(x)
        numeric.remove(x)
    colour = None
    if varying:
        colour = max(numeric or varying, key=lambda a: count[a])
    chosen = [x, colour] if colour else [x]
    panels, styles, fixed = [], [], []
    for axis in sorted((a for a in varying if a != colour), key=lambda a: -count[a]):
        if not _splits(df, chosen[1:], axis):
            # a number fixed by the others is named in the titles; a category (material,
            # model) keeps a line style of its own, where it tells two lines apart at a glance
            (styles if not _is_numeric(axis) else fixed).append(axis)
            continue
        n_panels = math.prod(count[a] for a in panels) * count[axis]
        (panels if len(panels) < 2 and n_panels <= MAX_PANELS else styles).append(axis)
        chosen.append(axis)
    return PlotLayout(x, colour, tuple(panels), tuple(styles), tuple(fixed))


#: a numeric colour axis with at most this many values gets a band per value on its colour
#: bar, each labelled; with more (a random sample), a continuous colour scale
BANDS_MAX = 20


def _colour_scale(axis: str | None, values: list):
    """``(colours, mappable)``: a colour per value of the colour axis, and the ScalarMappable
    of its colour bar (None for a categorical axis, which gets legend entries).

    Numeric: along viridis' dark-to-green part (every colour visible on white), a labelled
    band per value, or a continuous scale (logarithmic over two decades or more) for more
    than :data:`BANDS_MAX` values. Categorical: the tab10 cycle."""
    import matplotlib
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import BoundaryNorm, ListedColormap, LogNorm, Normalize

    if axis is None or not _is_numeric(axis):
        return [f"C{i % 10}" for i in range(len(values))], None
    cmap = ListedColormap(matplotlib.colormaps["viridis"](np.linspace(0.0, 0.9, 256)))
    known = [v for v in values if v is not None]
    if len(values) > BANDS_MAX and known:
        norm = (LogNorm if _log_scale(known) else Normalize)(min(known), max(known))
        return [cmap(norm(v)) if v is not None else "0.5" for v in values], \
            ScalarMappable(norm=norm, cmap=cmap)
    colours = [cmap(i / max(len(values) - 1, 1)) for i in range(len(values))]
    n = len(values)
    return colours, ScalarMappable(norm=BoundaryNorm(np.arange(n + 1), n),
                                   cmap=ListedColormap(colours))


def _colour_bar(fig, axes, axis: str, values: list, mappable):
    """The colour bar of ``axis`` beside ``axes``: each band labelled with its value."""
    banded = len(values) <= BANDS_MAX
    bar = fig.colorbar(mappable, ax=axes, fraction=0.05, pad=0.02,
                       aspect=max(20, 2 * len(values)) if banded else 20,
                       ticks=np.arange(len(values)) + 0.5 if banded else None)
    if banded:
        bar.ax.set_yticklabels(["nan" if v is None else f"{v:g}" for v in values])
    bar.ax.tick_params(labelsize=7, length=0 if banded else 3)
    bar.set_label(AXIS_INFO[axis].label)
    return bar


def _select(df, axes: tuple, key: tuple):
    """The rows of ``df`` whose ``axes`` take the values ``key`` (None matches NaN)."""
    mask = np.ones(len(df), dtype=bool)
    for axis, value in zip(axes, key):
        col = df[axis]
        mask &= (col.isna() if value is None else col == value).to_numpy()
    return df[mask]


def _log_scale(values) -> bool:
    """Positive values over 20 times or more: a logarithmic axis."""
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    return v.size > 0 and v.min() > 0 and v.max() / v.min() >= 20


def _grid(df, panels: tuple) -> tuple[list, int, int]:
    """The panel keys in reading order and the grid's rows and columns: one axis, a row of
    up to three panels or a near-square grid; two axes, a row per value of the first and a
    column per value of the second (a combination the sweep lacks stays empty, key None)."""
    keys = _panel_keys(df, panels)
    if len(panels) == 2:
        rows = _panel_keys(df, panels[:1])
        cols = _panel_keys(df, panels[1:])
        present = set(keys)
        keys = [r + c if r + c in present else None for r in rows for c in cols]
        return keys, len(rows), len(cols)
    ncols = len(keys) if len(keys) <= 3 else math.ceil(math.sqrt(len(keys)))
    return keys, math.ceil(len(keys) / ncols), ncols


def sweep_figure(df, title: str = "", trajectory=None):
    """The summary figure of a results frame (a :class:`matplotlib.figure.Figure`).

    Parameters
    ----------
    df : pandas.DataFrame
        Rows as :func:`sweep.load` returns them: the scene axes, ``status``, ``pull_off``
        (pi dg R), and with ``trajectory`` also ``scene_id`` and ``a0_result``.
    title : str
        The figure's title.
    trajectory : callable, optional
        ``scene_id -> {"a": ..., "P": ...}``: with it, a panel of the trajectories P(a).

    Returns
    -------
    matplotlib.figure.Figure
        Laid out by matplotlib's constrained layout; close it with ``plt.close(fig)``.
    """
    plt = pyplot()
    from matplotlib.ticker import LogFormatter

    lay = plot_layout(df)
    ok = df[df["status"] == "ok"]
    keys, nrows, ncols = _grid(df, lay.panels)
    size = (3.6, 2.9) if ncols <= 3 else (2.6, 2.2)
    width = ncols * size[0] + 1.4
    traj_w = 4.6 if trajectory is not None and len(ok) else 0.0
    fig = plt.figure(layout="constrained", figsize=(width + traj_w, nrows * size[1] + 1.3))
    left, right = fig.subfigures(1, 2, width_ratios=[width, traj_w]) if traj_w else (fig, None)
    # one x range for all panels, set below (matplotlib's sharex lays out the labels of n
    # shared panels in n^2 time: 56 panels of configs/scale.yaml took 20 s)
    axes = left.subplots(nrows, ncols, squeeze=False)
    colour_values = _distinct(df[lay.colour]) if lay.colour else [None]
    colours, mappable = _colour_scale(lay.colour, colour_values)
    colour_of = dict(zip(map(str, colour_values), colours))
    style_keys = _panel_keys(df, lay.styles)
    style_of = {k: STYLES[i % len(STYLES)] for i, k in enumerate(style_keys)}
    handles: dict = {}
    used = []
    keys = keys + [None] * (axes.size - len(keys))
    for ax, key in zip(axes.flat, keys):
        if key is None:
            ax.set_visible(False)
            continue
        used.append(ax)
        sub = _select(df, lay.panels, key)
        for ckey in colour_values:
            for skey in style_keys:
                g = _select(sub[sub["status"] == "ok"], (lay.colour,) * bool(lay.colour)
                            + lay.styles, (ckey,) * bool(lay.colour) + skey)
                if len(g):
                    g = g.sort_values(lay.x)
                    ls, marker = style_of[skey]
                    ax.plot(g[lay.x], g["pull_off"], ls=ls, marker=marker, ms=3, lw=1.1,
                            color=colour_of[str(ckey)])
        _mark_failed(ax, sub, lay.x)
        ax.set_title(", ".join([_text(a, v) for a, v in zip(lay.panels, key)]
                               + _fixed_text(sub, lay.fixed)), fontsize=8)
        ax.set_xscale("log" if lay.x == "rate" or _log_scale(df[lay.x]) else "linear")
        # axis labels on the grid's outer panels (x ticks below the lowest panel of each
        # column; each panel keeps its y ticks: the panels of different k differ in range)
        spec = ax.get_subplotspec()
        if spec.is_last_row() or keys[spec.num1 + ncols] is None:
            ax.set_xlabel(axis_label(lay.x), fontsize=8)
        else:
            ax.tick_params(labelbottom=False)
        if spec.is_first_col():
            ax.set_ylabel(r"pull-off $\hat P_{po}$ ($\pi\Delta\gamma_0 R$)", fontsize=8)
    _reference_lines(used, [_select(df, lay.panels, k) for k in keys if k is not None],
                     handles)
    xlim = (min(ax.get_xlim()[0] for ax in used), max(ax.get_xlim()[1] for ax in used))
    for ax in used:
        ax.set_xlim(xlim)
        if ax.get_yscale() == "log":      # plain numbers (20, 30, 100), not 2 x 10^1
            for which in ("major", "minor"):
                getattr(ax.yaxis, f"set_{which}_formatter")(LogFormatter(labelOnlyBase=False))
        ax.tick_params(which="both", labelsize=7)
        if len(used) > 9:
            ax.minorticks_off()           # small panels: the major ticks only
    if mappable is not None:
        _colour_bar(left, used, lay.colour, colour_values, mappable)
    elif lay.colour:
        for value, c in zip(colour_values, colours):
            handles[_text(lay.colour, value)] = _line(c, "-", "o")
    if lay.styles:
        for skey, (ls, marker) in style_of.items():
            handles[", ".join(_text(a, v) for a, v in zip(lay.styles, skey))] = \
                _line("0.3", ls, marker)
    failed = df[df["status"] != "ok"]
    if len(failed):
        # a failure without a pull-off sits on the x axis (not a load); several at one place
        # are one cross
        bare = int((~np.isfinite(failed["pull_off"].astype(float))).sum())
        handles[f"failed ({len(failed)}" + (f"; {bare} without a pull-off, on the x axis"
                                            if bare else "") + ")"] = _line("red", "none", "x")
    if right is not None:
        _trajectories(right, ok, lay, colour_of, trajectory, handles)
    # each line wrapped to the figure's width (a character at 10 pt: about 0.08 in), never
    # clipped; the title's own line breaks kept
    width = max(40, int(fig.get_figwidth() / 0.08))
    fig.suptitle("\n".join(textwrap.fill(line, width, break_long_words=False)
                           for line in title.split("\n")), fontsize=10)
    # as many columns as fit the figure's width (an entry: its text at 8 pt, about 0.065 in a
    # character, its line and the spacing)
    per_column = 0.065 * max(map(len, handles)) + 0.75
    fig.legend(list(handles.values()), list(handles), loc="outside lower center",
               ncols=max(1, min(len(handles), 4, int(fig.get_figwidth() / per_column))),
               fontsize=8, frameon=False)
    return fig


def _panel_keys(df, axes: tuple) -> list:
    """The combinations of ``axes`` present in ``df``, sorted (one empty key without axes)."""
    if not axes:
        return [()]
    rows = df[list(axes)].drop_duplicates()
    keys = {tuple(None if _missing(v) else v for v in row) for row in rows.itertuples(index=False)}
    return sorted(keys, key=lambda k: tuple((v is None, v if v is not None else 0) for v in k))


def _missing(value) -> bool:
    return value is None or (isinstance(value, float) and math.isnan(value))


def _fixed_text(sub, fixed: tuple) -> list:
    """``a0 = 11`` for each axis fixed by the others that has one value in the panel."""
    return [_text(a, sub[a].iloc[0]) for a in fixed
            if len(sub) and sub[a].nunique(dropna=False) == 1 and not _missing(sub[a].iloc[0])]


def _line(colour, ls, marker):
    from matplotlib.lines import Line2D

    return Line2D([], [], color=colour, ls=ls, marker=marker, ms=4 if marker != "x" else 7,
                  mew=1.5 if marker == "x" else 1.0)


#: pull-offs over this many times JKR's are drawn on a logarithmic axis
LOG_PULL_OFF = 100.0


def _reference_lines(axes: list, frames: list, handles: dict) -> None:
    """JKR's relaxed pull-off 1.5 on every panel and, where the panel's k is one and its
    pull-offs reach half of it, the glassy JKR pull-off 1.5/k. The y range of each panel
    holds its pull-offs and its reference lines with a margin (a reference line never sits
    on the frame), and is shared by the panels of one k (the pull-offs scale with 1/k); it is
    logarithmic on every panel when the largest value is :data:`LOG_PULL_OFF` times the
    smallest or more."""
    ranges, glassy_any = [], False
    for ax, sub in zip(axes, frames):
        po = sub["pull_off"].astype(float).to_numpy()
        po = po[np.isfinite(po)].tolist()
        ks = sub["k"].dropna().unique() if "k" in sub else []
        glassy = JKR_PULL_OFF / float(ks[0]) if len(ks) == 1 else math.nan
        shown = [JKR_PULL_OFF, *po]
        ax.axhline(JKR_PULL_OFF, color="black", ls="--", lw=1.0, zorder=1.5)
        if math.isfinite(glassy) and max(shown) >= 0.5 * glassy:
            ax.axhline(glassy, color="black", ls=":", lw=1.0, zorder=1.5)
            shown.append(glassy)
            glassy_any = True
        ranges.append((min(shown), max(shown), ks[0] if len(ks) == 1 else None))
    log = max(r[1] for r in ranges) / min(r[0] for r in ranges) >= LOG_PULL_OFF
    for ax, (lo, hi, k) in zip(axes, ranges):
        same = [r for r in ranges if r[2] == k]
        lo, hi = min(r[0] for r in same), max(r[1] for r in same)
        if log:
            ax.set_yscale("log")
            ax.set_ylim(lo / (hi / lo) ** 0.05, hi * (hi / lo) ** 0.05)
        else:
            pad = 0.06 * (hi - lo) if hi > lo else 0.5
            ax.set_ylim(lo - pad, hi + pad)
    handles[f"JKR relaxed pull-off, {JKR_PULL_OFF:g}"] = _line("black", "--", "none")
    if glassy_any:
        handles["JKR glassy pull-off, 1.5/k"] = _line("black", ":", "none")


#: the most panels whose trajectories get an axes each (more: drawn together on one)
TRAJECTORY_PANELS = 4


def _trajectories(fig, ok, lay: PlotLayout, colour_of: dict, trajectory, handles: dict):
    """P(a) of every ok scene on the right of ``fig`` (a subfigure): the colour of its line
    on the pull-off panels, darker for faster unloading; the relaxed JKR curve dashed. Scenes
    with a test protocol (a ``phase`` in their trajectory) draw their load cycle P(delta)
    instead: approach and dwell dotted, retraction solid. Each panel of the pull-offs has an
    axes of its own, titled as the panel is (up to :data:`TRAJECTORY_PANELS`; beyond, all
    are drawn on one axes and its title says so)."""
    keys = _panel_keys(ok, lay.panels)
    apart = 1 < len(keys) <= TRAJECTORY_PANELS
    axes = fig.subplots(len(keys) if apart else 1, 1, squeeze=False)[:, 0]
    rates = np.log10(ok["rate"].astype(float))
    span = float(rates.max() - rates.min())
    cycles = False
    for _, row in ok.sort_values("rate").iterrows():
        tr = trajectory(str(row["scene_id"]))
        key = row[lay.colour] if lay.colour else None
        ax = axes[keys.index(tuple(None if _missing(row[a]) else row[a] for a in lay.panels))
                  if apart else 0]
        shade = 0.35 + 0.65 * (math.log10(float(row["rate"])) - float(rates.min())) / span \
            if span > 0 else 1.0              # one rate: every line at full strength
        colour = colour_of[str(None if _missing(key) else key)]
        if "phase" in tr:                     # the load cycle of a test protocol
            cycles = True
            back = np.asarray(tr["phase"]) == 2
            ax.plot(tr["delta"][~back], tr["P"][~back], lw=1, ls=":", alpha=shade,
                    color=colour)
            ax.plot(tr["delta"][back], tr["P"][back], lw=1, alpha=shade, color=colour)
        else:
            ax.plot(tr["a"], tr["P"], lw=1, alpha=shade, color=colour)
    # beyond TRAJECTORY_PANELS the panels' axes are not told apart: the title says so
    together = (f"; every {', '.join(lay.panels)} together"
                if lay.panels and len(keys) > 1 and not apart else "")
    if cycles:
        head = "load cycles P(delta); dotted: approach, dwell" + together
    else:
        head = ("trajectories P(a)" + ("; darker: faster unloading" if span > 0 else "")
                + together)
    for i, ax in enumerate(axes):
        if not cycles:
            a = np.linspace(0.5, float(ok["a0_result"].max()), 200)
            ax.plot(a, jkr_load(a), color="black", ls="--", lw=1.0)
        panel = (", ".join(_text(a, v) for a, v in zip(lay.panels, keys[i])) if apart else "")
        ax.set_title("\n".join(t for t in (head if i == 0 else "", panel) if t), fontsize=8)
        if i == len(axes) - 1:
            ax.set_xlabel(r"indentation $\hat\delta$ ($d_{ref}$)" if cycles
                          else r"contact radius $\hat a$ ($a_{ref}$)", fontsize=8)
        ax.set_ylabel(r"load $\hat P$ ($\pi\Delta\gamma_0 R$)", fontsize=8)
        ax.tick_params(labelsize=7)
    jkr = f"JKR relaxed pull-off, {JKR_PULL_OFF:g}"      # one entry for both dashed lines
    merged = {(f"JKR relaxed: pull-off {JKR_PULL_OFF:g}, P(a)" if k == jkr and not cycles
               else k): h for k, h in handles.items()}
    handles.clear()
    handles.update(merged)


def _trajectory_reader(path: Path, ok):
    """``scene_id -> trajectory`` of the results file when it stores trajectories, else None."""
    if not len(ok):
        return None
    try:
        load_trajectory(path, str(ok["scene_id"].iloc[0]))
    except (KeyError, InputError, OSError):
        return None
    return lambda scene_id: load_trajectory(path, scene_id)


def plot_sweep(path, out=None) -> Path:
    """Write a PNG summary of the results file ``path``; returns the figure's path.

    Parameters
    ----------
    path : str or Path
        HDF5 results file of ``sweep run``.
    out : str or Path, optional
        Output PNG; default: the results file with the suffix ``.png``.
    """
    path = Path(path)
    df = load(path)
    if df.empty:
        raise InputError(f"results: {path} holds no finished scene")
    ok = df[df["status"] == "ok"]
    out = figure_path("out", out if out is not None else path.with_suffix(".png"))
    constant = ", ".join(constant_axes(df))
    fig = sweep_figure(df, f"{path.name}: {len(ok)} ok, {len(df) - len(ok)} failed"
                       + (f"\n{constant}" if constant else ""), _trajectory_reader(path, ok))
    return save_figure(fig, out)


def constant_axes(df) -> list[str]:
    """``k = 0.1``, ``mu = 3.24`` ... for each scene axis with one value over the results
    frame ``df`` (the figure's suptitle: what was run, which no panel or legend says); not
    ``n`` for a Prony table's scenes, where it is unused, nor an axis no row sets, nor a
    category at its default but the model and the material (``stop = pulloff``)."""
    table = "material" in df and df["material"].astype(str).str.startswith("prony:").all()
    out = []
    for axis in AXES:
        if axis not in df or (axis == "n" and table):
            continue
        values = df[axis].dropna()
        if len(values) and values.nunique() == 1:
            value = values.iloc[0]
            if (not _is_numeric(axis) and value == AXIS_INFO[axis].default
                    and axis not in ("model", "material")):
                continue
            out.append(_text(axis, float(value) if _is_numeric(axis) else value))
    return out

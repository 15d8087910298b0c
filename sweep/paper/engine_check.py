"""Committed results are main's results (issue 33 item 4): a committed campaign result records
what it was computed with, and a check says whether the engine on main still computes it.

Each result a campaign writes (``results/<campaign>/fit.json`` of the threshold and v-r fits,
``fig3.json``, ``aconv.json``) carries, beside its provenance (config name and hash, engine
version, git commit), an ``engine_check``: the numerics of its rows and a sample of its rows
(:func:`sample_rows`: up to :data:`SAMPLE_SIZE` of its cheapest scenes, spread over the grid,
and up to :data:`SAMPLE_FAILED` of its failed ones), with the status, pull-off and crack
speed the campaign computed for them.

:func:`check` runs those scenes again with those numerics and compares: the same status, the
pull-off within :data:`PULL_OFF_RTOL` and the crack speed within :data:`CRACK_SPEED_RTOL`;
and the campaign's config, as it resolves today, must still be the config the result was
computed from (its hash covers every scene id, hence the resolved numerics: a preset whose
values changed changes it). ``tests/paper/test_committed_results.py`` runs it in ``make test``
on every committed result, so a change of numerics or of the engine's numbers regenerates the
committed results (``make reproduce``) or is refused, instead of leaving a stale report. The
PDMS report (``results/pdms/pdms.json``, ``make pdms``) is checked there too: the campaign
fits it used must be the committed ones, and its crack-front curves are computed again at five
of its speeds.

The tolerances are above what the processor's last digits move in most rows (the same
scene in two processes gives the same bits, ``tests/engine/test_reproducible.py``; another
processor's BLAS rounds differently, which Newton's tolerance, 1e-6 h0 or finer, carries
into the pull-off at about that size) and below what a change of numerics moves: the Newton
tolerance from 1e-7 to 1e-6 h0 moved the threshold grid's pull-offs by up to 2.2e-5 and
crack speeds by up to 6.8e-4, a step or mesh change by 1e-4 or more (docs/performance.md).
In a few rows another processor moves the pull-off further: its BLAS fits another Prony
series, as valid (within the numerics' ``prony_rtol`` of the compliance), from the
disk-cached fits' nonnegative least squares, or pins the crack tip at a neighbouring node.
Measured with OpenBLAS's Sandybridge kernels and a fresh disk cache against results made
with its Haswell kernels (an AMD EPYC, 2026-11-27): 5 of the 28 sample rows moved, by
1.6e-5 to 1.4e-4 (at most 2 of a file's 8, the others by at most 5e-8), crack speeds by
up to 5e-4; with a kept disk cache every row within 3e-10. So at most a quarter of a
sample's rows (:data:`HOP_FRACTION`) may differ by up to the numerics' ``prony_rtol``
(1e-3 fast, 1e-4 balanced): an engine change that moves the rows systematically by more
than PULL_OFF_RTOL still fails the check, one that moves a few rows by less than
``prony_rtol`` does not.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from .._version import __version__
from ..scene import AXES, Numerics, Scene

__all__ = ["SAMPLE_SIZE", "SAMPLE_FAILED", "PULL_OFF_RTOL", "CRACK_SPEED_RTOL", "HOP_FRACTION",
           "COMMITTED", "sample_rows", "record", "rerun", "differences", "config_for"]

#: scenes of a campaign's sample (the cheapest, spread over the grid) and failed scenes in it
SAMPLE_SIZE = 8
SAMPLE_FAILED = 2
#: relative tolerances of the comparison (see the module docstring)
PULL_OFF_RTOL = 1e-5
CRACK_SPEED_RTOL = 1e-3
#: the fraction of a sample's rows whose pull-off may differ by more than PULL_OFF_RTOL, up
#: to the numerics' prony_rtol (module docstring)
HOP_FRACTION = 0.25
#: the committed results that carry a check, relative to the repository root
COMMITTED = ("results/threshold/fit.json", "results/vr/fit.json", "results/fig3/fig3.json",
             "results/aconv/aconv.json")
#: what a sample row keeps of the campaign's row
_SCENE_KEYS = tuple(AXES)


def sample_rows(df, size: int = SAMPLE_SIZE, failed: int = SAMPLE_FAILED) -> list[int]:
    """Positions (``df.iloc``) of the sample: the rows sorted by scene id (a fixed order
    that does not depend on the run), the cheaper half of the ``ok`` ones by wall time,
    ``size`` of them evenly spaced; and the first ``failed`` failed rows."""
    order = np.argsort(df["scene_id"].to_numpy(), kind="stable")
    ok = [i for i in order if df["status"].iloc[i] == "ok"]
    walls = np.array([float(df["wall_s"].iloc[i]) for i in ok])
    cheap = [i for i, w in zip(ok, walls) if w <= np.median(walls)] if ok else []
    picks = [cheap[int(j)] for j in np.unique(np.linspace(0, len(cheap) - 1, size).round())] \
        if cheap else []
    bad = [i for i in order if df["status"].iloc[i] == "failed"][:failed]
    return [int(i) for i in picks + bad]


def _row(scene: dict, res_like) -> dict:
    def num(x):
        x = float(x)
        return x if math.isfinite(x) else None
    return {"scene": scene, "status": str(res_like["status"]),
            "pull_off": num(res_like["pull_off"]), "crack_speed": num(res_like["crack_speed"])}


def record(runs, df=None) -> dict:
    """The ``engine_check`` of the campaign results file ``runs`` (its table ``df``, read if
    not given): engine version, the numerics of its rows, the sample with its values (none,
    and a note, where the rows ran with more than one set of numerics)."""
    from ..campaign.store import load, recorded_numerics

    df = load(runs) if df is None else df
    numerics = recorded_numerics(runs)
    if numerics is None:     # no check possible: make test refuses such a committed result
        return {"engine_version": __version__, "numerics": None, "rows": [],
                "note": "its rows ran with more than one set of numerics (or none)"}
    rows = []
    for i in sample_rows(df):
        r = df.iloc[i]
        scene = {k: (None if isinstance(r[k], float) and math.isnan(r[k]) else
                     (float(r[k]) if isinstance(r[k], (float, np.floating)) else r[k]))
                 for k in _SCENE_KEYS if k in df.columns}
        rows.append(_row(scene, r))
    return {"engine_version": __version__, "numerics": numerics.to_dict(), "rows": rows}


def rerun(check: dict, simulate=None) -> list[dict]:
    """The sample's scenes run again on this engine with the recorded numerics."""
    if simulate is None:
        from ..engine.models import simulate
    numerics = Numerics(**check["numerics"])
    out = []
    for row in check["rows"]:
        res = simulate(Scene(**row["scene"]), numerics)
        out.append(_row(row["scene"], {"status": res.status, "pull_off": res.pull_off,
                                       "crack_speed": res.crack_speed}))
    return out


def _rel(a, b) -> float:
    if a is None or b is None:
        return 0.0 if a is None and b is None else math.inf
    return abs(a - b) / max(abs(b), 1e-300)


def differences(recorded: list[dict], computed: list[dict], hop_rtol: float = 0.0) -> list[str]:
    """One line per sample row whose computed status, pull-off or crack speed differs from
    the recorded one beyond the tolerances: the pull-off within PULL_OFF_RTOL, except at
    most a quarter of the rows (HOP_FRACTION) within ``hop_rtol`` (the numerics'
    ``prony_rtol``: another processor's BLAS fits another valid Prony series, or pins the
    crack tip at a neighbouring node; module docstring); the crack speed within
    CRACK_SPEED_RTOL."""
    lines, hops = [], []
    for rec, now in zip(recorded, computed):
        what = []
        if rec["status"] != now["status"]:
            what.append(f"status {now['status']} (committed {rec['status']})")
        elif rec["status"] == "ok":
            rel = _rel(now["pull_off"], rec["pull_off"])
            if rel > PULL_OFF_RTOL:
                text = f"pull-off {now['pull_off']:.8g} (committed {rec['pull_off']:.8g})"
                if rel <= hop_rtol:
                    hops.append(f"{rec['scene']}: {text}, within {hop_rtol:g}")
                else:
                    what.append(text)
            if _rel(now["crack_speed"], rec["crack_speed"]) > CRACK_SPEED_RTOL:
                what.append(f"crack speed {now['crack_speed']:.6g} (committed "
                            f"{rec['crack_speed']:.6g})")
        if what:
            lines.append(f"{rec['scene']}: {', '.join(what)}")
    if len(hops) > HOP_FRACTION * len(recorded):
        lines += hops
    return lines


def config_for(name: str, configs: Path):
    """The campaign config named ``name`` under ``configs`` (its file's ``name:``), loaded;
    None when no config has that name."""
    from ..campaign.config import load_config
    import yaml

    for path in sorted(Path(configs).rglob("*.yaml")):
        try:
            doc = yaml.safe_load(path.read_text())
        except yaml.YAMLError:
            continue
        if isinstance(doc, dict) and doc.get("name") == name and "grid" in doc:
            return load_config(path)
    return None

"""Committed results are main's results (issue 33 item 4): every committed campaign result
records its config and a sample of its rows (sweep.paper.engine_check); its config must still
resolve to the same scenes and numerics, and main must still compute the sample's rows within
the stated tolerances. A failure here means: regenerate the result (the make target named in
the message) and commit it, or undo the change of numerics."""
from __future__ import annotations

import json
from pathlib import Path

import pandas as pd
import pytest

from sweep.paper import engine_check as ec

ROOT = Path(__file__).resolve().parents[2]

#: the make target that writes each committed result
TARGET = {"results/threshold/fit.json": "make threshold", "results/vr/fit.json": "make vr",
          "results/fig3/fig3.json": "make fig3", "results/aconv/aconv.json": "make figures"}


def test_every_committed_result_has_a_target():
    assert set(TARGET) == set(ec.COMMITTED)


@pytest.mark.parametrize("path", ec.COMMITTED)
def test_committed_result_is_what_main_computes(path):
    doc = json.loads((ROOT / path).read_text())
    check = doc.get("engine_check")
    assert check and check["rows"], f"{path} records no engine_check: run {TARGET[path]}"
    prov = doc["provenance"]
    cfg = ec.config_for(prov["config_name"], ROOT / "configs")
    assert cfg is not None, f"{path}: no config named {prov['config_name']!r} in configs/"
    assert cfg.config_hash == prov["config_hash"], (
        f"{path}: its config {prov['config_name']!r} now gives other scenes or numerics than "
        f"the result was computed with: run {TARGET[path]}")
    assert cfg.numerics.to_dict() == check["numerics"], path
    computed = ec.rerun(check)
    diffs = ec.differences(check["rows"], computed, hop_rtol=check["numerics"]["prony_rtol"])
    assert not diffs, (f"{path}: main computes other numbers than the committed result "
                       f"(run {TARGET[path]}):\n" + "\n".join(diffs))


def _rows(statuses, pull_offs, speeds=None):
    speeds = speeds or [1.0] * len(pull_offs)
    return [{"scene": {"n": 0.4 + i}, "status": s, "pull_off": p, "crack_speed": v}
            for i, (s, p, v) in enumerate(zip(statuses, pull_offs, speeds))]


def test_differences_within_and_beyond_the_tolerances():
    rec = _rows(["ok", "ok", "failed"], [2.0, 3.0, None], [1.0, 5.0, None])
    assert ec.differences(rec, _rows(["ok", "ok", "failed"], [2.0 * (1 + 5e-6), 3.0, None],
                                     [1.0, 5.0 * (1 + 5e-4), None])) == []
    lines = ec.differences(rec, _rows(["ok", "ok", "ok"], [2.0 * (1 + 2e-5), 3.0, 1.0],
                                      [1.0, 5.0 * (1 + 2e-3), 1.0]))
    assert len(lines) == 3
    assert "pull-off" in lines[0] and "crack speed" in lines[1]
    assert "status ok (committed failed)" in lines[2]


def test_a_quarter_of_the_rows_may_differ_by_up_to_the_prony_rtol():
    """Another processor's BLAS fits another valid Prony series (within prony_rtol) or pins
    the crack tip at a neighbouring node in a few rows (engine_check's docstring): up to a
    quarter of the sample within hop_rtol passes; more rows, or one row beyond it, fail."""
    rec = _rows(["ok"] * 8, [2.0 + i for i in range(8)])
    moved = lambda k, rel: _rows(["ok"] * 8, [(2.0 + i) * (1 + (rel if i < k else 0.0))  # noqa: E731
                                              for i in range(8)])
    assert ec.differences(rec, moved(2, 1.4e-4), hop_rtol=1e-3) == []
    assert len(ec.differences(rec, moved(3, 1.4e-4), hop_rtol=1e-3)) == 3
    assert len(ec.differences(rec, moved(1, 2e-3), hop_rtol=1e-3)) == 1
    assert len(ec.differences(rec, moved(1, 1.4e-4))) == 1         # no hop_rtol: none


def test_the_sample_is_cheap_spread_and_keeps_failed_rows():
    n = 40
    df = pd.DataFrame({"scene_id": [f"{i:04x}" for i in range(n)][::-1],
                       "status": ["failed" if i % 10 == 3 else "ok" for i in range(n)],
                       "wall_s": [float(i) for i in range(n)]})
    picks = ec.sample_rows(df, size=5, failed=2)
    shuffled = df.sample(frac=1.0, random_state=1).reset_index(drop=True)
    again = ec.sample_rows(shuffled, size=5, failed=2)          # the same scenes, any order
    assert [df.scene_id[i] for i in picks] == [shuffled.scene_id[i] for i in again]
    ok, bad = picks[:5], picks[5:]
    assert len(set(ok)) == 5 and all(df.status[i] == "ok" for i in ok)
    median = df.wall_s[df.status == "ok"].median()
    assert all(df.wall_s[i] <= median for i in ok)
    assert len(bad) == 2 and all(df.status[i] == "failed" for i in bad)


def test_committed_pdms_is_what_main_computes():
    """results/pdms/pdms.json (make pdms): the fits it used are the committed campaigns' fits,
    and main computes its crack-front curves again at five of its speeds, the pull-offs within
    engine_check.PULL_OFF_RTOL (issue 33 item 4)."""
    from sweep.paper import pdms

    doc = json.loads((ROOT / "results" / "pdms" / "pdms.json").read_text())
    fits = pdms.own_fits(ROOT)
    for key, fit in doc["fits"].items():
        assert fit["prefactor"] == pytest.approx(fits[key]["prefactor"], rel=1e-12), \
            f"results/pdms/pdms.json used another {key} fit than results/: run make pdms"
    speeds = doc["speeds_um_s"][::10]
    picks = list(range(0, len(doc["speeds_um_s"]), 10))
    for model in ("crack_pb", "crack_gs", "crack_pb_pz"):
        now = pdms.model_pull_off(model, speeds)["pull_off_mN"]
        then = [doc["pull_off_mN"][model][i] for i in picks]
        assert now == pytest.approx(then, rel=ec.PULL_OFF_RTOL), \
            f"results/pdms/pdms.json: main computes other {model} pull-offs: run make pdms"

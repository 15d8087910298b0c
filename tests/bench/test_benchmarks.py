"""The measurement harness of issue 9: Pareto fronts, preset suggestion, the plain numpy
solver against the engine's exact integrator, and the keys of bench.json (tiny plan).

No timing is asserted anywhere: only the logic that turns timings into figures."""
import json
import math

import numpy as np
import pytest

from sweep import Numerics, Scene
from sweep.engine.bem import simulate  # the BEM on the graded mesh (not the model dispatch)
from sweep.bench.benchmarks import (ROOT, BenchPlan, _bracket, bench_all, campaign_sample,
                              plain_time_at)
from sweep.campaign.config import load_config
from sweep.bench.plain_solver import plain_unload
from sweep.bench.tradeoff import (PRESETS, grid, numerics_fields, pareto_front, plot_pareto,
                            relative_error, suggest_presets, to_numerics, write_table)


def test_pareto_front_keeps_only_points_nothing_beats():
    cost = [1.0, 2.0, 3.0, 4.0, 0.5, 2.5]
    err = [1e-2, 1e-3, 2e-3, 1e-4, math.inf, 1e-3]
    front = pareto_front(cost, err)
    assert front == [0, 1, 3]            # 2 and 5 are beaten by 1; 4 failed (inf)
    # brute force: a point is on the front iff no other point is <= in both and < in one
    rng = np.random.default_rng(3)
    c, e = rng.random(40), rng.random(40)
    brute = sorted((i for i in range(40) if not any(
        (c[j] <= c[i] and e[j] <= e[i] and (c[j] < c[i] or e[j] < e[i])) for j in range(40))),
        key=lambda i: c[i])
    assert pareto_front(c, e) == brute


def test_relative_error_of_missing_values_is_infinite():
    assert relative_error(1.01, 1.0) == pytest.approx(0.01)
    assert relative_error(math.nan, 1.0) == math.inf
    assert relative_error(None, 1.0) == math.inf


def test_bracket_picks_plain_runs_on_either_side_of_the_engine_error():
    rows = [{"status": "ok", "err_pull_off": e, "wall_s": w}
            for e, w in ((5e-3, 0.1), (1e-3, 0.5), (2e-4, 2.0), (5e-5, 9.0))]
    rows.append({"status": "failed", "err_pull_off": math.inf, "wall_s": 0.01})
    b = _bracket(3e-4, rows)
    assert b["equal_or_worse"]["err_pull_off"] == 1e-3     # closest from above
    assert b["better"]["err_pull_off"] == 2e-4             # cheapest below
    assert _bracket(1e-6, rows)["better"] is None
    assert _bracket(1e-2, rows)["equal_or_worse"] is None


def test_plain_time_is_interpolated_on_the_frontier_of_the_plain_runs():
    rows = [{"status": "ok", "err_pull_off": e, "wall_s": w}
            for e, w in ((5e-3, 0.1), (1e-3, 0.5), (2e-3, 0.7), (2e-4, 2.0), (5e-5, 9.0))]
    rows.append({"status": "failed", "err_pull_off": math.inf, "wall_s": 0.01})
    # on a run: its time; between 1e-3 (0.5 s) and 2e-4 (2 s), a power law: at the
    # geometric mean of the errors, the geometric mean of the times
    assert plain_time_at(1e-3, rows) == pytest.approx(0.5)
    assert plain_time_at(math.sqrt(1e-3 * 2e-4), rows) == pytest.approx(1.0)
    # the dominated run (2e-3 at 0.7 s, worse and slower than 1e-3 at 0.5 s) is not used:
    # between 5e-3 and 1e-3 the law through (0.1, 0.5) gives 0.1 * 5**(log(2.5)/log(5))
    assert plain_time_at(2e-3, rows) == pytest.approx(0.1 * 2.5)
    assert plain_time_at(1e-5, rows) is None and plain_time_at(1e-2, rows) is None


def test_suggested_presets_are_cheapest_under_each_worst_case_target():
    rows = []
    for label, errs, wall in (("a", (1e-2, 2e-3), 0.1), ("b", (5e-4, 8e-4), 0.5),
                              ("c", (5e-5, 9e-5), 3.0), ("d", (1e-5, math.inf), 0.2)):
        for scene, e in zip(("s1", "s2"), errs):
            rows.append({"scene": scene, "label": label, "err_pull_off": e,
                         "err_crack_speed": e, "wall_s": wall})
    rows.append({"scene": "s1", "label": "only_one_scene", "err_pull_off": 0.0,
                 "err_crack_speed": 0.0, "wall_s": 0.0})
    s = suggest_presets(rows, targets=(1e-2, 1e-3, 1e-4, 1e-6))["suggested"]
    assert s["0.01"]["label"] == "a"
    assert s["0.001"]["label"] == "b"
    assert s["0.0001"]["label"] == "c"    # d fails on s2, "only_one_scene" is incomplete
    assert s["1e-06"] is None
    assert s["0.001"]["total_wall_s"] == pytest.approx(1.0)


def test_each_preset_is_set_beside_the_cheapest_numerics_with_an_error_estimate():
    """presets_on_front: per preset, the cheapest point meeting its target among the numerics
    that carry the error estimate (pull_off_rtol > 0): a cheaper point without it does not
    count, nor one whose grading (unseen by the estimate) differs; a cheaper point with it
    does (the preset is then off the front by the ratio), unless the error-coverage sample
    refused its numerics (REFUSED_BEYOND_THE_SCENES: da_max 2) or its crack speed misses the
    preset's crack-speed target (CRACK_SPEED_TARGETS)."""
    from sweep.bench.tradeoff import CRACK_SPEED_TARGETS, PRESET_TARGETS
    tgt = PRESET_TARGETS["balanced"]
    rows = []
    for label, err, wall, rtol, grading in (("balanced", 0.5 * tgt, 1.0, 0.01, 1.1),
                                            ("no_estimate", 0.1 * tgt, 0.1, 0.0, 1.1),
                                            ("other_grading", 0.1 * tgt, 0.2, 0.01, 1.3),
                                            ("cheaper", 0.9 * tgt, 0.5, 0.01, 1.1),
                                            ("refused", 0.9 * tgt, 0.3, 0.01, 1.1),
                                            ("slow_crack", 0.9 * tgt, 0.4, 0.01, 1.1),
                                            ("too_coarse", 2.0 * tgt, 0.05, 0.01, 1.1)):
        crack = 2.0 * CRACK_SPEED_TARGETS["balanced"] if label == "slow_crack" else err
        rows += [{"scene": sc, "label": label, "err_pull_off": err, "err_crack_speed": crack,
                  "wall_s": wall, "pull_off_rtol": rtol, "grading": grading, "tail_gap": 60.0,
                  "domain": None, "da_max": 2.0 if label == "refused" else 1.0}
                 for sc in ("s1", "s2")]
    got = suggest_presets(rows)
    on = got["presets_on_front"]["balanced"]
    assert on["cheapest"] == "cheaper" and on["meets_target"]
    assert on["wall_over_cheapest"] == pytest.approx(2.0)
    assert got["suggested"]["0.001"]["label"] == "no_estimate"    # the plain front: any point


def test_grid_has_the_presets_first_and_only_existing_fields():
    g = grid()
    assert [p["label"] for p in g[:len(PRESETS)]] == list(PRESETS)
    labels = [p["label"] for p in g]
    assert len(labels) == len(set(labels))
    have = numerics_fields() | {"preset"}
    assert all(set(p["overrides"]) <= have for p in g)
    dicts = [json.dumps(to_numerics(p["overrides"]).to_dict(), sort_keys=True) for p in g]
    assert len(dicts) == len(set(dicts))                     # no duplicate numerics
    assert any(to_numerics(p["overrides"]).exact for p in g)
    assert len(grid(quick=True)) < len(g)


def test_grid_holds_each_presets_neighbours():
    """Around fast and accurate, one field at a time (the front is searched beside each
    preset as well as around balanced)."""
    from sweep.bench.tradeoff import ACCURATE_ONE_AT_A_TIME, FAST_ONE_AT_A_TIME
    have = {json.dumps(to_numerics(p["overrides"]).to_dict(), sort_keys=True) for p in grid()}
    for preset, around in (("fast", FAST_ONE_AT_A_TIME), ("accurate", ACCURATE_ONE_AT_A_TIME)):
        for k, values in around.items():
            for v in values:
                want = to_numerics({"preset": preset, k: v}).to_dict()
                assert json.dumps(want, sort_keys=True) in have, (preset, k, v)


def test_tradeoff_times_in_rounds_and_keeps_the_best(monkeypatch):
    """Each numerics' runs are spread over the run (round after round over the grid), so a
    slower minute of the machine does not fall on one numerics only; the quickest run is
    kept, and the caches of meshes and starts are back to their sizes afterwards."""
    import types

    from sweep.bench import tradeoff as tr
    from sweep.engine import initial, mesh
    def sizes():                                # read by setting them back as they were
        m, r = mesh.set_mesh_cache_size(0), initial.set_relaxed_cache_size(0)
        mesh.set_mesh_cache_size(m), initial.set_relaxed_cache_size(r)
        return m, r
    before = sizes()
    calls = []

    def fake_simulate(scene, num):
        calls.append(json.dumps(num.to_dict(), sort_keys=True))
        wall = 1.0 / len(calls)                 # later runs quicker: the last round's kept
        return types.SimpleNamespace(status="ok", reason="", pull_off=1.0, crack_speed=1.0,
                                     wall_s=wall, steps=1, newton_iterations=1)

    monkeypatch.setattr(tr, "simulate", fake_simulate)
    monkeypatch.setattr(tr, "warm_up", lambda: None)
    monkeypatch.setattr(tr, "reference_for",
                        lambda *a, **k: {"pull_off": 1.0, "crack_speed": 1.0})
    report = tr.run_tradeoff(quick=True, repeat=3, progress=lambda m: None)
    n = len(tr.grid(quick=True))
    per_scene = 1 + 3 * n                       # the untimed warm-up, then three rounds
    assert len(calls) == 2 * per_scene
    first = calls[1:1 + n]
    assert calls[1 + n:1 + 2 * n] == first and calls[1 + 2 * n:per_scene] == first
    walls = [r["wall_s"] for r in report["rows"][:n]]
    assert walls == [1.0 / (1 + 2 * n + i + 1) for i in range(n)]
    assert sizes() == before


def test_table_and_pareto_png_are_written(tmp_path):
    rows = [{"scene": s, "label": lab, "err_pull_off": e, "err_crack_speed": 2 * e,
             "wall_s": w, "status": "ok"}
            for s in ("s1", "s2") for lab, e, w in (("fast", 1e-3, 0.1), ("x", 1e-4, 1.0),
                                                    ("y", math.inf, 0.5))]
    write_table(rows, tmp_path / "t.csv")
    lines = (tmp_path / "t.csv").read_text().splitlines()
    assert len(lines) == 1 + len(rows) and lines[0].startswith("scene,label")
    plot_pareto(rows, tmp_path / "p.png", {"s1": {"uncertainty_pull_off": 1e-5}})
    assert (tmp_path / "p.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_plain_solver_solves_the_same_discrete_problem_as_the_engine_exact_mode():
    """Same mesh, domain, fixed steps and exact hereditary integral: the two solvers (chord
    Newton in numpy, the engine's Woodbury Newton) must agree to the Newton tolerance."""
    scene = Scene(n=0.8, k=0.5, mu=3.24, delta0=1.0, rate=10.0)
    N, domain, step = 60, 2.5, 0.5
    plain = plain_unload(scene, N, domain, step, tol=1e-10)
    eng = simulate(scene, Numerics(nodes=N, domain=domain, step=step, exact=True,
                                   da_max=1e6, tol=1e-10, mesh="uniform", pull_off_rtol=0.0))
    assert plain.status == "ok" and eng.ok
    assert plain.steps == eng.steps
    assert plain.pull_off == pytest.approx(eng.pull_off, rel=1e-7)
    assert plain.crack_speed == pytest.approx(eng.crack_speed, rel=1e-5)


def test_plain_solver_needs_delta0():
    with pytest.raises(ValueError, match="delta0"):
        plain_unload(Scene(n=0.8, rate=1.0, a0=2.0), 60, 2.5, 0.5)


def test_random_sample_is_seeded_distinct_and_spans_the_grid():
    cfg = load_config(ROOT / "configs" / "scale.yaml")
    assert len(cfg.tasks()) == 10640
    a = campaign_sample(cfg, 200, seed=0)
    b = campaign_sample(cfg, 200, seed=0)
    scenes = [s for _, s in a.tasks()]
    assert scenes == [s for _, s in b.tasks()] and len(set(scenes)) == 200
    assert a.numerics == cfg.numerics
    for axis in ("n", "k", "rate", "delta0"):         # every value of every axis: no aliasing
        assert ({getattr(s, axis) for s in scenes}
                == {getattr(s, axis) for _, s in cfg.tasks()})


def test_dataset_sample_is_seeded_log_uniform_in_the_ranges_and_asks_for_the_accuracy():
    from sweep.bench.benchmarks import DATASET_RANGES, dataset_sample
    a, b = dataset_sample(60, seed=1), dataset_sample(60, seed=1)
    scenes = [s for _, s in a.tasks()]
    assert scenes == [s for _, s in b.tasks()] and len(set(scenes)) == 60
    assert scenes != [s for _, s in dataset_sample(60, seed=2).tasks()]
    assert a.numerics == Numerics.for_tolerance(0.01)
    assert {s.model for s in scenes} == {"bem"} and {s.material for s in scenes} == {"mpl"}
    for axis, (lo, hi) in DATASET_RANGES.items():
        v = np.log10([getattr(s, axis) for s in scenes])
        assert np.all((v >= np.log10(lo) - 1e-3) & (v <= np.log10(hi) + 1e-3)), axis
        # log-uniform: the sample reaches both halves of each range's decades
        mid = 0.5 * (np.log10(lo) + np.log10(hi))
        assert (v < mid).any() and (v > mid).any(), axis


def test_phase_timer_counts_each_phase_without_the_phases_nested_in_it(monkeypatch):
    """Exclusive times: a phase called inside another is subtracted from it (a fake clock)."""
    import types

    from sweep.bench import benchmarks as bm
    clock = types.SimpleNamespace(t=0.0)
    monkeypatch.setattr(bm.time, "perf_counter", lambda: clock.t)
    ns = types.SimpleNamespace()

    def outer():
        clock.t += 1.0
        ns.inner()
        ns.inner()
        clock.t += 2.0
        return "outer"

    def inner():
        clock.t += 5.0
    ns.outer, ns.inner = outer, inner
    monkeypatch.setattr(bm._PhaseTimer, "TARGETS", {"a": ((ns, "outer"),), "b": ((ns, "inner"),)})
    with bm._PhaseTimer() as timer:
        assert ns.outer() == "outer"
        ns.inner()
    assert timer.seconds == {"a": 3.0, "b": 15.0}
    assert timer.calls == {"a": 1, "b": 3}
    assert ns.outer is outer and ns.inner is inner          # put back


def test_dataset_campaign_counts_and_shares_add_up():
    from sweep.bench.benchmarks import bench_dataset_campaign
    plan = BenchPlan.tiny()
    rep = bench_dataset_campaign(plan)
    json.dumps(rep)
    n = plan.dataset_scenes
    assert rep["scenes"] == n and rep["numerics"]["pull_off_rtol"] == 0.03
    for label in ("first", "warm"):
        r = rep["rows"][label]
        assert r["scenes"] == r["ran"] == n == r["ok"] + r["failed"]
        assert sum(r["status_counts"].values()) == n
        assert sum(r["failure_reasons"].values()) == r["failed"]
        assert r["within_tolerance"] <= r["ok"]
        assert r["share_within_tolerance"] == pytest.approx(r["within_tolerance"] / n)
    assert rep["first_over_warm"] == pytest.approx(rep["first_s"] / rep["warm_s"])
    # every scene has k < 1: a first run fits Prony series, which the warm run reads
    assert rep["rows"]["first"]["prony_series_fitted"] >= 1
    assert rep["rows"]["warm"]["prony_series_fitted"] == 0
    prof = rep["profile"]
    assert prof["scenes"] == len(range(0, n, plan.dataset_profile_stride))
    assert prof["prony_series_fitted"] >= 1 and prof["calls"]["prony"] >= prof["scenes"]
    assert prof["calls"]["unload"] >= prof["scenes"]
    assert all(v >= 0.0 for v in prof["seconds"].values())
    assert sum(prof["share"].values()) == pytest.approx(1.0)
    assert sum(prof["seconds"].values()) <= prof["wall_s"]


def test_bench_json_keys_with_a_tiny_plan():
    plan = BenchPlan.tiny()
    rep = bench_all(plan, progress=lambda m: None)
    json.dumps(rep, default=str)
    assert set(rep["step_over_matvec"]) == {str(n) for n in plan.matvec_nodes}
    for row in rep["step_over_matvec_detail"].values():
        c = row["counters"]
        assert c["residual_matvecs_per_step"] >= 1.0          # at least one residual a step
        assert 0.0 < c["subset_fraction"] <= 1.0 and c["factorizations"] >= 1
    assert set(rep["prony_speedup"]) == {str(n) for n in plan.prony_steps}
    assert rep["compile_s"] is None                          # tiny: no fresh processes
    assert rep["scene_process_over_import"] is None
    assert rep["model_choice_ms"] > 0 and sum(rep["model_choice_detail"]["chosen"].values()) == 2000
    assert rep["scenes_per_minute"] > 0 and rep["parallel_speedup"] > 0
    sc = rep["scale_detail"]
    assert sc["sample"] == plan.scale_sample == sc["ran"] == sum(sc["status_counts"].values())
    assert sc["minutes_sample_rate"] == pytest.approx(sc["scenes"] * sc["wall_s"] / sc["sample"] / 60)
    assert set(sc["sequential_s"]) == {"cold", "warm"}
    assert 1 <= sc["start_groups"]["sample"] <= sc["start_groups"]["grid"]
    assert rep["scale_minutes"] == sc["minutes_estimate"] > 0
    dc = rep["dataset_campaign_detail"]
    assert rep["dataset_campaign"]["first_s"] == dc["first_s"] > 0
    assert rep["dataset_campaign"]["scenes"] == dc["rows"]["warm"]["ran"] == plan.dataset_scenes
    bc = rep["campaign_balanced_detail"]
    assert rep["campaign_balanced_s"] == bc["wall_s"] > 0
    assert bc["scenes"] == bc["ran"] == sum(bc["status_counts"].values()) >= 2
    assert sum(bc["scene_wall_s_by_a0"].values()) == pytest.approx(bc["scene_wall_s_sum"])
    assert set(rep["vs_numpy"]) == set(plan.vs_numpy_scenes)
    for by_cfg in rep["vs_numpy"].values():
        assert set(by_cfg) == set(plan.engine_numerics)
        for v in by_cfg.values():
            assert {"engine_s", "engine_err", "numpy_s", "numpy_err", "ratio"} <= set(v)
            if v["ratio"] is not None:                        # plain at equal or worse error
                assert v["numpy_err"] >= v["engine_err"]
                assert v["ratio"] == pytest.approx(v["numpy_s"] / v["engine_s"])
    d = rep["prony_speedup_detail"][str(plan.prony_steps[0])]
    assert d["prony_steps"] == d["exact_steps"]               # same fixed steps
    assert abs(d["pull_off_rel_diff"]) < 1e-2


def test_compare_results_reports_status_changes_and_relative_differences(tmp_path):
    # two results files of the same three scenes (plus one only in the first): one status
    # changed, the others differ by known relative amounts
    from sweep.bench.benchmarks import compare_results
    from sweep.campaign.store import ResultStore

    def write(path, rows):
        st = ResultStore(path, config_hash="synthetic", config_name="t",
                         config_text="name: t\n", n_scenes=len(rows))
        st.prepare(resume=False)
        st.begin(fresh=True)
        for row in rows:
            st.append(row)
        st.finish(complete=True)

    before = [dict(scene_id="a", status="ok", pull_off=2.0, crack_speed=1.0, wall_s=1.0),
              dict(scene_id="b", status="ok", pull_off=4.0, crack_speed=3.0, wall_s=2.0),
              dict(scene_id="c", status="ok", pull_off=1.0, crack_speed=1.0, wall_s=1.0),
              dict(scene_id="d", status="ok", pull_off=1.0, crack_speed=1.0, wall_s=1.0)]
    after = [dict(scene_id="a", status="ok", pull_off=2.002, crack_speed=1.0, wall_s=0.5),
             dict(scene_id="b", status="ok", pull_off=4.0, crack_speed=3.3, wall_s=1.0),
             dict(scene_id="c", status="failed", pull_off=float("nan"),
                  crack_speed=float("nan"), wall_s=0.1)]
    write(tmp_path / "before.h5", before)
    write(tmp_path / "after.h5", after)
    out = compare_results(tmp_path / "before.h5", tmp_path / "after.h5")
    assert out["scenes"] == 3 and out["only_before"] == 1 and out["only_after"] == 0
    assert out["status_changed"] == 1 and out["ok_in_both"] == 2
    assert out["pull_off"]["max_rel_diff"] == pytest.approx(1e-3)
    assert out["pull_off"]["median_rel_diff"] == pytest.approx(5e-4)
    assert out["crack_speed"]["max_rel_diff"] == pytest.approx(0.1)
    assert out["wall_s_sum"] == pytest.approx({"before": 4.0, "after": 1.6})


def test_newton_diagnosis_pairs_states_with_their_times():
    # on a smooth stretch of a small scene the cubic extrapolation through the accepted
    # states, at their times, must predict the next state closely in the contact interior
    # (a mismatched state or time makes it miss by O(h0)), and the chord map one step after
    # a factorization must contract
    from sweep.bench.benchmarks import newton_diagnosis
    out = newton_diagnosis(Scene(n=0.8, k=0.1, mu=3.24, delta0=3.6, rate=1e4),
                           Numerics.preset("fast"), at_step=30, ahead=3)
    rows = out["cubic_predictor_error_h0"]
    assert len(rows) == 3 and all(r["median"] < 1e-3 for r in rows)
    assert 0.0 <= out["chord_spectral_radius_after_steps"]["1"] < 0.5
    assert out["counters"]["newton_iterations_per_step"] >= 1.0


def test_scene_process_is_timed_against_the_imports_of_numpy_and_scipy():
    from sweep.bench.benchmarks import bench_scene_process

    rep = bench_scene_process(repeat=1)
    assert rep["command"].startswith("sweep scene --n=0.8") and "--preset fast" in rep["command"]
    assert rep["ratio"] == pytest.approx(rep["scene_process_s"] / rep["import_numpy_scipy_s"])
    assert rep["scene_process_s"] > rep["import_numpy_scipy_s"] > 0   # it imports both


def test_presets_derived_again_from_the_table_match_those_of_the_run(tmp_path):
    """`benchmarks tradeoff --from-table`: table.csv read back (numbers as floats, empty
    cells as None) gives the suggestions the in-memory rows gave."""
    import json as _json
    from sweep.bench.tradeoff import rederive_presets
    rows = [{"scene": sc, "label": lab, "err_pull_off": e, "err_crack_speed": e, "wall_s": w,
             "pull_off_rtol": 0.01, "grading": 1.1, "tail_gap": 60.0, "domain": None,
             "status": "ok"}
            for sc in ("s1", "s2") for lab, e, w in (("balanced", 5e-4, 1.0), ("x", 9e-4, 0.5))]
    write_table(rows, tmp_path / "table.csv")
    (tmp_path / "presets.json").write_text(_json.dumps({"wall_s": 1.0, "presets": {}}))
    got = rederive_presets(tmp_path)
    assert got == _json.loads(_json.dumps(suggest_presets(rows)))
    assert got["presets_on_front"]["balanced"]["cheapest"] == "x"
    doc = _json.loads((tmp_path / "presets.json").read_text())
    assert doc["wall_s"] == 1.0 and "presets_from" in doc

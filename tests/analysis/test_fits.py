"""sweep.analysis.fits on synthetic data with known answers, and the `sweep fit` commands."""
import json
import math

import numpy as np
import pandas as pd
import pytest
from scipy.optimize import brentq

from sweep.analysis import fits as an
from sweep import units
from sweep.cli import main
from sweep.errors import InputError
from sweep.campaign.store import ResultStore
from sweep.theory import pb_gamma_eff


# ------------------------------------------------------------------ power laws
def test_power_law_exact_data_recovers_constants():
    x = np.logspace(-2, 3, 12)
    fit = an.power_law_fit(x, 2.887 * x**1.171, n_boot=200)
    assert fit["prefactor"] == pytest.approx(2.887, rel=1e-12)
    assert fit["exponent"] == pytest.approx(1.171, rel=1e-12)
    assert fit["rms_log_residual"] < 1e-12
    # every resample of exact data gives the same line: zero-width intervals
    assert fit["exponent_ci"][1] - fit["exponent_ci"][0] < 1e-10


def test_power_law_noise_intervals_cover_truth_and_shrink_with_points():
    rng = np.random.default_rng(3)
    covered, widths = 0, {}
    for n_pts in (15, 120):
        for trial in range(20):
            x = np.logspace(0, 4, n_pts)
            y = 0.3 * x**2.7 * np.exp(rng.normal(0.0, 0.1, n_pts))
            fit = an.power_law_fit(x, y, n_boot=400, seed=trial)
            lo, hi = fit["exponent_ci"]
            covered += lo <= 2.7 <= hi
            widths.setdefault(n_pts, []).append(hi - lo)
            assert fit["prefactor_ci"][0] < fit["prefactor"] < fit["prefactor_ci"][1]
    # nominal 95 % coverage: at least 34 of 40 (binomial tail < 1e-3 if the coverage were 95 %)
    assert covered >= 34
    # the width of an exponent interval scales like 1/sqrt(points): 8x points, ~2.8x narrower
    ratio = np.mean(widths[15]) / np.mean(widths[120])
    assert 2.0 < ratio < 4.0


def test_power_law_bad_input():
    with pytest.raises(InputError, match="at least 3 points"):
        an.power_law_fit([1, 2], [1, 2])
    with pytest.raises(InputError, match="positive"):
        an.power_law_fit([1, 2, 3], [1, -2, 3])


def test_power_law_too_few_points_say_what_is_missing():
    """"needs at least 3 points with 2 distinct x (got 4)" did not say what was missing."""
    with pytest.raises(InputError) as info:
        an.power_law_fit([2.0, 2.0, 2.0, 2.0], [1, 2, 3, 4])
    assert str(info.value) == ("a power-law fit needs at least 2 distinct x (got 4 points, "
                               "all at x = 2)")
    with pytest.raises(InputError) as info:
        an.power_law_fit([1.0, 2.0], [1, 2])
    assert str(info.value) == "a power-law fit needs at least 3 points (got 2)"


def test_cli_fit_vr_names_the_selection_too_small_to_fit(tmp_path, capsys):
    """Two rates, 0.316 and 1, x 4 groups: 8 points, but the paper's rate range [1, 1e6]
    holds 4 at one rhat_PB. The error names that selection and what it lacks."""
    df = synthetic_vr_runs()
    df = df[df["rate"].isin(sorted(df["rate"].unique())[1:3])]
    path = tmp_path / "vr.h5"
    write_results(path, df)
    assert main(["fit", "vr", str(path), "--boot", "0"]) == 2
    err = capsys.readouterr().err
    assert err == ("error: MPL points at rates r-hat in [1, 1e+06]: a power-law fit needs at "
                   "least 2 distinct x (got 4 points, all at x = 0.143887)\n")


# ------------------------------------------------------------------ threshold radius
def saturating(a, plateau=12.0, length=0.6, a_start=1.0):
    """P(a) = plateau - c exp(-a/L): dP/da = (c/L) exp(-a/L) falls monotonically."""
    c = (plateau - 2.0) * math.exp(a_start / length)
    return plateau - c * np.exp(-np.asarray(a) / length), c


def test_threshold_radius_of_saturating_curve():
    length = 0.6
    a = np.arange(1.0, 8.01, 0.2)
    p, c = saturating(a, length=length)
    exact = length * math.log(c / (0.1 * length))   # (c/L) exp(-a/L) = 0.1
    res = an.threshold_radius(a, p)
    assert res["status"] == "interior"
    # spline interpolation error on a 0.2 grid: the derivative is good to ~1e-3 relative
    assert res["a0t"] == pytest.approx(exact, abs=5e-3)
    assert res["pull_off_at_a0t"] == pytest.approx(saturating(exact, length=length)[0], abs=1e-3)
    # the grid order does not matter
    perm = np.random.default_rng(0).permutation(a.size)
    assert an.threshold_radius(a[perm], p[perm])["a0t"] == pytest.approx(res["a0t"], abs=1e-12)


def test_threshold_takes_the_first_crossing_of_an_overshooting_curve():
    # rises, overshoots (peak near a = 3), settles from above to 10.5
    def p_of(a):
        return 10.5 + 2.5 * np.exp(-((a - 3.0) / 0.8) ** 2) - 9.0 * np.exp(-(a - 1.0) / 0.5)

    def dp_of(a):
        return (-2.5 * 2 * (a - 3.0) / 0.8**2 * np.exp(-((a - 3.0) / 0.8) ** 2)
                + 9.0 / 0.5 * np.exp(-(a - 1.0) / 0.5))

    fine = np.linspace(1.0, 8.0, 100001)
    first = fine[np.argmax(dp_of(fine) < 0.1)]
    exact = brentq(lambda s: dp_of(s) - 0.1, first - 1e-3, first)
    a = np.arange(1.0, 8.01, 0.1)
    res = an.threshold_radius(a, p_of(a))
    assert res["status"] == "interior"
    assert res["a0t"] == pytest.approx(exact, abs=5e-3)
    assert res["peak_a0"] == pytest.approx(fine[np.argmax(p_of(fine))], abs=2e-2)
    assert res["overshoot"] == pytest.approx(p_of(fine).max() / p_of(8.0) - 1.0, rel=1e-2)


def test_threshold_edges():
    a = np.linspace(1.0, 8.0, 15)
    flat = an.threshold_radius(a, 1.5 + 0.01 * a)          # slope 0.01 everywhere
    assert flat["status"] == "at_lower_edge" and flat["a0t"] == 1.0
    steep = an.threshold_radius(a, 0.5 * a**2)             # slope >= 1 everywhere
    assert steep["status"] == "not_reached" and math.isnan(steep["a0t"])
    with pytest.raises(InputError, match="at least 4 distinct"):
        an.threshold_radius([1, 2, 3], [1, 2, 3])


def synthetic_threshold_runs(prefactor=0.3, exponent=2.7, k=0.1, length=0.5):
    """Runs table of an a0 sweep whose groups have thresholds on P = A a0t^B exactly.

    Group j: P(a) = Pinf - c exp(-a/L) with dP/da = 0.1 at a_t, P(a_t) = A a_t^B, i.e.
    c = 0.1 L exp(a_t/L) and Pinf = A a_t^B + 0.1 L.
    """
    a = np.round(np.arange(1.0, 8.001, 0.1), 10)
    rows = []
    for j, a_t in enumerate([1.6, 2.0, 2.4, 2.8, 3.2, 3.6, 4.3, 5.0]):
        c = 0.1 * length * math.exp(a_t / length)
        p_inf = prefactor * a_t**exponent + 0.1 * length
        for n in (0.4, 1.6):
            for ai in a:
                rows.append({"material": "mpl", "n": n, "k": k, "mu": 3.24, "rate": 10.0**j,
                             "a0": ai, "a0_inner": 0.8 * ai, "status": "ok",
                             "pull_off": p_inf - c * math.exp(-ai / length),
                             "crack_speed": 1.0})
    rows.append({**rows[0], "status": "failed", "pull_off": float("nan")})
    return pd.DataFrame(rows)


def test_collapse_fit_recovers_the_power_law():
    df = synthetic_threshold_runs()
    table = an.threshold_table(df)
    assert len(table) == 16 and set(table["status"]) == {"interior"}
    fit = an.collapse_fit(table, saturation_fraction=0.9, n_boot=300)
    # a_t = 4.3 and 5.0 give P = 15.4 and 23.0 > 13.5 = 0.9 * 15: dropped; 6 x 2 n remain
    assert fit["n_points"] == 12
    assert fit["prefactor"] == pytest.approx(0.3, rel=2e-2)
    assert fit["exponent"] == pytest.approx(2.7, abs=1e-2)
    # a0t_inner = 0.8 a0t: same exponent, prefactor scaled by 0.8^-B
    inner = an.collapse_fit(table, 0.9, radius="a0t_inner", n_boot=0)
    assert inner["exponent"] == pytest.approx(fit["exponent"], rel=1e-6)
    assert inner["prefactor"] == pytest.approx(fit["prefactor"] * 0.8 ** -fit["exponent"],
                                               rel=1e-3)
    out = an.threshold_analysis(df, n_boot=100)
    assert out["failed"] == 1 and out["scenes"] == len(df)
    assert out["prefactor_no_pi"] == pytest.approx(
        out["prefactor"] * math.pi ** (-out["exponent"] / 3), rel=1e-12)
    rules = [r["rule"] for r in out["sensitivity"]]
    assert rules[0].endswith("(chosen)") and len(rules) == len(an.SENSITIVITY_RULES)
    assert sum(r["in_fit"] for r in out["table"]) == out["n_points"]
    json.dumps(out)  # JSON-ready


# ------------------------------------------------------------------ v-r fit, PB vs BEM
def synthetic_vr_runs(alpha_true=units.ALPHA_PB, noise=0.0, seed=1):
    """Scenes whose crack speed follows vhat = 3 rhat^1.1 and whose pull-off is exactly PB's
    Gamma_eff(vhat) with vhat measured using alpha_true."""
    rng = np.random.default_rng(seed)
    rows = []
    mu = 3.24
    for n in (0.4, 1.6):
        for k in (0.05, 0.1):
            for rate in np.logspace(-1, 6, 15):
                rhat = units.rhat_pb(rate, mu)
                vhat = 3.0 * rhat**1.1 * math.exp(rng.normal(0, noise)) if noise else \
                    3.0 * rhat**1.1
                rows.append({"material": "mpl", "n": n, "k": k, "mu": mu, "rate": rate,
                             "status": "ok",
                             "crack_speed": vhat * units.l0_hat(mu, alpha_true),
                             "pull_off": 1.5 * float(pb_gamma_eff(n, k, vhat))})
    return pd.DataFrame(rows)


def test_paper_variables_use_units():
    df = synthetic_vr_runs()
    d = an.paper_variables(df)
    row = d.iloc[7]
    assert row["h0"] == units.h0_hat(3.24) and row["l0"] == units.l0_hat(3.24)
    assert row["rhat_pb"] == pytest.approx(float(units.rhat_pb(row["rate"], 3.24)), rel=1e-15)
    assert row["vhat"] == pytest.approx(
        float(units.vhat_from_crack_speed(row["crack_speed"], 3.24)), rel=1e-15)
    assert row["gamma_eff"] == pytest.approx(row["pull_off"] / 1.5, rel=1e-15)


def test_vr_fit_and_pb_comparison_on_exact_data():
    df = synthetic_vr_runs()
    fits = an.vr_fit(df, n_boot=100)
    assert fits["all"]["prefactor"] == pytest.approx(3.0, rel=1e-10)
    assert fits["all"]["exponent"] == pytest.approx(1.1, rel=1e-10)
    assert fits["unsaturated"]["n_points"] < fits["all"]["n_points"]
    pts, comp = an.pb_comparison(df, 3.0, 1.1)
    # the pull-offs ARE PB at the measured speed, and the speed IS the fit: no error
    for way in ("measured", "predicted"):
        assert comp[way]["share_within_15pct"] == 1.0
        assert comp[way]["max_abs_error"] < 1e-9
    # a wrong speed law is seen by the predicted way only
    _, comp2 = an.pb_comparison(df, 30.0, 1.1)
    assert comp2["measured"]["max_abs_error"] < 1e-9
    assert comp2["predicted"]["median_abs_error"] > 0.05


def test_best_alpha_recovers_the_alpha_of_the_data():
    # synthetic pull-offs made with alpha = 0.5: the fit must find 0.5, not pi/9
    df = synthetic_vr_runs(alpha_true=0.5)
    res = an.best_alpha(df)
    assert res["alpha_best"] == pytest.approx(0.5, rel=1e-3)
    assert res["rms_log_error_best"] < 1e-4 < res["rms_log_error_paper_alpha"]
    out = an.vr_analysis(synthetic_vr_runs(noise=0.05), n_boot=100, paper_fit=(2.887, 1.171))
    lo, hi = out["exponent_ci"]
    # coverage is tested above; here: within 4 standard errors (sigma ~ CI width / 3.92)
    assert abs(out["exponent"] - 1.1) < 4 * (hi - lo) / 3.92
    assert out["alpha_best"] == pytest.approx(units.ALPHA_PB, rel=1e-3)
    assert "predicted_paper_fit" in out["pb_vs_bem"]
    json.dumps(out)


def test_pb_regimes_linear_slope_is_the_small_speed_limit():
    for n in (0.2, 0.8, 1.6):
        reg = an.pb_regimes(n, 1e-3)
        # Gamma - 1 = (1-k) pi n v + O(v^2 ...): within 2 % over v <= 1e-2
        assert reg["q1"] == pytest.approx(reg["q1_limit"], rel=2e-2)
        assert 0.0 < reg["m2"] < 1.0
    law = an.pb_power_law(0.8, 0.1)
    assert 0.0 < law["m"] < 1.0 and law["max_rel_error"] < 0.2


# ------------------------------------------------------------------ CLI
def write_results(path, df, **attrs):
    """``df`` as a complete results file; ``attrs``: the store's own (config_source, ...)."""
    st = ResultStore(path, **{"config_hash": "synthetic", "config_name": "t",
                              "config_text": "name: t\n", **attrs}, n_scenes=len(df))
    st.prepare(resume=False)
    st.begin(fresh=True)
    for i, row in enumerate(df.to_dict("records")):
        st.append({"scene_id": f"s{i:05d}", **row})
    st.finish(complete=True)


def test_cli_fit_threshold_and_vr(tmp_path, capsys):
    tpath = tmp_path / "thr.h5"
    write_results(tpath, synthetic_threshold_runs())
    assert main(["fit", "threshold", str(tpath), "--json", "--boot", "50"]) == 0
    out = json.loads(capsys.readouterr().out)
    for key in ("prefactor", "exponent", "prefactor_ci", "exponent_ci", "n_points", "rule",
                "sensitivity", "table"):
        assert key in out
    assert out["exponent"] == pytest.approx(2.7, abs=1e-2)
    assert main(["fit", "threshold", str(tpath), "--boot", "0"]) == 0
    text = capsys.readouterr().out
    assert "P_po = A a0t^B" in text and "paper's protocol: A = " in text
    assert "smallest unloading rate considered" in text and "B per n" in text

    vpath = tmp_path / "vr.h5"
    write_results(vpath, synthetic_vr_runs())
    assert main(["fit", "vr", str(vpath), "--json", "--boot", "50"]) == 0
    out = json.loads(capsys.readouterr().out)
    for key in ("prefactor", "exponent", "prefactor_ci", "exponent_ci",
                "pb_share_within_15pct", "alpha_best", "n_points"):
        assert key in out
    assert out["exponent"] == pytest.approx(1.1, rel=1e-9)
    assert main(["fit", "vr", str(vpath)]) == 0
    text = capsys.readouterr().out
    assert "alpha_best" in text and "alpha_best per k: k = 0.05" in text
    assert "paper's rate range r-hat in [1, 1e+06]: A = 3 " in text and "local slope" in text


@pytest.mark.parametrize("args, word", [
    (["fit", "threshold", "missing.h5"], "results"),
    (["fit", "vr", "NOTAFILE"], "results"),
    (["fit", "threshold", "THR", "--slope", "-1"], "slope"),
    (["fit", "vr", "THR", "--boot", "many"], "boot"),
    (["fit", "vr", "THR", "--saturation", "0"], "saturation"),
    (["fit", "threshold", "TEXT"], "results"),
])
def test_cli_fit_bad_input_one_line_exit_2(tmp_path, capsys, args, word):
    thr = tmp_path / "thr.h5"
    write_results(thr, synthetic_threshold_runs())
    text = tmp_path / "text.h5"
    text.write_text("not hdf5\n")
    args = [str(thr) if a == "THR" else str(text) if a == "TEXT" else a for a in args]
    before = thr.read_bytes()
    assert main(args) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("error: ") and word in err and "\n" not in err
    assert thr.read_bytes() == before


# ------------------------------------------------------------------ the paper's protocols
def protocol_table():
    """A threshold table whose points on the paper's protocol (rate >= 10^0.5, P(a0t) below
    0.5 x 1.5/k = 7.5) lie exactly on P = 0.3 a0t^2.7, while the slow rates (r-hat = 1) sit
    20 % high and the points near the plateau 5 % low (the bend toward saturation)."""
    rows = []
    for n, radii in ((0.4, (1.6, 2.0, 2.4, 2.7)), (1.6, (1.8, 2.2, 2.6, 3.4, 4.0))):
        for j, a in enumerate(radii):
            for rate in (1.0, 10.0 ** (0.5 + j)):
                p = 0.3 * a**2.7
                if rate < 3.0:
                    p *= 1.2
                elif p > 7.5:
                    p *= 0.95
                rows.append({"material": "mpl", "n": n, "k": 0.1, "mu": 3.24, "rate": rate,
                             "a0t": a, "pull_off_at_a0t": p, "pull_off_plateau": 1.02 * p,
                             "a0t_inner": 0.8 * a, "status": "interior", "saturation": 15.0})
    rows.append({**rows[0], "status": "at_lower_edge", "pull_off_at_a0t": 99.0})
    return pd.DataFrame(rows)


def test_paper_protocol_recovers_the_line_its_rule_selects():
    table = protocol_table()
    pp = an.paper_protocol_fit(table, paper_exponent=2.7, n_boot=200)
    # kept: rate >= 10^0.5 and P < 7.5: n = 0.4 radii 1.6..2.7 (P <= 4.4), n = 1.6 radii
    # 1.8, 2.2, 2.6 (P(3.4) = 0.95 x 8.16 = 7.75 > 7.5 is dropped): 7 points, on the line
    assert pp["n_points"] == 7
    assert pp["A"] == pytest.approx(0.3, rel=1e-10) and pp["B"] == pytest.approx(2.7, rel=1e-10)
    assert pp["B_ci"][1] - pp["B_ci"][0] < 1e-8
    # the radius in (R^2 dg/E0*)^(1/3) is a_ref / pi^(1/3) ... times pi^(1/3) larger
    assert pp["A_no_pi"] == pytest.approx(0.3 * math.pi ** (-2.7 / 3), rel=1e-10)
    assert pp["A_at_B_fixed"] == pytest.approx(0.3, rel=1e-10)
    assert pp["A_no_pi_at_B_fixed"] == pytest.approx(0.3 * math.pi ** -0.9, rel=1e-10)
    assert [s["choice"] for s in pp["sources"]][0] == "rate >= 10^0.5"
    assert "smallest unloading rate considered" in pp["sources"][0]["paper"]
    # per n under the same rule: both n on the line
    per_n = {r["n"]: r for r in pp["per_n"]}
    assert per_n[0.4]["B"] == pytest.approx(2.7, rel=1e-10) and per_n[0.4]["n_points"] == 4
    assert per_n[1.6]["B"] == pytest.approx(2.7, rel=1e-10) and per_n[1.6]["n_points"] == 3
    # the project's rule keeps the slow and the bent points: another line
    proj = an.collapse_fit(table, 0.9, n_boot=0)
    assert proj["n_points"] > pp["n_points"] and abs(proj["exponent"] - 2.7) > 0.05
    # the cuts table: the 0.9 cut at rate >= 10^0.5 takes the bent points (7.75, 12.0 < 13.5)
    cut = {(r["ordinate"], r["saturation_fraction"]): r for r in pp["cuts"]}
    assert cut[("pull_off_at_a0t", 0.5)]["B"] == pytest.approx(pp["B"], rel=1e-12)
    assert cut[("pull_off_at_a0t", 0.9)]["B"] < 2.65
    # the plateau ordinate 1.02 P: same exponent, prefactor 1.02 x
    assert cut[("pull_off_plateau", 0.5)]["A"] == pytest.approx(0.306, rel=1e-9)
    with pytest.raises(InputError, match="saturation_fraction"):
        an.paper_protocol_fit(table, protocol={"saturation_fraction": 0.0})


def test_radius_unit_check_tells_a_factor_from_an_offset():
    table = protocol_table()
    table = table[table["rate"] > 3].copy()
    a = table["a0t"].to_numpy()
    # a line in a unit pi^(1/3) smaller: the same pull-offs at radii pi^(1/3) a0t
    table["pull_off_at_a0t"] = 0.3 * (math.pi ** (1 / 3) * a) ** 2.7
    res = an.radius_unit_check(table, 0.3, 2.7, saturation_fraction=10.0)
    assert res["ratio_mean"] == pytest.approx(math.pi ** (1 / 3), rel=1e-12)
    assert res["ratio_std"] < 1e-12 and res["line_intercept"] == pytest.approx(0.0, abs=1e-9)
    assert res["offset_max"] - res["offset_min"] > 0.5
    # an additive offset of 0.5: constant difference, a ratio that falls with a0t
    table["pull_off_at_a0t"] = 0.3 * (a + 0.5) ** 2.7
    res = an.radius_unit_check(table, 0.3, 2.7, saturation_fraction=10.0)
    assert res["offset_min"] == pytest.approx(0.5, rel=1e-10)
    assert res["offset_max"] == pytest.approx(0.5, rel=1e-10)
    assert res["ratio_std"] > 0.02 and res["line_slope"] == pytest.approx(1.0, rel=1e-10)
    with pytest.raises(InputError, match="prefactor"):
        an.radius_unit_check(table, -1.0, 2.7)


def test_threshold_analysis_carries_both_protocols():
    out = an.threshold_analysis(synthetic_threshold_runs(), n_boot=50, paper_fit=(0.3, 2.7))
    pp = out["paper_protocol"]
    for key in ("A", "B", "A_ci", "B_ci", "A_no_pi", "n_points", "rule", "per_n", "cuts"):
        assert key in pp
    # synthetic thresholds on P = 0.3 a0t^2.7: both rules find the line; the paper's keeps
    # rates >= 10^0.5 (groups j >= 1) with P < 7.5 (a_t = 2.0 .. 3.2): 4 groups x 2 n
    assert pp["n_points"] == 8 and pp["B"] == pytest.approx(2.7, abs=1e-2)
    assert sum(r["in_paper_fit"] for r in out["table"]) == pp["n_points"]
    assert out["radius_unit"]["ratio_mean"] == pytest.approx(1.0, abs=2e-3)
    assert {r["n"] for r in out["per_n"]} == {0.4, 1.6}
    json.dumps(out)


def two_law_vr_runs():
    """vhat = 3 rhat^1.1 for rate >= 1 and 5 rhat^1 below (the slow points the paper's grid
    does not have)."""
    df = synthetic_vr_runs()
    rhat = units.rhat_pb(df["rate"].to_numpy(), 3.24)
    slow = df["rate"].to_numpy() < 1 - 1e-9
    vhat = np.where(slow, 5.0 * rhat, 3.0 * rhat**1.1)
    df["crack_speed"] = vhat * units.l0_hat(3.24)
    return df


def test_vr_paper_range_keeps_the_paper_rates_only():
    df = two_law_vr_runs()
    pr = an.vr_paper_range(df, n_boot=50)
    # rates 10^(-1 + j/2): j >= 2 are >= 1: 13 of 15 rates x 4 groups
    assert pr["n_points"] == 52 and pr["rate_range"] == [1.0, 1e6]
    assert pr["prefactor"] == pytest.approx(3.0, rel=1e-10)
    assert pr["exponent"] == pytest.approx(1.1, rel=1e-10)
    everything = an.vr_fit(df, n_boot=0)["all"]
    assert abs(everything["exponent"] - 1.1) > 0.01
    ranges = {tuple(r["rate_range"]): r for r in pr["ranges"]}
    assert ranges[(1.0, 1e4)]["exponent"] == pytest.approx(1.1, rel=1e-10)
    assert ranges[(0.1, 1e6)]["n_points"] == 60
    assert "10^0,10^6" in pr["source"]
    with pytest.raises(InputError, match="rate_range"):
        an.vr_paper_range(df, rate_range=(10.0, 1.0))


def test_vr_local_slope_and_ratio():
    ls = an.vr_local_slope(two_law_vr_runs())
    assert len(ls) == 15 and math.isnan(ls[0]["slope_median"])
    rhat = [r["rhat_pb"] for r in ls]
    for i, r in enumerate(ls):
        if r["rate"] >= 1.0 - 1e-9:
            assert r["v_over_r_median"] == pytest.approx(3.0 * rhat[i] ** 0.1, rel=1e-10)
        if r["rate"] > 1.0 + 1e-9:           # both neighbours on the 3 rhat^1.1 law
            assert r["slope_median"] == pytest.approx(1.1, rel=1e-10)
            assert r["slope_max"] == pytest.approx(1.1, rel=1e-10)
    assert ls[1]["slope_median"] == pytest.approx(1.0, rel=1e-10)    # on 5 rhat
    assert ls[0]["v_over_r_median"] == pytest.approx(5.0, rel=1e-10)


def test_vr_local_slope_of_a_grid_with_several_a0_per_rate():
    """A threshold-style grid (several a0 per (n, k, rate)): the local slope pooled the a0 of
    one rate, dividing by ln rhat - ln rhat = 0 (numpy's "divide by zero" warning, slopes
    -inf). Each a0 is its own curve: vhat = c(a0) rhat^1.1 has the slope 1.1 everywhere."""
    import warnings

    frames = []
    for a0, c in ((2.0, 3.0), (3.0, 4.0), (5.0, 6.0)):
        df = synthetic_vr_runs()
        df["a0"] = a0
        df["crack_speed"] *= c / 3.0
        frames.append(df)
    df = pd.concat(frames, ignore_index=True)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ls = an.vr_local_slope(df)
        out = an.vr_analysis(df, n_boot=0)
    assert len(ls) == 15 and math.isnan(ls[0]["slope_median"])
    for r in ls[1:]:
        assert r["n_groups"] == 12                       # 2 n x 2 k x 3 a0
        for key in ("slope_median", "slope_min", "slope_max"):
            assert r[key] == pytest.approx(1.1, rel=1e-10)
    assert out["local_slope"] == ls


def test_alpha_per_k_recovers_each_k():
    a = synthetic_vr_runs(alpha_true=0.5)
    b = synthetic_vr_runs(alpha_true=units.ALPHA_PB)
    df = pd.concat([a[a["k"] == 0.05], b[b["k"] == 0.1]], ignore_index=True)
    rows = {r["k"]: r for r in an.alpha_per_k(df)}
    assert rows[0.05]["alpha_best"] == pytest.approx(0.5, rel=1e-3)
    assert rows[0.1]["alpha_best"] == pytest.approx(units.ALPHA_PB, rel=1e-3)
    assert rows[0.05]["n_points"] == 30


def test_bem_power_law_of_points_on_a_power_law():
    rows = []
    for n, (beta, m) in ((0.4, (1.5, 0.2)), (1.6, (2.5, 0.3))):
        for vhat in np.logspace(-1, 4, 21):
            rows.append({"material": "mpl", "n": n, "k": 0.1, "mu": 3.24, "rate": 1.0,
                         "status": "ok", "crack_speed": vhat * units.l0_hat(3.24),
                         "pull_off": 1.5 * min(beta * vhat**m, 12.0)})
    res = {r["n"]: r for r in an.bem_power_law(pd.DataFrame(rows))}
    # Gamma in [10^0.25, 10^0.75] = [1.78, 5.62]: on the power law, below the cap 12
    assert res[0.4]["beta"] == pytest.approx(1.5, rel=1e-9)
    assert res[0.4]["m"] == pytest.approx(0.2, rel=1e-9)
    assert res[1.6]["beta"] == pytest.approx(2.5, rel=1e-9)
    assert res[1.6]["m"] == pytest.approx(0.3, rel=1e-9)
    assert res[1.6]["n_points"] >= 3


def test_threshold_analysis_without_enough_points_for_the_paper_protocol():
    # only the groups at rates 1 and 10: the paper's protocol keeps rate 10 (a_t = 2.0 for
    # both n), 2 points: no fit; the project's rule keeps all 4
    df = synthetic_threshold_runs()
    df = df[df["rate"] <= 10.0]
    out = an.threshold_analysis(df, n_boot=0)
    assert out["paper_protocol"] is None and out["n_points"] == 4
    assert not any(r["in_paper_fit"] for r in out["table"])


def test_no_interval_from_a_handful_of_points_or_resamples():
    """Four points (two near-equal x) had given B's "95 % interval" [2.2, 204], and one
    resample an interval that excluded the estimate: below MIN_BOOT_POINTS points or
    MIN_BOOT_RESAMPLES valid resamples there is none."""
    from sweep.analysis.fits import MIN_BOOT_POINTS, MIN_BOOT_RESAMPLES, power_law_fit

    x = np.array([1.955, 1.956, 2.6, 3.4])
    y = 0.85 * x**2.5 * np.array([1.0, 1.02, 0.99, 1.01])
    few = power_law_fit(x, y, n_boot=2000)
    assert few["exponent"] == pytest.approx(2.5, abs=0.2)
    assert few["exponent_ci"] is None and few["prefactor_ci"] is None
    x6 = np.linspace(1.0, 4.0, MIN_BOOT_POINTS)
    y6 = 0.85 * x6**2.5 * (1.0 + 0.01 * np.cos(7.0 * x6))
    assert power_law_fit(x6, y6, n_boot=MIN_BOOT_RESAMPLES - 1)["exponent_ci"] is None
    fit = power_law_fit(x6, y6, n_boot=2000)
    lo, hi = fit["exponent_ci"]
    assert lo <= fit["exponent"] <= hi and hi - lo < 0.1


def test_the_vr_fit_takes_the_bems_rows_only():
    """A file of crack-front and pb rows had given "Gamma_PB within 15 %: 100 %" (the
    crack-front model is the PB law: circular) and one power law of two models; its rows are
    refused, and the BEM's rows of a mixed file are the fit's."""
    from sweep.analysis.fits import bem_rows, vr_analysis

    df = synthetic_vr_runs()
    other = df.assign(model_used="crack")
    with pytest.raises(InputError, match=r"no BEM rows for the v-r fit \(\d+ crack\)"):
        vr_analysis(other, n_boot=0)
    mixed = pd.concat([df.assign(model_used="bem"), other.assign(pull_off=other.pull_off * 3)])
    assert len(bem_rows(mixed)) == len(df)
    a, b = vr_analysis(mixed, n_boot=0), vr_analysis(df, n_boot=0)
    assert a["exponent"] == b["exponent"] and a["other_models"] == len(df)


def test_a_sensitivity_rule_with_too_few_points_says_how_many_it_has():
    """A rule of the collapse sensitivity with 2 qualifying points gives NaN and said
    n_points 0; it says 2."""
    from sweep.analysis.fits import collapse_sensitivity

    table = pd.DataFrame({"status": ["interior"] * 3, "rate": [1.0, 100.0, 1000.0],
                          "saturation": [15.0] * 3, "a0t": [1.5, 2.0, 2.5],
                          "a0t_inner": [1.4, 1.9, 2.4], "pull_off_at_a0t": [2.0, 4.0, 8.0],
                          "pull_off_plateau": [2.1, 4.1, 8.1]})
    rules = [("rate >= 10", 0.9, 10.0, "pull_off_at_a0t"), ("all", 0.9, 0.0, "pull_off_at_a0t")]
    few, every = collapse_sensitivity(table, rules, n_boot=0)
    assert math.isnan(few["exponent"]) and few["n_points"] == 2
    assert every["n_points"] == 3 and every["exponent"] == pytest.approx(
        math.log(4.0) / math.log(2.5 / 1.5), rel=0.05)

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
def write_results(path, df):
    st = ResultStore(path, config_hash="synthetic", config_name="t", config_text="name: t\n",
                     n_scenes=len(df))
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
    assert "P_po = A a0t^B" in capsys.readouterr().out

    vpath = tmp_path / "vr.h5"
    write_results(vpath, synthetic_vr_runs())
    assert main(["fit", "vr", str(vpath), "--json", "--boot", "50"]) == 0
    out = json.loads(capsys.readouterr().out)
    for key in ("prefactor", "exponent", "prefactor_ci", "exponent_ci",
                "pb_share_within_15pct", "alpha_best", "n_points"):
        assert key in out
    assert out["exponent"] == pytest.approx(1.1, rel=1e-9)
    assert main(["fit", "vr", str(vpath)]) == 0
    assert "alpha_best" in capsys.readouterr().out


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

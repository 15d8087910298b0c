"""sweep.analysis.calibrate on synthetic measurements with a known answer, and `sweep calibrate`.

The fits use the crack-front model (model crack: one Persson-Brener table per (n, k), then
about 20 ms a scene) on 4 speeds, with the free parameters chosen among those that leave
the table unchanged (dg, tau0, h0, and the process zone's pz_v0, pz_xi), so the whole
module runs a few thousand scenes.
"""
import json
import math

import numpy as np
import pytest
import yaml

from sweep.analysis import calibrate as cb
from sweep.campaign.si import SIScene, run_si
from sweep.cli import main
from sweep.errors import InputError

FIXED = {"R": 0.0103, "E0": 1.0e6, "nu": 0.5, "preload": 1.5e-3, "n": 0.22, "Einf": 3.0e9}
TRUTH = {"dg": 0.15, "tau0": 0.02, "h0": 3.08e-8}
SPEEDS = np.logspace(-6, -2, 4)       # m/s


def _problem(tmp_path, fit, fixed, data=None, **extra):
    """Write a calibration YAML (and its CSV if ``data`` is given); returns the YAML path."""
    cfg = {"name": "t", "data": "d.csv", "fixed": fixed, "fit": fit, "model": "crack", **extra}
    path = tmp_path / "c.yaml"
    path.write_text(yaml.safe_dump(cfg))
    if data is not None:
        cols = list(data)
        lines = [",".join(cols)] + [",".join(f"{data[c][i]!r}" for c in cols)
                                    for i in range(len(data[cols[0]]))]
        (tmp_path / "d.csv").write_text("\n".join(lines) + "\n")
    return path


def _synthetic(fit, fixed, truth, seed, sigma, repeats=1, noise=0.05, speeds=SPEEDS):
    cal = cb.calibration_from_dict({"name": "s", "fixed": fixed, "fit": fit, "model": "crack"},
                                   measurements=([1.0] * 9, [1.0] * 9, None))
    d = cb.synthesize(cal, truth, speeds, repeats=repeats, noise=noise, seed=seed,
                      sigma=sigma)
    return {k: [float(x) for x in v] for k, v in d.items()}


def _fitted(tmp, fit, fixed, data, **extra):
    """Calibrate a written problem (a search of 8 points, 1 start, profiles of 5 points)."""
    path = _problem(tmp, fit, fixed, data, search={"points": 8, "starts": 1},
                    profile={"points": 5}, **extra)
    cal = cb.load_calibration(path)
    return cal, cb.calibrate(cal, jobs=1, curve_points=5)


# ------------------------------------------------------------------ fits with a known answer
@pytest.fixture(scope="module")
def identifiable(tmp_path_factory):
    """dg and tau0 free (n, Einf, h0 fixed), sigma given, from a deliberately bad start."""
    tmp = tmp_path_factory.mktemp("ident")
    fit = {"dg": [0.03, 1.0], "tau0": [1.0e-4, 10.0]}
    fixed = {**FIXED, "h0": TRUTH["h0"]}
    truth = {k: TRUTH[k] for k in fit}
    data = _synthetic(fit, fixed, truth, seed=2, sigma=True, repeats=2)
    return _fitted(tmp, fit, fixed, data, start={"dg": 1.0, "tau0": 1.0e-4}, truth=truth)


@pytest.fixture(scope="module")
def degenerate(tmp_path_factory):
    """tau0 and h0 free (dg fixed): the crack-front model sees only tau0/h0^2 (through
    l0 ~ h0^2), so h0 is not determined by pull-off against speed."""
    tmp = tmp_path_factory.mktemp("degen")
    fit = {"tau0": [1.0e-6, 1.0e2], "h0": [1.0e-8, 1.0e-7]}
    fixed = {**FIXED, "dg": TRUTH["dg"]}
    truth = {k: TRUTH[k] for k in fit}
    data = _synthetic(fit, fixed, truth, seed=3, sigma=False, repeats=2)
    return _fitted(tmp, fit, fixed, data, truth=truth)


def _assert_recovered(res, names):
    """Each parameter's interval holds its estimate and its truth, closed inside the box."""
    for name in names:
        p = res["parameters"][name]
        lo, hi = p["interval"]
        assert lo < p["estimate"] < hi
        assert lo <= p["truth"] <= hi, (name, p)
        assert p["identifiable"] and p["status"] == "identifiable"
        assert p["bounds"][0] < lo and hi < p["bounds"][1]          # closed inside the box


def test_truth_inside_the_intervals_from_a_bad_start(identifiable):
    cal, res = identifiable
    # the bad start is the first local fit; it starts 3+ orders of magnitude above the end
    first = res["search"]["local_fits"][0]
    assert first["start"]["dg"] == pytest.approx(1.0)
    assert first["start"]["tau0"] == pytest.approx(1e-4)
    assert first["ssr"] < 1e-3 * first["ssr_start"]
    _assert_recovered(res, ("dg", "tau0"))
    # with sigmas the statistic is chi-square(1), and the fit is consistent with the noise
    assert res["fit"]["statistic"] == "chi2(1)"
    assert res["fit"]["threshold"] == pytest.approx(3.8415, abs=1e-3)
    assert res["fit"]["chi2"] < 3.0 * res["fit"]["dof"]
    # dg and tau0 trade off: a larger dg with a shorter tau0 gives the same curve
    corr = np.array(res["correlation"]["matrix"])
    assert corr[0, 1] < -0.5 and corr[0, 0] == pytest.approx(1.0)


def test_profile_statistic_is_zero_at_the_estimate_and_crosses_at_the_ends(identifiable):
    cal, res = identifiable
    thr = res["fit"]["threshold"]
    for name, pr in res["profiles"].items():
        p = res["parameters"][name]
        vals, stat = np.array(pr["values"]), np.array(pr["statistic"])
        assert stat[np.argmin(abs(vals - p["estimate"]))] == pytest.approx(0.0, abs=1e-6)
        assert stat.max() > thr                        # the walk went past the threshold
        lo, hi = p["interval"]
        inside = (vals > lo * 1.0001) & (vals < hi * 0.9999)
        assert np.all(stat[inside] <= thr * 1.05)


def test_fitted_values_are_the_engine_at_the_estimate(identifiable):
    """The reported fitted pull-offs equal run_si at the estimate (an independent call)."""
    cal, res = identifiable
    est = {k: v["estimate"] for k, v in res["parameters"].items()}
    for i in (0, len(cal.speed_m_s) - 1):
        si = SIScene(**cal.fixed, **est, speed=float(cal.speed_m_s[i]))
        ref = run_si(si, "crack")["pull_off_N"]
        assert res["data"]["fitted_N"][i] == pytest.approx(ref, rel=1e-6)
    # the band holds the fitted curve
    c = res["curve"]
    assert np.all(np.array(c["band_lo_N"]) <= np.array(c["pull_off_N"]) * (1 + 1e-12))
    assert np.all(np.array(c["band_hi_N"]) >= np.array(c["pull_off_N"]) * (1 - 1e-12))
    assert res["scenes_run"] > 0 and res["cache_hits"] > 0 and res["failed_scenes"] == 0


@pytest.fixture(scope="module")
def process_zone(tmp_path_factory):
    """pz_v0 and pz_xi free (issue 35 item 5): the bulk, dg and h0 fixed, pz_law among the
    fixed fields; 5 speeds, 2 % noise with sigmas. The crack speed at pull-off runs from
    about 1e-5 to 2e-2 m/s, across the truth's pz_v0 = 1e-4 m/s."""
    tmp = tmp_path_factory.mktemp("pz")
    fit = {"pz_v0": [1.0e-6, 1.0e-1], "pz_xi": [0.2, 1.0]}
    fixed = {**FIXED, "h0": TRUTH["h0"], "tau0": TRUTH["tau0"], "dg": TRUTH["dg"],
             "pz_law": "gent-schultz"}
    truth = {"pz_v0": 1.0e-4, "pz_xi": 0.5}
    data = _synthetic(fit, fixed, truth, seed=4, sigma=True, noise=0.02,
                      speeds=np.logspace(-6, -2, 5))
    return _fitted(tmp, fit, fixed, data, truth=truth)


def test_process_zone_recovered_inside_its_intervals(process_zone):
    cal, res = process_zone
    assert res["fixed"]["pz_law"] == "gent-schultz"
    assert res["parameters"]["pz_v0"]["scale"] == "log"            # four decades of bounds
    assert res["parameters"]["pz_xi"]["scale"] == "linear"
    _assert_recovered(res, ("pz_v0", "pz_xi"))
    # 2 % noise pins pz_v0 within a factor 1.5 and pz_xi within 0.1 (the bounds: 1e5, 0.8)
    iv = res["parameters"]["pz_v0"]["interval"]
    assert iv[1] / iv[0] < 1.5
    iv = res["parameters"]["pz_xi"]["interval"]
    assert iv[1] - iv[0] < 0.1
    assert res["fit"]["chi2"] < 3.0 * res["fit"]["dof"] + 3.0
    # the fitted pull-offs are the crack-front model with the process zone at the estimate
    est = {k: v["estimate"] for k, v in res["parameters"].items()}
    for i in (0, len(cal.speed_m_s) - 1):
        si = SIScene(**cal.fixed, **est, speed=float(cal.speed_m_s[i]))
        assert res["data"]["fitted_N"][i] == pytest.approx(run_si(si, "crack")["pull_off_N"],
                                                           rel=1e-6)
    # ... and not the model without it: the fastest point is about 4x the pull-off without it
    bare = {k: v for k, v in cal.fixed.items() if k != "pz_law"}
    si = SIScene(**bare, speed=float(cal.speed_m_s[-1]))
    assert res["data"]["fitted_N"][-1] > 2.0 * run_si(si, "crack")["pull_off_N"]


def test_unidentifiable_parameter_is_flagged(degenerate):
    cal, res = degenerate
    h0 = res["parameters"]["h0"]
    assert not h0["identifiable"] and h0["status"] == "not identifiable"
    assert h0["interval"] == pytest.approx(h0["bounds"])
    # without sigmas: log residuals, F(1, N - p) threshold
    assert res["fit"]["statistic"] == f"F(1, {res['fit']['dof']})"
    assert res["fit"]["rms_log_residual"] < 0.15
    # tau0 is pinned only through h0's bounds, and its interval holds the truth
    tau = res["parameters"]["tau0"]
    assert tau["interval"][0] <= tau["truth"] <= tau["interval"][1]
    # ... and the estimate: a point along the flat valley 5e-10 below in SSR had moved the
    # estimate to tau0 = 0.18, outside its interval [0.0017, 0.089] about the first point
    assert tau["interval"][0] <= tau["estimate"] <= tau["interval"][1]
    assert not res["recentred"] and not res["warnings"]
    # the flat direction is tau0 ~ h0^2: the two are fully correlated
    assert abs(res["correlation"]["matrix"][0][1]) > 0.99


# ------------------------------------------------------------------ a lower minimum on a profile
# s48_A finding 1: the data of a 20-arm Prony table fitted with an SLS (a model that does
# not match the data). The one local fit ends at dg = 0.37, tau0 = 1e-4 s (SSR 2.13); the
# profile of tau0 finds SSR 0.72 at tau0 = 10 s, dg = 0.027. The estimate had moved there
# while the intervals and statuses stayed those of the first point: dg 0.0266 was printed
# with the interval [0.235, 0.5], "lower limit only", its profile's least D 11.75.
SLS_PROBLEM = {
    "name": "sls", "material": "sls", "model": "crack",
    "fixed": {"R": 5.0e-3, "nu": 0.5, "h0": 30.0e-9, "preload": 1.0e-3, "E0": 1.5e6,
              "Einf": 1.3547649e9, "n": 0.3},
    "fit": {"dg": [0.005, 0.5], "tau0": [1.0e-4, 10.0]},
    "search": {"points": 16, "starts": 1}, "profile": {"points": 6}}
SLS_DATA = ([1e-6, 1e-6, 1e-5, 1e-5, 1e-4, 1e-4, 1e-3, 1e-3],
            [0.0235247, 0.0204944, 0.0280127, 0.0271963, 0.0338494, 0.034091, 0.0398056,
             0.0419992], None)


def _assert_about_the_estimate(res):
    """Every interval holds its estimate, and each profile is about the estimate: D = 0
    there (its least value) and below the threshold wherever the interval says."""
    thr = res["fit"]["threshold"]
    for name, p in res["parameters"].items():
        lo, hi = p["interval"]
        assert lo <= p["estimate"] <= hi, (name, p)
        vals, stat = (np.array(res["profiles"][name][k]) for k in ("values", "statistic"))
        at = np.argmin(abs(np.log(vals) - math.log(p["estimate"])))
        assert stat[at] == 0.0 and stat.min() == 0.0, (name, stat)
        assert np.all(stat[(vals > lo * 1.0001) & (vals < hi * 0.9999)] <= thr), (name, stat)
        assert p["identifiable"] == (p["status"] == "identifiable")
        # a side flagged open stays below the threshold out to its bound
        if p["status"] in ("lower limit only", "not identifiable"):
            assert hi == pytest.approx(p["bounds"][1]) and stat[-1] <= thr
        if p["status"] in ("upper limit only", "not identifiable"):
            assert lo == pytest.approx(p["bounds"][0]) and stat[0] <= thr


def test_a_lower_minimum_on_a_profile_recentres_the_fit():
    cal = cb.calibration_from_dict(SLS_PROBLEM, measurements=SLS_DATA)
    res = cb.calibrate(cal, jobs=1, curve_points=5)
    _assert_about_the_estimate(res)
    (move,) = res["recentred"]                       # the case happened, once
    assert move["profile"] == "tau0" and move["ssr"] < 0.5 * move["ssr_from"]
    assert res["fit"]["ssr"] == move["ssr"] and not res["warnings"]
    assert res["parameters"]["dg"]["estimate"] == pytest.approx(move["estimate"]["dg"])
    # dg is now closed about the new estimate (it was "lower limit only" about the old)
    dg = res["parameters"]["dg"]
    assert dg["status"] == "identifiable" and dg["interval"][1] < 0.2
    assert any(line.startswith("note: the profile of tau0 found a lower minimum")
               for line in cb.summary_lines(res))


def test_a_lower_minimum_after_the_last_recentring_is_a_warning(monkeypatch):
    """With no re-centring left, the estimate stays where the profiles are about (the local
    fit's end), and the output says where the lower point is."""
    monkeypatch.setattr(cb, "MAX_RECENTRES", 0)
    cal = cb.calibration_from_dict(SLS_PROBLEM, measurements=SLS_DATA)
    res = cb.calibrate(cal, jobs=1, curve_points=5)
    assert not res["recentred"]
    (warning,) = res["warnings"]
    assert "the profile of tau0 still found a lower minimum" in warning
    best = min(res["search"]["local_fits"], key=lambda f: f["ssr"])
    assert res["fit"]["ssr"] == best["ssr"]
    assert res["parameters"]["dg"]["estimate"] == pytest.approx(best["end"]["dg"])
    _assert_about_the_estimate(res)
    assert f"warning: {warning}" in cb.summary_lines(res)


# ------------------------------------------------------------------ pieces
def test_parameter_unit_coordinates_round_trip():
    log = cb.Parameter("tau0", 1e-4, 10.0, log=True)
    lin = cb.Parameter("n", 0.1, 1.5, log=False)
    assert log.value(0.5) == pytest.approx(math.sqrt(1e-4 * 10.0))
    assert lin.value(0.5) == pytest.approx(0.8)
    for p, x in ((log, 3.3e-2), (lin, 0.37)):
        assert p.value(p.unit(x)) == pytest.approx(x, rel=1e-12)


def test_bounds_spanning_a_decade_are_log_scaled(tmp_path):
    path = _problem(tmp_path, {"dg": [0.01, 1.0], "n": [0.1, 0.5], "tau0": [1e-3, 1e-2, "linear"]},
                    {k: v for k, v in {**FIXED, "h0": 3e-8}.items() if k != "n"},
                    {"speed_m_s": [1e-6, 1e-5, 1e-4, 1e-3], "pull_off_N": [1.0] * 4})
    cal = cb.load_calibration(path)
    assert [p.log for p in cal.params] == [True, False, False]


def test_cache_reuses_scenes_and_matches_run_si(tmp_path):
    path = _problem(tmp_path, {"dg": [0.05, 0.5]}, {**FIXED, "h0": 3.08e-8, "tau0": 0.02},
                    {"speed_m_s": [1e-6, 1e-4, 1e-4], "pull_off_N": [0.01, 0.02, 0.021]})
    cal = cb.load_calibration(path)
    ev = cb.SceneEvaluator(cal, jobs=1)
    u = [[0.3], [0.7]]
    first = ev.predict(u)
    assert first.shape == (2, 2) and ev.scenes_run == 4        # 2 distinct speeds
    again = ev.predict(u)
    assert ev.scenes_run == 4 and np.array_equal(first, again)
    dg = cal.params[0].value(0.3)
    ref = run_si(SIScene(**cal.fixed, dg=dg, speed=1e-4), "crack")["pull_off_N"]
    assert first[0, 1] == pytest.approx(ref, rel=1e-8)


def test_synthesize_without_noise_is_the_engine():
    fit = {"dg": [0.05, 0.5]}
    fixed = {**FIXED, "h0": 3.08e-8, "tau0": 0.02}
    d = _synthetic(fit, fixed, {"dg": 0.2}, seed=0, sigma=True, noise=0.0)
    si = SIScene(**fixed, dg=0.2, speed=float(SPEEDS[1]))
    assert d["pull_off_N"][1] == pytest.approx(run_si(si, "crack")["pull_off_N"], rel=1e-12)
    assert d["sigma_N"] == [0.0] * len(SPEEDS)


# ------------------------------------------------------------------ bad files: one line, exit 2
GOOD_FIT = {"dg": [0.05, 0.5], "tau0": [1e-3, 1.0]}
GOOD_FIXED = {**FIXED, "h0": 3.08e-8}
GOOD_DATA = {"speed_m_s": [1e-6, 1e-5, 1e-4], "pull_off_N": [0.01, 0.02, 0.03]}


@pytest.mark.parametrize("change, words", [
    ({"data": {"speed_m_s": [1e-6, 1e-5, 1e-4], "force": [1.0, 2.0, 3.0]}},
     "missing column pull_off_N"),
    ({"data": {"speed_m_s": [1e-6, -1e-5, 1e-4], "pull_off_N": [0.01, 0.02, 0.03]}},
     "speed_m_s must be a number > 0 (row 2"),
    ({"fit": {"dg": [0.5, 0.05], "tau0": [1e-3, 1.0]}}, "fit.dg: bounds reversed"),
    ({"fixed": {**GOOD_FIXED, "dg": 0.1}}, "dg: both fixed and fitted"),
    ({"data": {"speed_m_s": [1e-6], "pull_off_N": [0.01]}}, "1 points for 2 free parameters"),
    ({"fit": {"dg": [0.05, 0.5], "tau": [1e-3, 1.0]}}, "fit.tau: unknown SI field"),
    ({"fit": {**GOOD_FIT, "nu": [0.1, 0.7]}, "fixed": {k: v for k, v in GOOD_FIXED.items()
                                                     if k != "nu"}},
     "fit.nu upper bound must be in [0, 0.5]"),
    ({"fixed": {k: v for k, v in GOOD_FIXED.items() if k != "R"}}, "R: missing"),
    ({"fit": {**GOOD_FIT, "Einf": [1e5, 1e9]}, "fixed": {k: v for k, v in GOOD_FIXED.items()
                                                              if k != "Einf"}},
     "fit.Einf: lower bound must be >= E0"),
    ({"model": "fem"}, "model must be one of bem, crack, pb, auto"),
    ({"fit": {**GOOD_FIT, "pz_law": [0.0, 1.0]}}, "fit.pz_law: a law is chosen, not fitted"),
    ({"fixed": {**GOOD_FIXED, "pz_law": "viscous"}},
     "fixed.pz_law must be one of none, gent-schultz"),
    ({"fit": {**GOOD_FIT, "pz_v0": [1e-5, 1e-1]}},
     "pz_v0: a process-zone parameter needs fixed.pz_law"),
    ({"fixed": {**GOOD_FIXED, "pz_law": "gent-schultz", "pz_xi": 0.5}},
     "pz_v0: missing; pz_law gent-schultz needs pz_v0 [m/s] and pz_xi"),
])
def test_bad_files_one_line_exit_2(tmp_path, capsys, change, words):
    fit = change.get("fit", GOOD_FIT)
    fixed = change.get("fixed", GOOD_FIXED)
    extra = {"model": change["model"]} if "model" in change else {}
    path = _problem(tmp_path, fit, fixed, change.get("data", GOOD_DATA), **extra)
    assert main(["calibrate", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"error: {path}: ") and "\n" not in err, err   # as sweep run's
    assert words in err, err


@pytest.mark.parametrize("csv, words", [
    # an unlabelled extra column: pandas read it shifted by one, the speeds as the index
    ("speed_m_s,pull_off_N\n1e-6,0.0145,1\n1e-5,0.02,1\n1e-4,0.03,1\n",
     "row 1 (line 2) has 3 fields, the header 2 (speed_m_s, pull_off_N)"),
    # trailing commas: read as a NaN pull-off, "(row 1: np.float64(nan))"
    ("# lab\nspeed_m_s,pull_off_N\n1e-6,0.0145\n1e-5,0.02,\n1e-4,0.03,\n",
     "row 2 (line 4) has 3 fields, the header 2"),
    ("speed_m_s,pull_off_N,sigma_N\n1e-6,0.0145,1e-3\n1e-5,0.02\n1e-4,0.03,1e-3\n",
     "row 2 (line 3) has 2 fields, the header 3"),
    # a bad value: the value as written, not a numpy repr ("np.float64(-1e-06)")
    ("speed_m_s,pull_off_N\n1e-6,0.0145\n-1e-05,0.02\n1e-4,0.03\n",
     "speed_m_s must be a number > 0 (row 2: -1e-05)"),
    ("speed_m_s,pull_off_N\n1e-6,0.0145\n1e-5,\n1e-4,0.03\n",
     "pull_off_N must be a number > 0 (row 2: empty)"),
    ("speed_m_s,pull_off_N\n1e-6,0.0145\n1e-5,abc\n1e-4,0.03\n",
     "pull_off_N must be a number > 0 (row 2: abc)"),
    # a misspelt sigma_N: an unweighted fit, silently
    ("speed_m_s,pull_off_N,sigma_n\n1e-4,0.02,0.001\n1e-3,0.03,0.001\n",
     "unknown column(s) sigma_n (columns speed_m_s, pull_off_N and optional sigma_N)"),
])
def test_data_rows_must_match_the_header(tmp_path, capsys, csv, words):
    path = _problem(tmp_path, GOOD_FIT, GOOD_FIXED)
    (tmp_path / "d.csv").write_text(csv)
    assert main(["calibrate", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"error: {path}: data ") and "\n" not in err and "np." not in err
    assert words in err, err


def test_data_comments_blank_lines_and_spaces_are_read():
    """What pandas read before still reads: # comments (whole or trailing), blank lines,
    spaces after commas, columns in any order."""
    import tempfile
    from pathlib import Path

    with tempfile.TemporaryDirectory() as tmp:
        p = Path(tmp) / "d.csv"
        p.write_text("# synthetic\n\npull_off_N, sigma_N, speed_m_s\n0.01, 1e-3, 1e-6  # a\n"
                     "\n0.02, 2e-3, 1e-5\n")
        speed, po, sigma = cb._read_data(p)
    assert speed.tolist() == [1e-6, 1e-5] and po.tolist() == [0.01, 0.02]
    assert sigma.tolist() == [1e-3, 2e-3]


def test_a_prony_table_is_refused_first_naming_the_file(tmp_path, capsys):
    """A table as the material is the problem, not the MPL constants it leaves out: the
    first error says so (it had said "E0, Einf, n, tau0: missing"), after the file's name."""
    fixed = {k: v for k, v in GOOD_FIXED.items() if k not in ("E0", "Einf", "n")}
    path = _problem(tmp_path, {"dg": [0.05, 0.5]}, fixed, GOOD_DATA,
                    material={"prony": "lab.csv"})
    assert main(["calibrate", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"error: {path}: material: a Prony table is not supported"), err
    assert "missing" not in err and "\n" not in err
    # a material that is neither: the choice, also with the file's name
    path = _problem(tmp_path, GOOD_FIT, GOOD_FIXED, GOOD_DATA, material="maxwell")
    with pytest.raises(InputError, match=r"c\.yaml: material must be one of mpl, sls"):
        cb.load_calibration(path)


def test_a_byte_order_mark_is_not_part_of_the_header(tmp_path):
    """Excel's "CSV UTF-8" starts the file with a BOM: the data (and a YAML saved the same
    way) read as without it; it had read as a column '\\ufeffspeed_m_s', "missing column"."""
    path = _problem(tmp_path, GOOD_FIT, GOOD_FIXED)
    path.write_bytes(b"\xef\xbb\xbf" + path.read_bytes())
    (tmp_path / "d.csv").write_bytes(b"\xef\xbb\xbfspeed_m_s,pull_off_N\r\n1e-6,0.01\r\n"
                                     b"1e-5,0.02\r\n1e-4,0.03\r\n")
    cal = cb.load_calibration(path)
    assert cal.speed_m_s.tolist() == GOOD_DATA["speed_m_s"]
    assert cal.pull_off_N.tolist() == GOOD_DATA["pull_off_N"]


def test_missing_data_file_is_one_line(tmp_path, capsys):
    path = _problem(tmp_path, GOOD_FIT, GOOD_FIXED)          # no CSV written
    assert main(["calibrate", str(path)]) == 2
    assert "data: no such file" in capsys.readouterr().err


def test_sigma_must_be_positive(tmp_path):
    path = _problem(tmp_path, GOOD_FIT, GOOD_FIXED, {**GOOD_DATA, "sigma_N": [1e-3, 0.0, 1e-3]})
    with pytest.raises(InputError, match="sigma_N must be a number > 0"):
        cb.load_calibration(path)


# ------------------------------------------------------------------ the command end to end
def test_cli_json_and_out(tmp_path, capsys):
    fixed = {**FIXED, "h0": 3.08e-8, "tau0": 0.02}
    data = _synthetic({"dg": [0.05, 0.5]}, fixed, {"dg": 0.2}, seed=5, sigma=False)
    path = _problem(tmp_path, {"dg": [0.05, 0.5]}, fixed, data,
                    search={"points": 4, "starts": 1}, profile={"points": 4})
    out = tmp_path / "out"
    assert main(["calibrate", str(path), "--json", "--out", str(out), "-j", "1"]) == 0
    captured = capsys.readouterr()
    res = json.loads(captured.out)
    assert "search: 4 Sobol points" in captured.err                 # progress on stderr
    dg = res["parameters"]["dg"]
    assert dg["interval"][0] <= 0.2 <= dg["interval"][1] and dg["identifiable"]
    assert res["scenes_run"] > 0 and res["wall_s"] > 0
    assert set(res["fit"]) >= {"rms_log_residual", "dof", "threshold"}
    for name in ("calibration.json", "fit.png", "profile_dg.png"):
        assert (out / name).stat().st_size > 1000
    assert json.loads((out / "calibration.json").read_text())["parameters"]["dg"] == dg

"""DMA fitting: MPL and generalized Maxwell recovery from synthetic master curves, WLF shift,
Kramers-Kronig check, the `sweep fit-dma` command and its one-line errors on bad files."""
import json
import math

import numpy as np
import pytest

from sweep.cli import main
from sweep.analysis.dma import (
    DMAData, fit_maxwell, fit_mpl, kramers_kronig_check, read_dma_csv, wlf_log_shift,
)
from sweep.errors import InputError
from sweep.materials import MPLRetardation, Prony
from tests.reference import paper_values

PDMS = paper_values()["pdms_experiment"]
TRUE = dict(E0=PDMS["E0_MPa"] * 1e6, Einf=PDMS["Einf_MPa"] * 1e6, n=PDMS["n"],
            tau0=PDMS["tau0_s"])
NOISE = 0.01


def noisy(E, seed):
    rng = np.random.default_rng(seed)
    return (E.real * (1.0 + NOISE * rng.standard_normal(E.size)),
            E.imag * (1.0 + NOISE * rng.standard_normal(E.size)))


@pytest.fixture(scope="module")
def mpl_data():
    # 21 decades, as the paper's temperature sweep -130 .. 20 C at 1 Hz gives after the shift
    w = np.logspace(-2, 19, 85)
    E = MPLRetardation(**TRUE).complex_modulus(w)
    return DMAData(w, *noisy(E, 1))


def test_mpl_recovers_known_constants(mpl_data):
    fit = fit_mpl(mpl_data)
    assert fit.success
    for name, value in TRUE.items():
        got, se = getattr(fit, name), fit.stderr[name]
        # the reported standard error is honest (within 4 sigma) and small (1 % noise)
        assert abs(got - value) <= 4.0 * se, (name, got, value, se)
        assert abs(got / value - 1.0) < 0.01, (name, got, value)
    # residuals at the noise level: nothing systematic left
    assert 0.5 * NOISE < fit.quality["rms_rel_storage"] < 1.5 * NOISE
    assert 0.5 * NOISE < fit.quality["rms_rel_loss"] < 1.5 * NOISE


def test_mpl_exact_data_recovered_to_optimizer_precision():
    w = np.logspace(-1, 18, 40)
    truth = dict(E0=2.0e6, Einf=1.0e9, n=0.5, tau0=1e-3)
    E = MPLRetardation(**truth).complex_modulus(w)
    fit = fit_mpl((w, E.real, E.imag))
    for name, value in truth.items():
        assert getattr(fit, name) == pytest.approx(value, rel=1e-6)


def test_maxwell_recovers_an_18_arm_model():
    # a known 18-arm Wiechert model with its times where the fit puts them (the data's decades)
    w = np.logspace(-3, 9, 73)
    times = np.logspace(-9, 3, 18)
    E0 = 1.0e6
    moduli = E0 * 3.0 * (times / 1e-9) ** -0.25          # a broad, smooth spectrum
    truth = Prony(moduli, times, E0=E0, kind="maxwell")
    E = truth.complex_modulus(w)
    fit = fit_maxwell(DMAData(w, *noisy(E, 2)), arms=18)
    np.testing.assert_allclose(fit.times, times, rtol=1e-12)
    assert fit.E0 == pytest.approx(E0, rel=0.02)
    assert fit.Einf == pytest.approx(truth.Einf, rel=0.02)
    # the relaxation modulus over the data's window (individual arms are ill-conditioned)
    t = np.logspace(-8, 2, 30)
    np.testing.assert_allclose(fit.material.relaxation_modulus(t), truth.relaxation_modulus(t),
                               rtol=0.03)
    assert fit.quality["rms_rel_storage"] < 1.5 * NOISE
    assert fit.quality["rms_rel_loss"] < 1.5 * NOISE


def test_maxwell_of_noise_free_data_is_exact():
    w = np.logspace(-2, 4, 30)
    times = np.logspace(-4, 2, 6)
    truth = Prony(np.linspace(1.0, 6.0, 6) * 1e5, times, E0=1e5, kind="maxwell")
    E = truth.complex_modulus(w)
    fit = fit_maxwell((w, E.real, E.imag), arms=6)
    np.testing.assert_allclose(fit.moduli, truth.maxwell_moduli, rtol=1e-8)
    assert fit.E0 == pytest.approx(1e5, rel=1e-8)


def test_kramers_kronig_flags_inconsistent_loss(mpl_data):
    ok = kramers_kronig_check(mpl_data)
    assert ok.consistent and ok.rms_rel < 0.06
    # a loss modulus distorted by 40 % over the upper half of the data violates KK
    w = mpl_data.omega
    bad = DMAData(w, mpl_data.E_storage, mpl_data.E_loss * np.where(w > 1e8, 1.4, 1.0))
    chk = kramers_kronig_check(bad)
    assert not chk.consistent and chk.rms_rel > 0.15


def test_wlf_shift_is_the_papers_equation():
    C1, C2, Tg = (PDMS["wlf"][k] for k in ("C1", "C2_K", "Tg_C"))
    assert wlf_log_shift(Tg) == 0.0
    T = -100.0
    assert wlf_log_shift(T) == pytest.approx(-C1 * (T - Tg) / (C2 + T - Tg), rel=1e-15)
    with pytest.raises(InputError, match="T_C must be > Tg - C2"):
        wlf_log_shift(Tg - C2 - 1.0)


def write_sweep(path, mat, temps, f=1.0, T_ref=20.0):
    """A temperature sweep at fixed frequency that shifts onto ``mat``'s master curve."""
    shift = wlf_log_shift(temps) - wlf_log_shift(T_ref)
    E = mat.complex_modulus(2.0 * math.pi * f * 10.0 ** shift)
    lines = ["T_C,f_Hz,E_storage_Pa,E_loss_Pa"]
    lines += [f"{float(T)!r},{float(f)!r},{float(e.real)!r},{float(e.imag)!r}" for T, e in zip(temps, E)]
    path.write_text("\n".join(lines) + "\n")


def test_temperature_sweep_is_shifted_and_fitted(tmp_path):
    mat = MPLRetardation(**TRUE)
    temps = np.arange(-130.0, 20.5, 2.5)          # the paper's range, finer steps
    p = tmp_path / "sweep.csv"
    write_sweep(p, mat, temps)
    data = read_dma_csv(p)
    assert data.kind == "temperature" and data.T_ref == 20.0
    # the coldest point lands highest: -130 C -> 10^(log aT(-130) - log aT(20)) * 2 pi
    top = 2 * math.pi * 10 ** (wlf_log_shift(-130.0) - wlf_log_shift(20.0))
    assert data.omega.max() == pytest.approx(top, rel=1e-12)
    fit = fit_mpl(data)
    for name, value in TRUE.items():
        assert getattr(fit, name) == pytest.approx(value, rel=1e-4)


def write_master(path, w, E):
    lines = ["omega_rad_s,E_storage_Pa,E_loss_Pa"]
    lines += [f"{float(wi)!r},{float(e.real)!r},{float(e.imag)!r}" for wi, e in zip(w, E)]
    path.write_text("\n".join(lines) + "\n")


def test_cli_fit_dma_refuses_a_wlf_shift_of_a_master_curve(tmp_path, capsys):
    """--tref and --wlf apply to a temperature sweep; on a master curve they were accepted
    and ignored, silently."""
    w = np.logspace(-2, 19, 43)
    p = tmp_path / "master.csv"
    write_master(p, w, MPLRetardation(**TRUE).complex_modulus(w))
    for extra in (["--tref", "0"], ["--wlf", "17,51,-120"]):
        assert main(["fit-dma", str(p), "--maxwell", "0", *extra]) == 2
        err = capsys.readouterr().err.strip()
        assert err.startswith(f"error: {extra[0]}: ") and "is a master curve" in err


def test_cli_fit_dma_json(tmp_path, capsys):
    w = np.logspace(-2, 19, 43)
    E = MPLRetardation(**TRUE).complex_modulus(w)
    p = tmp_path / "master.csv"
    write_master(p, w, E)
    code = main(["fit-dma", str(p), "--maxwell", "18", "--json"])
    out, err = capsys.readouterr()
    assert code == 0 and err == ""
    d = json.loads(out)
    for name, value in TRUE.items():
        assert d[name] == pytest.approx(value, rel=1e-5)
    assert d["kind"] == "master" and d["points"] == 43
    assert len(d["maxwell"]["moduli"]) == 18
    assert d["kramers_kronig"]["consistent"] is True


def test_cli_fit_dma_out_is_a_prony_table(tmp_path, capsys):
    """--out writes the --json object to a file, which read_prony takes as the Maxwell table
    (issue 36 item 1); with --maxwell 0 the file holds only the MPL and read_prony refuses it."""
    from sweep.materials import read_prony

    w = np.logspace(-2, 14, 33)
    E = MPLRetardation(**TRUE).complex_modulus(w)
    p = tmp_path / "master.csv"
    write_master(p, w, E)
    fit = tmp_path / "fit.json"
    assert main(["fit-dma", str(p), "--maxwell", "12", "--out", str(fit)]) == 0
    out = capsys.readouterr().out
    assert f"fit: {fit}" in out
    d = json.loads(fit.read_text())
    mx = d["maxwell"]
    table = read_prony(fit)
    keep = np.array(mx["moduli"]) > 0
    assert table.source_format == "fit-dma" and table.n_arms == int(keep.sum())
    assert table.E0 == mx["E0"] and table.Einf == pytest.approx(mx["Einf"], rel=1e-14)
    assert np.array_equal(table.weights, np.array(mx["moduli"])[keep])
    assert main(["fit-dma", str(p), "--maxwell", "0", "--out", str(fit)]) == 0
    with pytest.raises(InputError, match="holds only an MPL fit"):
        read_prony(fit)
    assert main(["fit-dma", str(p), "--out", str(tmp_path / "no" / "f.json")]) == 2


def test_cli_fit_dma_text_and_plot(tmp_path, capsys):
    pytest.importorskip("matplotlib")
    w = np.logspace(0, 12, 25)
    E = MPLRetardation(1e6, 1e8, 0.4, 1e-3).complex_modulus(w)
    p = tmp_path / "m.csv"
    write_master(p, w, E)
    png = tmp_path / "fig.png"
    code = main(["fit-dma", str(p), "--maxwell", "8", "--plot", str(png)])
    out, _ = capsys.readouterr()
    assert code == 0
    assert "E0    = 1e+06" in out and "Generalized Maxwell, 8 arms" in out
    assert png.stat().st_size > 1000


BAD = {
    "missing_column": ("omega_rad_s,E_storage_Pa\n1,2\n2,3\n3,4\n",
                       "missing column(s) E_loss_Pa"),
    "negative_omega": ("omega_rad_s,E_storage_Pa,E_loss_Pa\n1,2,3\n-2,3,4\n3,4,5\n",
                       "line 3 (data row 2), column omega_rad_s: must be > 0 (got -2)"),
    "zero_frequency": ("T_C,f_Hz,E_storage_Pa,E_loss_Pa\n0,1,2,3\n10,0,3,4\n20,1,4,5\n",
                       "line 3 (data row 2), column f_Hz: must be > 0 (got 0)"),
    "nan": ("omega_rad_s,E_storage_Pa,E_loss_Pa\n1,2,3\n2,3,4\n3,nan,5\n",
            "line 4 (data row 3), column E_storage_Pa: must be a finite number (got nan)"),
    "text": ("omega_rad_s,E_storage_Pa,E_loss_Pa\n1,2,3\n2,x,4\n3,4,5\n",
             "line 3 (data row 2), column E_storage_Pa: must be a number (got 'x')"),
    "one_row": ("omega_rad_s,E_storage_Pa,E_loss_Pa\n1,2,3\n",
                "needs at least 3 data rows for a 4-parameter fit (got 1)"),
    "empty_cell": ("omega_rad_s,E_storage_Pa,E_loss_Pa\n1,2,3\n2,,4\n3,4,5\n",
                   "line 3 (data row 2), column E_storage_Pa: missing value"),
    "below_wlf_pole": ("T_C,f_Hz,E_storage_Pa,E_loss_Pa\n-170,1,2,3\n10,1,3,4\n20,1,4,5\n",
                       "line 2 (data row 1), column T_C: must be > Tg - C2"),
    # 0.1 C above the pole (Tg - C2 = -166.6 C): a shift of 10^8700, which had overflowed to
    # inf and ended the fit in "math domain error"
    "at_wlf_pole": ("T_C,f_Hz,E_storage_Pa,E_loss_Pa\n-166.5,1,2,3\n10,1,3,4\n20,1,4,5\n",
                    "line 2 (data row 1), column T_C: the WLF shift to 20 C at -166.5 C is 10^"),
    # one frequency repeated: PCHIP had raised "x must contain at least 2 elements"
    "one_frequency": ("omega_rad_s,E_storage_Pa,E_loss_Pa\n1,1e6,1e3\n1,1e6,1e3\n1,1e6,1e3\n"
                      "1,1e6,1e3\n", "needs at least 3 distinct frequencies for a 4-parameter "
                                     "fit (got 1 among 4 rows)"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_cli_bad_files_one_line_exit_2(tmp_path, capsys, case):
    text, message = BAD[case]
    p = tmp_path / f"{case}.csv"
    p.write_text(text)
    code = main(["fit-dma", str(p)])
    out, err = capsys.readouterr()
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and err.startswith("error: ")
    assert message in err and str(p) in err


def test_a_byte_order_mark_is_not_part_of_the_header(tmp_path, capsys):
    """Excel's "CSV UTF-8" starts with a BOM: it had become part of the first column's name
    ("missing column omega_rad_s")."""
    p = tmp_path / "bom.csv"
    w = np.logspace(0, 12, 25)
    E = MPLRetardation(1e6, 1e8, 0.4, 1e-3).complex_modulus(w)
    p.write_text("\ufeffomega_rad_s,E_storage_Pa,E_loss_Pa\n"
                 + "".join(f"{a:.10g},{b:.10g},{c:.10g}\n" for a, b, c in zip(w, E.real, E.imag)),
                 encoding="utf-8")
    assert main(["fit-dma", str(p), "--maxwell", "0", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["points"] == 25


def test_cli_bad_options(tmp_path, capsys):
    p = tmp_path / "m.csv"
    p.write_text("omega_rad_s,E_storage_Pa,E_loss_Pa\n1,2,3\n2,3,4\n3,4,5\n")
    assert main(["fit-dma", str(p), "--wlf", "1,2"]) == 2
    assert "wlf must be three numbers" in capsys.readouterr().err
    assert main(["fit-dma", str(p), "--maxwell", "x"]) == 2
    assert "maxwell must be an integer" in capsys.readouterr().err
    assert main(["fit-dma", str(tmp_path / "none.csv")]) == 2
    assert "cannot read the file" in capsys.readouterr().err


def test_papers_protocol_sparse_temperature_sweep(tmp_path):
    # the paper's DMA protocol: -130 .. 20 C in 10 C steps at 1 Hz (16 points over 20
    # decades after the shift, up to 5 decades apart near Tg), 1 % noise
    T = np.arange(-130.0, 20.5, 10.0)
    mat = MPLRetardation(**TRUE)
    w = 2 * math.pi * 10 ** (wlf_log_shift(T) - wlf_log_shift(20.0))
    E1, E2 = noisy(mat.complex_modulus(w), 7)
    p = tmp_path / "protocol.csv"
    p.write_text("T_C,f_Hz,E_storage_Pa,E_loss_Pa\n" + "".join(
        f"{float(t)!r},1.0,{float(a)!r},{float(b)!r}\n" for t, a, b in zip(T, E1, E2)))
    data = read_dma_csv(p)
    fit = fit_mpl(data)
    for name, value in TRUE.items():
        assert getattr(fit, name) == pytest.approx(value, rel=0.03), name
    assert kramers_kronig_check(data).consistent
    # the same sweep with the loss modulus of the cold half doubled is flagged
    bad = DMAData(data.omega, data.E_storage, data.E_loss * np.where(data.omega > 1e6, 2.0, 1.0))
    assert not kramers_kronig_check(bad).consistent


def test_array_input_is_sorted_and_checked():
    w = np.logspace(4, 0, 9)                       # descending, as a temperature sweep gives
    E = MPLRetardation(1e6, 1e8, 0.4, 1e-2).complex_modulus(w)
    fit = fit_mpl((w, E.real, E.imag))
    assert fit.n == pytest.approx(0.4, rel=1e-5)
    assert kramers_kronig_check((w, E.real, E.imag)).interior_points >= 2
    with pytest.raises(InputError, match=r"E_loss\[2\] must be a finite number > 0"):
        fit_mpl((w, E.real, np.where(np.arange(9) == 2, np.nan, E.imag)))
    with pytest.raises(InputError, match="equal lengths"):
        fit_maxwell((w, E.real, E.imag[:-1]))


def _hand_made(tmp_path, noise=0.03, seed=3, distort=None, decades=(-3, 1)):
    """A hand-made master curve, as a user would make one: the PDMS MPL over a few decades
    (by default below the transition, never near the glassy plateau) with ``noise`` relative
    noise; ``distort`` multiplies E'' above the middle of the window."""
    w = np.logspace(*decades, 31)
    E = MPLRetardation(**TRUE).complex_modulus(w)
    rng = np.random.default_rng(seed)
    E1 = E.real * (1.0 + noise * rng.standard_normal(w.size))
    E2 = E.imag * (1.0 + noise * rng.standard_normal(w.size))
    if distort is not None:
        E2 = E2 * np.where(w > 10.0 ** (0.5 * sum(decades)), distort, 1.0)
    p = tmp_path / "hand.csv"
    p.write_text("omega_rad_s,E_storage_Pa,E_loss_Pa\n" + "".join(
        f"{float(a)!r},{float(b)!r},{float(c)!r}\n" for a, b, c in zip(w, E1, E2)))
    return p


def test_a_constant_at_its_bound_is_flagged_not_given_an_interval(tmp_path, capsys):
    p = _hand_made(tmp_path)
    fit = fit_mpl(read_dma_csv(p))
    # 4 decades below the transition: E' never nears Einf = 3.1 GPa, Einf ends on its bound
    assert "Einf" in fit.at_bound and fit.at_bound["Einf"].startswith("upper bound")
    assert math.isnan(fit.stderr["Einf"]) and math.isnan(fit.rel_stderr["Einf"])
    assert "E0" not in fit.at_bound and math.isfinite(fit.stderr["E0"])
    assert main(["fit-dma", str(p), "--maxwell", "0", "--noise", "0.03"]) == 0
    out = capsys.readouterr().out
    einf = next(ln for ln in out.splitlines() if ln.strip().startswith("Einf"))
    assert "at its upper bound 100 x max E': NOT DETERMINED" in einf and "+-" not in einf
    assert "constant(s) at a bound (Einf)" in out
    assert main(["fit-dma", str(p), "--maxwell", "0", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["mpl"]["stderr"]["Einf"] is None and "Einf" in d["mpl"]["at_bound"]
    # a curve over the whole transition: nothing at a bound
    assert fit_mpl(DMAData(*_wide())).at_bound == {}


def _wide():
    w = np.logspace(-2, 19, 60)
    E = MPLRetardation(**TRUE).complex_modulus(w)
    return w, E.real, E.imag


@pytest.mark.parametrize("seed", [3, 4, 5])
def test_kramers_kronig_passes_data_within_the_stated_noise(tmp_path, capsys, seed):
    # five decades through the start of the transition (loss tangent 4e-4 .. 0.35)
    p = _hand_made(tmp_path, noise=0.03, seed=seed, decades=(-1, 4))
    kk = kramers_kronig_check(read_dma_csv(p), noise=0.03)
    assert kk.threshold == pytest.approx(0.02 + 1.5 * 0.03)
    assert kk.consistent, kk.to_dict()
    assert main(["fit-dma", str(p), "--maxwell", "0", "--noise", "0.03"]) == 0
    line = next(ln for ln in capsys.readouterr().out.splitlines()
                if ln.startswith("Kramers-Kronig"))
    assert "tolerance 0.065 = 0.02 + 1.5 x the stated noise 0.03" in line
    assert line.endswith(": consistent")
    # the same curve with its loss modulus doubled over the upper half is not consistent
    bad = _hand_made(tmp_path, noise=0.03, seed=seed, distort=2.0, decades=(-1, 4))
    assert not kramers_kronig_check(read_dma_csv(bad), noise=0.03).consistent


def test_kk_noise_option_is_checked(tmp_path, capsys):
    p = _hand_made(tmp_path)
    assert main(["fit-dma", str(p), "--noise", "2"]) == 2
    assert "noise must be in [0, 0.5]" in capsys.readouterr().err


def test_data_no_solid_gives_and_a_fit_that_misses_are_said(tmp_path, capsys):
    """A storage modulus that falls with frequency (2e6 to 1e5 Pa over four decades) had been
    fitted with E' missed by 79 % rms and reported 'converged True' without a word: both are
    warnings now (and JSON keys); MPL data within the noise give neither."""
    bad = tmp_path / "falls.csv"
    bad.write_text("omega_rad_s,E_storage_Pa,E_loss_Pa\n1,2e6,1e3\n10,1e6,2e3\n100,0.5e6,3e3\n"
                   "1000,0.2e6,3e3\n10000,0.1e6,3e3\n")
    assert main(["fit-dma", str(bad), "--maxwell", "0"]) == 0
    text = capsys.readouterr().out
    assert "WARNING: the MPL misses these data" in text
    assert "WARNING: E' falls with frequency, by 0.6 of it from 100 to 1e+03 rad/s" in text
    assert main(["fit-dma", str(bad), "--maxwell", "0", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["storage_falls"] is True and d["mpl_fit_within_noise"] is False
    good = tmp_path / "mpl.csv"
    w = np.logspace(-2, 12, 30)
    E = MPLRetardation(1.458e6, 3.089e9, 0.2207, 0.01876).complex_modulus(w)
    good.write_text("omega_rad_s,E_storage_Pa,E_loss_Pa\n" + "".join(
        f"{a!r},{b!r},{c!r}\n" for a, b, c in zip(w.tolist(), E.real.tolist(), E.imag.tolist())))
    assert main(["fit-dma", str(good), "--maxwell", "0"]) == 0
    assert "WARNING" not in capsys.readouterr().out

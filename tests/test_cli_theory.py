"""The `sweep pb` and `sweep material` commands: output, JSON, and one-line input errors."""
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from sweep.cli import main
from sweep.theory import pb_gamma_eff


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


# --------------------------------------------------------------------------------------------
# sweep pb
# --------------------------------------------------------------------------------------------
def test_pb_json(capsys):
    code, out, err = run(capsys, "pb", "--n", "0.4", "--k", "0.1", "--v", "1e-2,1,1e3", "--json")
    assert code == 0 and err == ""
    data = json.loads(out)  # exactly one JSON object
    assert set(data) == {"n", "k", "vhat", "gamma_eff"}
    assert data["vhat"] == [1e-2, 1.0, 1e3]
    expected = pb_gamma_eff(0.4, 0.1, [1e-2, 1.0, 1e3])
    np.testing.assert_allclose(data["gamma_eff"], expected, rtol=1e-15)


def test_pb_table(capsys):
    code, out, err = run(capsys, "pb", "--n", "1.6", "--k", "0.1", "--v", "0,1e12")
    assert code == 0 and err == ""
    rows = [line.split() for line in out.splitlines() if not line.startswith("#")]
    assert rows[0] == ["vhat", "gamma_eff"]
    values = np.array(rows[1:], dtype=float)
    np.testing.assert_allclose(values[:, 0], [0.0, 1e12])
    np.testing.assert_allclose(values[:, 1], [1.0, 10.0], rtol=1e-10)
    # aligned: every row has the same width
    assert len({len(line) for line in out.splitlines()[1:]}) == 1


@pytest.mark.parametrize(
    "argv,message",
    [
        (["--n", "0", "--k", "0.1", "--v", "1"], "error: n must be in (0, 10] (got 0)"),
        (["--n", "-1", "--k", "0.1", "--v", "1"], "error: n must be in (0, 10] (got -1)"),
        (["--n", "0.4", "--k", "0", "--v", "1"], "error: k must be in (0, 1] (got 0)"),
        (["--n", "0.4", "--k", "1.5", "--v", "1"], "error: k must be in (0, 1] (got 1.5)"),
        (["--n", "0.4", "--k", "0.1", "--v", "1,-2"], "error: v must be >= 0 (got -2)"),
        (["--n", "0.4", "--k", "0.1", "--v", "nan"], "error: v must be a finite number (got nan)"),
        (["--n", "0.4", "--k", "0.1", "--v", "abc"], "error: v must be a number (got 'abc')"),
        (["--n", "x", "--k", "0.1", "--v", "1"], "error: n must be a number (got 'x')"),
    ],
)
def test_pb_bad_input(capsys, argv, message):
    code, out, err = run(capsys, "pb", *argv)
    assert code == 2
    assert out == ""
    assert err == message + "\n"


def test_pb_console_script_subprocess():
    exe = Path(sys.executable).parent / "sweep"
    if not exe.exists():
        pytest.skip(f"console script not installed next to {sys.executable}")
    ok = subprocess.run(
        [str(exe), "pb", "--n", "0.8", "--k", "0.1", "--v", "1", "--json"],
        capture_output=True, text=True, timeout=120,
    )
    assert ok.returncode == 0, ok.stderr
    value = json.loads(ok.stdout)["gamma_eff"][0]
    assert value == pytest.approx(pb_gamma_eff(0.8, 0.1, 1.0), rel=1e-14)
    bad = subprocess.run(
        [str(exe), "pb", "--n", "0.8", "--k", "0.1", "--v", "abc"],
        capture_output=True, text=True, timeout=120,
    )
    assert bad.returncode == 2
    assert bad.stderr == "error: v must be a number (got 'abc')\n"
    assert "Traceback" not in bad.stderr and bad.stdout == ""


# --------------------------------------------------------------------------------------------
# sweep material
# --------------------------------------------------------------------------------------------
def mpl_chat(n, k, t):
    """Independent Chat of the MPL retardation spectrum, paper eq. (Ctgen) in Bessel form:
    1 - (1-k) 2 t^(n/2) K_n(2 sqrt t) / Gamma(n)."""
    from scipy.special import gamma, kv

    t = np.asarray(t, dtype=float)
    return 1 - (1 - k) * 2 * t ** (n / 2) * kv(n, 2 * np.sqrt(t)) / gamma(n)


def prony_eval(weights, times, t):
    """Chat = 1 - sum c_i exp(-t/tau_i); tau = inf (null in JSON) is a glassy constant."""
    total = np.ones_like(t)
    for c, tau in zip(weights, times):
        total -= c * (1.0 if tau is None or np.isinf(tau) else np.exp(-t / tau))
    return total


def test_material_mpl_json(capsys):
    t = [1e-3, 1.0, 100.0]
    code, out, err = run(
        capsys, "material", "--n", "0.22", "--k", "4.73e-4", "--t", "1e-3,1,100", "--json"
    )
    assert code == 0 and err == ""
    data = json.loads(out)
    assert data["model"] == "mpl" and data["t"] == t
    np.testing.assert_allclose(data["chat"], mpl_chat(0.22, 4.73e-4, t), rtol=1e-6)
    prony = data["prony"]
    assert prony["n_terms"] == len(prony["weights"]) == len(prony["times"])
    assert prony["max_rel_error"] <= 1e-6
    # the series reproduces Chat on the window to its stated error
    tt = np.logspace(-3, 2, 41)
    approx = prony_eval(prony["weights"], prony["times"], tt)
    np.testing.assert_allclose(approx, mpl_chat(0.22, 4.73e-4, tt), rtol=2e-6)


def test_material_sls_table(capsys):
    code, out, err = run(capsys, "material", "--k", "0.1", "--t", "0.5,2", "--model", "sls")
    assert code == 0 and err == ""
    lines = out.splitlines()
    rows = [line.split() for line in lines if not line.startswith("#")]
    assert rows[0] == ["t", "chat"]
    chat = np.array(rows[1:3], dtype=float)
    np.testing.assert_allclose(chat[:, 1], 1 - 0.9 * np.exp(-chat[:, 0]), rtol=1e-12)
    assert any(line.startswith("# Prony series") for line in lines)
    # SLS is one exact Kelvin term: weight 1 - k at time 1
    assert [float(x) for x in lines[-1].split()] == pytest.approx([0.9, 1.0], rel=1e-12)


@pytest.mark.parametrize(
    "argv,message",
    [
        (["--n", "0", "--k", "0.1", "--t", "1,2"], "error: n must be in (0, "),
        (["--n", "0.4", "--k", "0", "--t", "1,2"], "error: k must be in (0, 1] (got 0)"),
        (["--n", "0.4", "--k", "0.1", "--t", "1,-1"], "error: t must be > 0 (got -1)"),
        (["--n", "0.4", "--k", "0.1", "--t", "nan"], "error: t must be a finite number (got nan)"),
        (["--n", "0.4", "--k", "0.1", "--t", "1"], "error: t must hold at least two distinct"),
        (
            ["--n", "0.4", "--k", "0.1", "--t", "1,2", "--model", "kelvin"],
            "error: model must be one of mpl, sls",
        ),
        (
            ["--n", "0.4", "--k", "0.1", "--t", "1,2", "--rtol", "2"],
            "error: rtol must be in [",
        ),
        (["--k", "0.1", "--t", "1,2"], "error: n must be given for model mpl"),
    ],
)
def test_material_bad_input(capsys, argv, message):
    code, out, err = run(capsys, "material", *argv)
    assert code == 2
    assert out == ""
    assert err.startswith(message) and err.count("\n") == 1


@pytest.mark.parametrize("argv, message", [
    (["pb", "--n", "0.4", "--k", "0.1", "--v", "1e300"], "error: v must be <= 1e+100"),
    (["material", "--n", "0.4", "--k", "0.1", "--t", "1e-200,1e200"],
     "error: t_max/t_min must be at most 1e100"),
])
def test_extreme_values_are_one_line_errors(capsys, argv, message):
    # these ended in a ValueError / OverflowError traceback before
    code, out, err = run(capsys, *argv)
    assert code == 2 and out == ""
    assert err.startswith(message) and err.count("\n") == 1


@pytest.mark.parametrize("args, message", [
    # the option's name, not theory's argument's ("vhat must be <= 1e+100")
    (["pb", "--n", "0.4", "--k", "0.1", "--v", "1e300"], "error: v must be <= 1e+100 (got 1e+300)"),
    # an exponent given to the SLS had been ignored without a word
    (["material", "--model", "sls", "--n", "0.5", "--k", "0.1", "--t", "1,10"],
     "error: n: the SLS has no exponent (model mpl only); leave --n out"),
])
def test_options_named_and_not_ignored(capsys, args, message):
    assert main(args) == 2
    err = [ln for ln in capsys.readouterr().err.splitlines() if ln.strip()]
    assert err == [message]

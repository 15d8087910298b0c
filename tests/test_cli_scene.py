"""`sweep scene` and `sweep plot` from the command line."""
import json
import subprocess
import sys
from pathlib import Path

import pytest

from sweep import Scene, simulate
from sweep.cli import main

SCENE = ["scene", "--n", "0.8", "--k", "0.1", "--mu", "3.24", "--a0", "2.0", "--rate", "10",
         "--preset", "fast"]


def test_scene_json_has_the_promised_keys(capsys):
    assert main(SCENE + ["--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    for key in ("pull_off", "a_pulloff", "delta_pulloff", "crack_speed", "vhat", "steps",
                "wall_s", "status", "a0_result", "delta0_result", "scene_id"):
        assert key in out
    assert out["status"] == "ok" and out["pull_off"] > 1.5


def test_scene_with_delta0_reports_a0_and_delta0(capsys):
    assert main(["scene", "--n", "0.8", "--delta0", "4.0", "--rate", "10", "--preset", "fast",
                 "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["delta0_result"] == 4.0 and out["a0_result"] > 1.0


def test_scene_trajectory_and_text_output(capsys):
    assert main(SCENE + ["--json", "--trajectory"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert len(out["trajectory"]["P"]) == out["steps"] + 1
    assert main(SCENE) == 0
    text = capsys.readouterr().out
    assert "pull-off" in text and "crack" in text
    numerics = _line(text, "numerics")
    assert numerics.startswith("numerics   BEM: preset=fast mesh=graded nodes=")
    assert "nodes=0 " not in numerics and "nan" not in numerics
    assert "factorizations=" in _line(text, "cost")


def _line(text: str, head: str) -> str:
    """The line of ``sweep scene``'s text output that starts with ``head``."""
    lines = [ln for ln in text.splitlines() if ln.startswith(head)]
    assert len(lines) == 1, text
    return lines[0]


# each model shows its own numerics (issue 34 item 7): none of the BEM's mesh fields, no NaN
@pytest.mark.parametrize("model, k, numerics, cost", [
    ("crack", "0.1", "crack-front model: Radau integration rtol=", "steps="),
    ("crack", "0.99", "crack-front model, nearly elastic (1/k - 1 = 0.0101 <= 0.05): JKR at "
                      "constant Gamma = 1.00504 dg, closed form", "wall="),
    ("pb", "0.1", "PB estimate, closed form: vhat = 2.887 rhat_PB^1.171", "wall="),
])
def test_scene_text_shows_the_models_own_numerics(model, k, numerics, cost, capsys):
    assert main(["scene", "--model", model, "--n", "0.8", "--k", k, "--a0", "3",
                 "--rate", "10"]) == 0
    text = capsys.readouterr().out
    assert _line(text, "numerics").startswith("numerics   " + numerics)
    assert _line(text, "model").split() == ["model", model]
    assert "mesh=" not in text and "nodes=" not in text and "nan" not in text
    assert _line(text, "cost").startswith("cost       " + cost)   # closed forms: no steps
    assert ("initial" in text) == (model != "pb")       # the estimate has no initial state


def test_scene_text_says_why_auto_chose_its_model(capsys):
    # mu = 200 is beyond the BEM's range: auto runs the crack-front model and says so
    assert main(["scene", "--model", "auto", "--n", "0.8", "--a0", "3", "--mu", "200",
                 "--rate", "10"]) == 0
    text = capsys.readouterr().out
    assert _line(text, "model").startswith("model      crack  (auto: crack-front model")
    assert "Radau" in _line(text, "numerics")


@pytest.mark.parametrize("args, name", [
    (["--n", "-1"], "n must be"), (["--k", "2"], "k must be"), (["--rate", "abc"], "rate must be"),
    (["--mu", "nan"], "mu must be"), (["--nodes", "3.5"], "nodes must be"),
    (["--delta0", "3"], "a0/delta0"),
])
def test_scene_bad_input_one_line_exit_2(args, name, capsys):
    argv = list(SCENE)
    for flag, value in zip(args[::2], args[1::2]):
        if flag in argv:
            argv[argv.index(flag) + 1] = value
        else:
            argv += [flag, value]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and name in err


def test_scene_nodes_takes_an_exact_integer_in_any_form(capsys):
    """`--nodes 1e3` was refused ("nodes must be an integer (got '1e3')"): a number that is
    an integer is that integer, in the scene's numerics and its id."""
    bem = ["scene", "--n", "0.8", "--a0", "2", "--rate", "1", "--model", "bem", "--preset",
           "fast", "--pull-off-rtol", "1", "--json"]      # the mesh options need a mesh
    rows = []
    for nodes in ("2e2", "200", "200.0"):
        main(bem + ["--nodes", nodes])
        rows.append(json.loads(capsys.readouterr().out))
    assert {r["num_nodes"] for r in rows} == {200}
    assert len({r["scene_id"] for r in rows}) == 1
    main(bem + ["--nodes", "1.5e2"])                            # 150
    assert json.loads(capsys.readouterr().out)["num_nodes"] == 150
    assert main(bem + ["--nodes", "150.5"]) == 2
    assert capsys.readouterr().err.strip() == "error: nodes must be an integer (got '150.5')"


def test_scene_help_offers_material_only_what_it_takes(capsys):
    """`sweep scene --help` said --material [mpl|sls] also takes "a Prony table ({prony: file}
    or inline ...)"; the option takes mpl or sls, and the help says where a table goes."""
    assert main(["scene", "--help"]) == 0
    text = " ".join(capsys.readouterr().out.split())
    help_ = text[text.index("--material [mpl|sls]"):text.index("--stop")]
    assert "or a Prony table ({prony: file} or inline" not in help_
    assert "MPL retardation spectrum or SLS; mpl, sls" in help_
    assert "a Prony table is the material of a config" in help_
    assert main(SCENE + ["--material", "prony:x.csv"]) == 2
    assert "'prony:x.csv' is not one of 'mpl', 'sls'" in capsys.readouterr().err


def test_failed_scene_exits_1(capsys):
    # mu = 10, a0 = 10 on a graded mesh of 300 nodes: the process zone spans half a node
    # spacing; refused with the advice, status failed (without --nodes the scene runs on
    # the tip-following mesh, tests/engine/test_tip_following.py)
    assert main(["scene", "--n", "1", "--mu", "10", "--a0", "10", "--rate", "1",
                 "--preset", "fast", "--nodes", "300", "--json"]) == 1
    out = json.loads(capsys.readouterr().out)
    assert out["status"] == "failed" and "too coarse" in out["reason"]
    assert "more nodes" in out["reason"]


def test_console_script_and_plot(tmp_path):
    exe = Path(sys.executable).with_name("sweep")
    proc = subprocess.run([str(exe), "scene", "--n", "0.8", "--rate", "1"], capture_output=True,
                          text=True)
    assert proc.returncode == 2 and proc.stderr.startswith("error: a0/delta0")
    missing = subprocess.run([str(exe), "plot", str(tmp_path / "none.h5")], capture_output=True,
                             text=True)
    assert missing.returncode == 2 and "no such file" in missing.stderr


def test_plot_of_a_sweep_with_trajectories(tmp_path, capsys):
    cfg = tmp_path / "tiny.yaml"
    cfg.write_text(
        "name: tiny\n"
        "grid: {n: 0.8, k: 0.1, mu: 3.24, a0: 2.0, rate: [1, 100]}\n"
        "numerics: {preset: fast}\n"
        "store: {trajectories: true}\n"
        f"output: {tmp_path / 'tiny.h5'}\n")
    assert main(["run", str(cfg), "-j", "1", "--progress", "none"]) == 0
    png = tmp_path / "tiny.png"
    assert main(["plot", str(tmp_path / "tiny.h5"), "--out", str(png)]) == 0
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 20_000


def test_scene_asked_for_an_accuracy(capsys):
    """`--pull-off-rtol` (issue 33 item 1): the cheapest preset that meets it, refinements
    allowed; with --preset, that preset at the tolerance; a bad value is one line, exit 2."""
    base = [a for a in SCENE if a not in ("--preset", "fast")]
    assert main(base + ["--pull-off-rtol", "0.01", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["num_pull_off_rtol"] == 0.01 and out["num_refinements"] == 3
    assert out["num_band_resolution"] == 16.0                   # balanced's resolution
    assert out["error_estimate"] <= 0.01 and out["band_resolution_used"] >= 16.0
    assert main(SCENE + ["--pull-off-rtol", "0.01", "--json"]) in (0, 1)
    out = json.loads(capsys.readouterr().out)
    assert out["num_band_resolution"] == 9.0 and out["num_refinements"] == 3
    assert out["status"] == "ok" or out["reason"].startswith("unresolved")
    assert main(base + ["--pull-off-rtol", "2"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["error: pull_off_rtol must be in (0, 1] (got 2)"]
    # the text names the preset the request started from, not --preset's default
    assert main(base + ["--pull-off-rtol", "0.05"]) in (0, 1)
    assert "BEM: preset=fast (from --pull-off-rtol)" in capsys.readouterr().out
    assert main(SCENE + ["--pull-off-rtol", "0.05"]) in (0, 1)
    assert "BEM: preset=fast mesh=" in capsys.readouterr().out


def test_scene_text_shows_a_protocols_cycle_and_its_error(capsys):
    """A test protocol's row: the hysteresis energy (the work to the pull-off) and its error
    estimate, the same numbers as the Result; a relaxed start has no such line."""
    argv = ["scene", "--n", "0.5", "--k", "1", "--mu", "5", "--rate", "10",
            "--approach-rate", "1", "--preload", "2", "--dwell", "1"]
    assert main(argv) == 0
    res = simulate(Scene(n=0.5, k=1.0, mu=5.0, rate=10.0, approach_rate=1.0, preload=2.0,
                         dwell=1.0))
    cycle = _line(capsys.readouterr().out, "cycle").split()
    assert float(cycle[1].split("=")[1]) == pytest.approx(res.hysteresis_energy, rel=1e-5)
    assert float(cycle[-1].split("=")[1]) == pytest.approx(res.hysteresis_error, rel=1e-5)
    assert main(["scene", "--n", "0.5", "--k", "1", "--mu", "5", "--rate", "10",
                 "--a0", "2"]) == 0
    assert "cycle" not in capsys.readouterr().out


def test_scene_takes_the_knobs_its_advice_names(capsys):
    """A failure's advice names band_resolution, max_nodes, max_steps and time_budget_s;
    `sweep scene` had none of these options. Each reaches the row's numerics."""
    assert main(SCENE + ["--band-resolution", "12", "--max-nodes", "500", "--max-steps", "1e5",
                         "--time-budget", "60", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert (out["num_band_resolution"], out["num_max_nodes"], out["num_max_steps"],
            out["num_time_budget_s"]) == (12.0, 500, 100000, 60.0)
    assert main(SCENE + ["--band-resolution", "1"]) == 2
    assert "band_resolution must be in [2, 500] (got 1)" in capsys.readouterr().err


def test_scene_si_runs_at_the_numerics_asked_for(capsys):
    """`sweep scene --si` ignored --preset (and every numerics option): the fast and the
    accurate presets gave the balanced row. Independent value: run_si at those numerics."""
    from sweep import Numerics
    from sweep.campaign.si import SIScene, run_si

    si = ["scene", "--si", "--R", "1e-4", "--E0", "1e6", "--Einf", "1e7", "--nu", "0.5", "--n",
          "0.8", "--tau0", "0.1", "--dg", "0.05", "--h0", "2e-7", "--a0-si", "1e-5", "--speed",
          "1e-6", "--model", "bem", "--json"]
    pull_offs = {}
    for preset in ("fast", "accurate"):
        assert main(si + ["--preset", preset]) == 0
        pull_offs[preset] = json.loads(capsys.readouterr().out)["pull_off"]
    assert pull_offs["fast"] != pull_offs["accurate"]
    scene = SIScene(n=0.8, R=1e-4, E0=1e6, Einf=1e7, nu=0.5, tau0=0.1, dg=0.05, h0=2e-7,
                    a0=1e-5, speed=1e-6)
    assert pull_offs["fast"] == run_si(scene, "bem", Numerics.preset("fast"))["pull_off"]


def test_scene_refuses_mesh_options_for_a_model_without_a_mesh(capsys):
    """`--model crack --nodes 100 --exact` (or pb) was accepted and ignored; a time budget
    applies to every model and stays accepted."""
    base = ["scene", "--n", "0.8", "--k", "0.1", "--mu", "3.24", "--a0", "2", "--rate", "10"]
    assert main(base + ["--model", "crack", "--nodes", "100", "--exact"]) == 2
    assert capsys.readouterr().err.strip() == (
        "error: --nodes, --exact: model crack has no mesh and no time steps (the BEM's and "
        "the elastic branch's options)")
    assert main(base + ["--model", "pb", "--band-resolution", "20"]) == 2
    assert main(base + ["--model", "crack", "--time-budget", "30", "--json"]) == 0


def test_an_unresolved_row_prints_its_pull_off_marked(capsys):
    """A failed, unresolved row's finest pull-off had been only inside the reason's text (and
    in --json): the text output prints it on the pull-off line, marked unresolved."""
    argv = ["scene", "--n", "0.5", "--k", "1", "--mu", "2", "--a0", "2", "--rate", "1",
            "--pz-law", "gent-schultz", "--pz-v0", "1000", "--pz-xi", "0.5", "--model", "bem"]
    assert main(argv + ["--json"]) == 1
    row = json.loads(capsys.readouterr().out)
    assert row["status"] == "failed" and row["reason"].startswith("unresolved")
    assert main(argv) == 1
    line = [ln for ln in capsys.readouterr().out.splitlines() if ln.startswith("pull-off")]
    assert line == [f"pull-off   P={row['pull_off']:.6g} (pi dg R), unresolved: "
                    f"error_estimate={row['error_estimate']:.3g} > pull_off_rtol"]

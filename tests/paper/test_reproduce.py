"""The reproduction pipeline (python -m sweep.paper.reproduce): fit files, figures and REPORT.md
from synthetic results files with known fits (no simulation: fast)."""
import json

import pytest

from sweep.cli import main as sweep_main
from tests.analysis.test_fits import synthetic_threshold_runs, synthetic_vr_runs, write_results

pytest.importorskip("matplotlib")


def main(argv):
    """``sweep reproduce ARGV`` (what python -m sweep.paper.reproduce runs)."""
    return sweep_main(["reproduce", *argv])


def test_pipeline_writes_fits_figures_and_report(tmp_path, capsys):
    root = tmp_path / "results"
    thr = tmp_path / "thr.h5"
    write_results(thr, synthetic_threshold_runs().assign(wall_s=1.0, reason=""))
    vr = tmp_path / "vr.h5"
    write_results(vr, synthetic_vr_runs().assign(wall_s=2.0, reason=""))
    assert main(["threshold", str(thr), str(root / "threshold")]) == 0
    assert main(["vr", str(vr), str(root / "vr")]) == 0
    assert main(["theory", str(root / "theory"), "--vr", str(vr)]) == 0
    assert main(["report", "--results", str(root)]) == 0
    capsys.readouterr()
    for rel in ("threshold/threshold.png", "vr/v_vs_r.png", "vr/pb_vs_bem.png",
                "theory/mplplot.png", "theory/pb_bem.png", "theory/b1.png"):
        assert (root / rel).stat().st_size > 10_000, rel
    fit = json.loads((root / "threshold" / "fit.json").read_text())
    assert fit["exponent"] == pytest.approx(2.7, abs=1e-2)           # the synthetic truth
    assert fit["cost"]["scenes"] == fit["cost"]["ok"] + fit["cost"]["failed"]
    assert fit["cost"]["failed"] == 1 and fit["provenance"]["results"] == str(thr)
    vfit = json.loads((root / "vr" / "fit.json").read_text())
    assert vfit["exponent"] == pytest.approx(1.1, rel=1e-9)
    theory = json.loads((root / "theory" / "theory.json").read_text())
    # q1(n) of PB theory: (1-k) pi n for small k, a line through ~0
    q = theory["b1"]["q1_linear_fit"]
    assert abs(q["intercept"]) < 0.05 and q["slope"] == pytest.approx(3.14, rel=1e-2)
    report = (root / "REPORT.md").read_text()
    # each fit beside the paper's value, figures linked, counts and the failure listed
    assert f"{fit['exponent']:.4g}" in report and "| 2.7 |" in report
    assert f"{vfit['prefactor']:.4g}" in report and "| 2.887 |" in report
    assert "](threshold/threshold.png)" in report and "](vr/pb_vs_bem.png)" in report
    assert "`make fig3` | `configs/fig3.yaml` | not run" in report
    assert "Failures: " in report and "failed" in report
    # written elsewhere, its links lead to the same files (they had pointed nowhere)
    other = tmp_path / "elsewhere" / "R.md"
    other.parent.mkdir()
    assert main(["report", "--results", str(root), "--out", str(other)]) == 0
    moved = other.read_text()
    assert "](../results/threshold/threshold.png)" in moved
    assert (other.parent / "../results/threshold/threshold.png").exists()


def test_bad_input_one_line_exit_2(tmp_path, capsys):
    assert main(["threshold", str(tmp_path / "none.h5"), str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("error: results") and "\n" not in err
    assert main(["report", "--results", str(tmp_path / "nodir")]) == 2
    assert "\n" not in capsys.readouterr().err.strip()


def test_an_output_that_cannot_be_a_directory_or_written_is_one_line(tmp_path, capsys):
    """OUTDIR an existing file (theory, vr, fig3, ...) and report --out into a missing folder:
    one line, exit 2 (they had ended in FileExistsError and FileNotFoundError tracebacks);
    the file in the way is as it was."""
    vr = tmp_path / "vr.h5"
    write_results(vr, synthetic_vr_runs().assign(wall_s=2.0, reason=""))
    before = vr.read_bytes()
    for args in (["theory", str(vr)], ["vr", str(vr), str(vr)]):
        capsys.readouterr()
        assert main(args) == 2
        err = capsys.readouterr().err.strip()
        assert err == f"error: outdir: {vr} is a file; give a directory", err
    assert vr.read_bytes() == before
    root = tmp_path / "results"
    assert main(["vr", str(vr), str(root / "vr")]) == 0
    capsys.readouterr()
    assert main(["report", "--results", str(root), "--out", str(tmp_path / "no" / "R.md")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"error: out: cannot write {tmp_path / 'no' / 'R.md'} (") and "\n" not in err


def test_figure_titles_say_what_the_data_hold(tmp_path):
    """The threshold figure's titles were the paper campaign's ("k = 0.1, mu = 3.24", "every
    rate 10^0-10^6") whatever the file held; aconv joined several n into one line per a0.
    Titles now come from the rows."""
    from sweep.paper.figures import _held, _rates

    import pandas as pd

    d = pd.DataFrame({"k": [0.1, 0.1], "mu": [2.9, 2.9], "n": [0.4, 1.6],
                      "rate": [10**0.5, 100.0]})
    assert _held(d, "k", "mu") == r"k = 0.1, $\mu$ = 2.9"
    assert _held(d, "n") == "n = 0.4-1.6"
    assert _rates(d) == r"rates $10^{0.5}$-$10^{2}$"


def test_fig3_refuses_a_file_without_its_scenes(tmp_path, capsys):
    """A file without Fig. 3's scenes had drawn three empty panels and exited 0."""
    import pandas as pd

    from sweep.paper.figures import fig3_panels

    vr = tmp_path / "vr.h5"
    write_results(vr, synthetic_vr_runs().assign(wall_s=2.0, reason=""))
    assert main(["fig3", str(vr), str(tmp_path / "f3")]) == 2
    err = capsys.readouterr().err.strip()
    assert "holds no trajectory of an ok scene" in err and "\n" not in err
    d = pd.DataFrame({"n": [0.8, 0.8, 1.6, 0.4], "a0": [3.61, 3.61, 2.0, 3.61],
                      "rate": [10.0, 10**2.5, 10**2.5, 1.0]})
    assert fig3_panels(d) == [2, 1, 1]
    assert fig3_panels(d.assign(a0=2.5, n=0.4, rate=1.0)) == [0, 0, 0]


def test_the_report_names_the_config_that_ran(tmp_path, capsys):
    """A QUICK=1 report had named the full campaigns' configs (configs/threshold.yaml, "28 of
    28") though the thinned ones ran: the campaign table names each results file's own
    ``config_source``."""
    thr = tmp_path / "thr.h5"
    write_results(thr, synthetic_threshold_runs().assign(wall_s=1.0, reason=""),
                  config_name="threshold-quick", config_source="configs/quick/threshold.yaml")
    root = tmp_path / "results"
    assert main(["threshold", str(thr), str(root / "threshold")]) == 0
    assert main(["report", "--results", str(root)]) == 0
    capsys.readouterr()
    report = (root / "REPORT.md").read_text()
    assert "| `make threshold` | `configs/quick/threshold.yaml` |" in report
    assert "`configs/threshold.yaml`" not in report

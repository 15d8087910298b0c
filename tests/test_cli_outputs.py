"""Output paths of the command line (`sweep plot --out`, `sweep info --si --csv`, `sweep fit-dma
--plot/--out`): a path that cannot be written, or a figure format matplotlib does not know, is
one line naming the option, exit 2, no traceback, nothing written (sweep.errors.writing and
sweep.analysis.plots.save_figure, the one helper every figure and file goes through)."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from sweep.campaign.scheduler import run_sweep
from sweep.cli import main
from sweep.materials import MPLRetardation
from sweep.scene import Result

pytest.importorskip("matplotlib")

#: unwritable places and the reasons given (either, by what writes: a figure's directory is
#: created first, a file is opened): a missing directory under /proc, a parent that is a
#: file, a path that is a directory
BAD_PATHS = [
    ("/proc/nope/x.{ext}", ("No such file or directory",)),
    ("{tmp}/afile/x.{ext}", ("{tmp}/afile is a file, not a directory", "Not a directory")),
    ("{tmp}/adir/x.{ext}", ("Is a directory",)),
]


def assert_cannot_write(err: str, option: str, path: str, reasons: tuple) -> None:
    """``err`` is the one line ``error: OPTION: cannot write PATH (REASON)``."""
    line = one_error_line(err)
    assert line.startswith(f"error: {option}: cannot write {path} ("), line
    assert any(r in line for r in reasons), line


def one_error_line(err: str) -> str:
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: "), err
    return lines[0]


def _ok(scene, numerics):
    return Result(scene=scene, numerics=numerics, status="ok", pull_off=1.5 + scene.n)


@pytest.fixture
def places(tmp_path):
    (tmp_path / "afile").write_text("x")
    for ext in ("png", "csv", "json"):
        (tmp_path / "adir" / f"x.{ext}").mkdir(parents=True)
    return tmp_path


@pytest.fixture
def results(tmp_path):
    out = tmp_path / "r.h5"
    run_sweep({"name": "r", "grid": {"n": [0.4, 0.8], "rate": [1, 10], "a0": 2.0},
               "numerics": {"preset": "fast"}, "output": str(out)}, jobs=1, simulate=_ok,
              progress="none")
    return out


def _expand(path: str, reasons: tuple, tmp: Path, ext: str) -> tuple[str, tuple]:
    return (path.replace("{tmp}", str(tmp)).replace("{ext}", ext),
            tuple(r.replace("{tmp}", str(tmp)) for r in reasons))


@pytest.mark.parametrize("path, reasons", BAD_PATHS)
def test_plot_out_that_cannot_be_written(places, results, capsys, path, reasons):
    path, reasons = _expand(path, reasons, places, "png")
    assert main(["plot", str(results), "--out", path]) == 2
    assert_cannot_write(capsys.readouterr().err, "out", path, reasons)


@pytest.mark.parametrize("args", [["plot", "{results}", "--out", "{tmp}/x.foo"],
                                  ["fit-dma", "{dma}", "--maxwell", "0", "--plot", "{tmp}/x.foo"]])
def test_a_figure_format_matplotlib_cannot_write(places, results, capsys, args):
    dma = _master_curve(places)
    args = [a.replace("{results}", str(results)).replace("{dma}", str(dma))
            .replace("{tmp}", str(places)) for a in args]
    assert main(args) == 2
    line = one_error_line(capsys.readouterr().err)
    option = "out" if args[0] == "plot" else "plot"
    assert line.startswith(f"error: {option}: cannot write a figure as '.foo'")
    assert ".png" in line and ".svg" in line and ".pdf" in line   # what it can write
    assert not (places / "x.foo").exists()


def test_plot_writes_another_known_format(results, tmp_path, capsys):
    out = tmp_path / "fig.svg"
    assert main(["plot", str(results), "--out", str(out)]) == 0
    assert capsys.readouterr().out.strip() == str(out)
    assert out.read_text().lstrip().startswith("<?xml")


@pytest.fixture
def si_results(tmp_path):
    p = tmp_path / "si.yaml"
    p.write_text("name: si\nunits: si\ngrid: {R: 5.19e-3, E0: 1.0e+6, Einf: 1.0e+7, nu: 0.5, "
                 "n: 0.8, tau0: 0.1, dg: 0.05, h0: 2.0e-7, preload: 1.0e-3, speed: 1.0e-6, "
                 f"model: pb}}\noutput: {tmp_path / 'si.h5'}\n")
    assert main(["run", str(p), "-j", "1", "--progress", "none"]) == 0
    return tmp_path / "si.h5"


@pytest.mark.parametrize("path, reasons", BAD_PATHS)
def test_info_csv_that_cannot_be_written(places, si_results, capsys, path, reasons):
    path, reasons = _expand(path, reasons, places, "csv")
    capsys.readouterr()
    assert main(["info", str(si_results), "--si", "--csv", path]) == 2
    assert_cannot_write(capsys.readouterr().err, "csv", path, reasons)


def _master_curve(tmp: Path) -> Path:
    w = np.logspace(0, 12, 25)
    E = MPLRetardation(1e6, 1e8, 0.4, 1e-3).complex_modulus(w)
    p = tmp / "m.csv"
    p.write_text("omega_rad_s,E_storage_Pa,E_loss_Pa\n"
                 + "".join(f"{a:.10g},{b:.10g},{c:.10g}\n" for a, b, c in zip(w, E.real, E.imag)))
    return p


@pytest.mark.parametrize("option, ext", [("--plot", "png"), ("--out", "json")])
@pytest.mark.parametrize("path, reasons", BAD_PATHS)
def test_fit_dma_outputs_that_cannot_be_written(places, capsys, option, ext, path, reasons):
    path, reasons = _expand(path, reasons, places, ext)
    code = main(["fit-dma", str(_master_curve(places)), "--maxwell", "0", option, path])
    assert code == 2
    assert_cannot_write(capsys.readouterr().err, option[2:], path, reasons)


def test_a_figure_without_a_suffix_is_a_png_and_its_path_is_printed(results, tmp_path, capsys):
    """matplotlib writes OUT.png for an OUT without a suffix: that is the path printed (and the
    one fit-dma's JSON names), not OUT."""
    out = tmp_path / "plotnoext"
    assert main(["plot", str(results), "--out", str(out)]) == 0
    assert capsys.readouterr().out.strip() == f"{out}.png"
    assert Path(f"{out}.png").read_bytes()[:4] == b"\x89PNG" and not out.exists()
    fig = tmp_path / "dmanoext"
    assert main(["fit-dma", str(_master_curve(tmp_path)), "--maxwell", "0", "--plot", str(fig),
                 "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["plot"] == f"{fig}.png"
    assert Path(f"{fig}.png").read_bytes()[:4] == b"\x89PNG"


def test_info_csv_needs_si(results, si_results, tmp_path, capsys):
    """`sweep info FILE --csv X` without --si wrote nothing and exited 0: it is refused in one
    line (docs/configs.md: --csv is an option of --si), and with --si it writes the table."""
    out = tmp_path / "x.csv"
    for path in (results, si_results):
        capsys.readouterr()
        assert main(["info", str(path), "--csv", str(out)]) == 2
        line = one_error_line(capsys.readouterr().err)
        assert line.startswith("error: csv: needs --si") and "sweep.load" in line
        assert not out.exists()
    assert main(["info", str(si_results), "--si", "--csv", str(out)]) == 0
    assert out.read_text().startswith("scene_id,")


def test_an_output_never_replaces_the_input_or_a_results_file(results, si_results, tmp_path,
                                                             capsys):
    """`sweep info R --si --csv R` had replaced the results file by its CSV table (exit 0),
    `--csv` onto another results file likewise, `sweep fit-dma m.csv --out m.csv` the DMA data
    by the fit; `--out DIR/` had written DIR.png beside the directory. Each is one line naming
    the option, exit 2, and the file is as it was."""
    cases = [(["info", str(si_results), "--si", "--csv", str(si_results)], si_results,
              f"error: csv: {si_results} is the input {si_results}; give another file"),
             (["info", str(si_results), "--si", "--csv", str(results)], results,
              f"error: csv: {results} is an HDF5 file (a sweep's results?); it is not written "
              f"over"),
             (["fit-dma", str(_master_curve(tmp_path)), "--maxwell", "0", "--out",
               str(tmp_path / "m.csv")], tmp_path / "m.csv",
              f"error: out: {tmp_path / 'm.csv'} is the input")]
    for args, kept, needle in cases:
        before = Path(kept).read_bytes()
        capsys.readouterr()
        assert main(args) == 2
        assert one_error_line(capsys.readouterr().err).startswith(needle)
        assert Path(kept).read_bytes() == before
    (tmp_path / "figs").mkdir()
    assert main(["plot", str(results), "--out", f"{tmp_path / 'figs'}/"]) == 2
    assert "names a directory; give a file in it" in one_error_line(capsys.readouterr().err)
    assert not (tmp_path / "figs.png").exists() and not any((tmp_path / "figs").iterdir())

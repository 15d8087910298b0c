"""docs/: every citation of docs/design.md points at an existing section, and the numbers
the design notes quote are what the code computes."""
from __future__ import annotations

import re
from pathlib import Path

import pytest

from sweep import units

ROOT = Path(__file__).resolve().parents[1]
DESIGN = ROOT / "docs" / "design.md"
CITE = re.compile(r"docs/design\.md`?\s+sections?\s+([\d ,and]+)")


def _sections() -> set[str]:
    return set(re.findall(r"^## (\d+)\. ", DESIGN.read_text(), flags=re.M))


def _sources():
    for pattern in ("sweep/**/*.py", "kernels/*.py", "tests/**/*.py", "configs/*.yaml",
                    "docs/*.md", "README.md"):
        yield from ROOT.glob(pattern)


def test_design_citations_point_at_sections():
    sections = _sections()
    assert {"1", "2", "3", "4", "8"} <= sections
    cited = 0
    for path in _sources():
        text = path.read_text()
        assert not re.search(r"(?<![\w/])" + "DESIGN" + r"\.md", text), f"{path}: old note"
        for group in CITE.findall(text.replace("\n", " ")):
            for num in re.findall(r"\d+", group):
                cited += 1
                assert num in sections, f"{path}: docs/design.md section {num} does not exist"
    assert cited > 10


def test_numbers_quoted_in_the_design_notes():
    text = DESIGN.read_text()
    assert f"{units.h0_hat(3.24):.5f}" in text                       # 0.14389
    assert f"= {units.l0_coefficient():.4f}" in text                  # c_l = 2.4797
    assert f"l0 = {units.l0_hat(1.0):.4f}/mu^2" in text               # 1.6931/mu^2


@pytest.mark.parametrize("page", ["design.md", "configs.md", "results.md", "cluster.md"])
def test_pages_exist(page):
    assert (ROOT / "docs" / page).stat().st_size > 500


def test_setup_says_how_to_reach_the_sweep_command():
    """`sweep` lives in .venv/bin, which is not on PATH: the README's set-up and the end of
    `make demo` say so (both ways: the full path, and activating the environment)."""
    readme = ROOT.joinpath("README.md").read_text()
    setup = readme[: readme.index("## One scene")]
    assert ".venv/bin/sweep" in setup and "source .venv/bin/activate" in setup
    demo = ROOT.joinpath("Makefile").read_text().split("\ndemo:", 1)[1].split("\n\n", 1)[0]
    echoed = "\n".join(ln for ln in demo.splitlines() if "@echo" in ln)
    assert ".venv/bin/sweep" in echoed and "source .venv/bin/activate" in echoed


def test_results_doc_lists_every_column():
    """docs/results.md names every column of the runs table (the numerics by their prefix)."""
    from sweep.campaign.config import load_config
    from sweep.campaign.scheduler import template_row

    doc = ROOT.joinpath("docs", "results.md").read_text()
    cols = list(template_row(load_config(ROOT / "configs" / "demo.yaml")))
    assert "scene_id" in cols and any(c.startswith("num_") for c in cols)
    missing = [c for c in cols if not c.startswith("num_") and f"`{c}`" not in doc]
    assert not missing, f"docs/results.md does not list the columns {missing}"


def test_configs_doc_quotes_the_bem_mu_range():
    from sweep.engine.problem import BEM_MU_RANGE

    text = ROOT.joinpath("docs", "configs.md").read_text()
    lo, hi = BEM_MU_RANGE
    assert f"mu in [{lo:g}, {hi:g}]" in text and "mu > 20" not in text


def _fake_with_trajectory(scene, numerics):
    import numpy as np

    from sweep.scene import Result

    t = np.linspace(0.0, 1.0, 5)
    res = Result(scene=scene, numerics=numerics, status="ok", pull_off=1.0)
    res.trajectory = {"t": t, "delta": -t, "P": t ** 2, "a": 2.0 - t, "a_inner": 1.5 - t}
    return res


def test_readme_reading_snippet_runs(tmp_path, monkeypatch):
    """The README's `sweep.load` / `sweep.load_trajectory` snippet runs on the file `make demo`
    writes (here with a stand-in solver: the snippet, not the physics, is checked)."""
    from sweep.campaign.scheduler import run_sweep

    readme = ROOT.joinpath("README.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", readme, flags=re.S)
    snippet = next(b for b in blocks if "load_trajectory" in b)
    paths = set(re.findall(r'"(results/[^"]+\.h5)"', snippet))
    assert paths == {"results/demo.h5"}, paths       # one file, the demo's
    monkeypatch.chdir(tmp_path)
    run_sweep(ROOT / "configs" / "demo.yaml", jobs=1, simulate=_fake_with_trajectory,
              progress="none")
    scope: dict = {}
    exec(compile(snippet, "README.md", "exec"), scope)  # noqa: S102 - our own README
    assert len(scope["df"]) == 12 and set(scope["tr"]) >= {"t", "P", "a"}

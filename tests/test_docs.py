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


@pytest.mark.parametrize("page", ["design.md", "configs.md", "results.md"])
def test_pages_exist(page):
    assert (ROOT / "docs" / page).stat().st_size > 500


def test_setup_says_how_to_reach_the_sweep_command():
    """`sweep` lives in .venv/bin, which is not on PATH: the README's set-up and the end of
    `make demo` say so (both ways: the full path, and activating the environment)."""
    readme = ROOT.joinpath("README.md").read_text()
    setup = readme[: readme.index("## Units")]
    assert ".venv/bin/sweep" in setup and "source .venv/bin/activate" in setup
    demo = ROOT.joinpath("Makefile").read_text().split("\ndemo:", 1)[1].split("\n\n", 1)[0]
    echoed = "\n".join(ln for ln in demo.splitlines() if "@echo" in ln)
    assert ".venv/bin/sweep" in echoed and "source .venv/bin/activate" in echoed

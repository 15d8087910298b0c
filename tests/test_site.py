"""The documentation site (issue 34 items 3-5), checked statically: `make docs` builds it
(docs/conf.py) and .ci/run runs that; here, without building it, that its configuration
covers what the site promises. Every example is executed by the gallery, the CLI reference
lists every command, every page is in the table of contents, the docs extra's packages are
pinned in constraints.txt within the extra's ranges, nothing reaches the network at build
time, and the sample DMA file is what its generator writes."""
from __future__ import annotations

import re
import runpy
import tomllib
from pathlib import Path

import numpy as np
import pytest
from packaging.requirements import Requirement

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"


@pytest.fixture(scope="module")
def conf():
    """docs/conf.py's namespace (it imports sweep and loads the CLI's lazy commands)."""
    return runpy.run_path(str(DOCS / "conf.py"))


def test_gallery_executes_every_example(conf):
    gallery = conf["sphinx_gallery_conf"]
    assert "sphinx_gallery.gen_gallery" in conf["extensions"]
    assert gallery["examples_dirs"] == "examples" and gallery["abort_on_example_error"]
    assert not gallery.get("only_warn_on_example_error")
    assert gallery.get("plot_gallery", "True") in (True, "True")
    scripts = sorted((DOCS / "examples").glob("*.py"))
    assert len(scripts) >= 8
    pattern = re.compile(gallery["filename_pattern"])
    for script in scripts:
        # sphinx-gallery matches the pattern against the script's full path
        assert pattern.search(str(script)), f"{script.name} would be shown but never run"
        head = script.read_text().split('"""')
        assert len(head) >= 3 and head[1].strip().splitlines()[1].startswith("="), \
            f"{script.name}: a gallery script opens with a docstring whose title is underlined"


def test_gallery_index_states_the_examples_and_their_time():
    """The gallery's header page names its total run time and covers every example."""
    header = (DOCS / "examples" / "README.txt").read_text()
    scripts = sorted((DOCS / "examples").glob("plot_*.py"))
    m = re.search(r"(\d+) examples ran in ([\d.]+) s", " ".join(header.split()))
    assert m, "docs/examples/README.txt states 'N examples ran in T s ...'"
    assert int(m.group(1)) == len(scripts)
    for script in scripts:
        assert script.stem in header, f"README.txt does not list {script.stem}'s time"


def test_cli_reference_lists_every_command(conf):
    """sphinx-click documents a group's loaded commands; conf.py loads the lazy ones."""
    import click

    from sweep.cli import cli

    with click.Context(cli) as ctx:
        listed = set(cli.list_commands(ctx))
    assert "reproduce" in listed and listed == set(cli.commands)
    assert ".. click:: sweep.cli:cli" in (DOCS / "cli.rst").read_text()
    assert ":nested: full" in (DOCS / "cli.rst").read_text()


def _sources() -> set[str]:
    """The site's source pages (docnames), not what the build generates."""
    generated = {"_build", "auto_examples", "examples"}
    return {p.relative_to(DOCS).with_suffix("").as_posix()
            for p in [*DOCS.rglob("*.md"), *DOCS.rglob("*.rst")]
            if not generated & set(p.relative_to(DOCS).parts)} - {"sg_execution_times"}


def test_every_page_is_in_a_table_of_contents():
    entries = {"index"}
    for doc in _sources():
        path = next(DOCS.glob(doc + ".*"))
        folder = Path(doc).parent.as_posix()
        for block in re.findall(r"toctree::\n((?:   .*\n|\n)+)", path.read_text()):
            for entry in re.findall(r"^   ([\w/-]+)$", block, flags=re.M):
                entries.add(entry if folder == "." else f"{folder}/{entry}")
    assert _sources() <= entries, f"in no table of contents: {sorted(_sources() - entries)}"
    assert "auto_examples/index" in entries


def test_api_reference_covers_the_public_api():
    import sweep

    api = "\n".join(p.read_text() for p in (DOCS / "api").glob("*.rst"))
    for name in sweep.__all__:
        if name not in ("__version__", "PRESETS"):
            assert f"sweep.{name}" in api, f"docs/api/ does not document sweep.{name}"
    for module in ("sweep.units", "sweep.materials", "sweep.theory", "sweep.analysis.fits",
                   "sweep.analysis.dma", "sweep.analysis.calibrate", "sweep.campaign.si"):
        assert f".. automodule:: {module}" in api, module


def test_build_is_offline_and_strict(conf):
    assert not any("intersphinx" in e or "linkcheck" in e for e in conf["extensions"])
    make = (ROOT / "Makefile").read_text()
    rule = make.split("\ndocs: ", 1)[1].split("\n\n", 1)[0]
    assert "sphinx -W " in rule and "docs/_build/html" in rule
    ci = (ROOT / ".ci" / "run").read_text()
    assert re.search(r"^make docs$", ci, flags=re.M) and re.search(r"^make test$", ci, flags=re.M)
    ignored = (ROOT / ".gitignore").read_text().splitlines()
    for generated in ("docs/_build/", "docs/auto_examples/", "docs/sg_execution_times.rst"):
        assert generated in ignored


def test_docs_extra_is_pinned_in_constraints():
    """Each package of the docs extra is pinned in constraints.txt (which the Makefile installs
    with) at a version its range in pyproject.toml admits."""
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    extra = [Requirement(r) for r in project["optional-dependencies"]["docs"]]
    pins = {}
    for line in (ROOT / "constraints.txt").read_text().splitlines():
        name, _, version = line.partition("==")
        pins[name.lower().replace("_", "-")] = version
    names = {r.name.lower() for r in extra}
    assert {"sphinx", "furo", "myst-parser", "sphinx-click", "sphinx-gallery"} <= names
    for req in extra:
        version = pins.get(req.name.lower())
        assert version, f"constraints.txt pins no {req.name}"
        assert req.specifier.contains(version), f"{req.name}=={version} outside {req.specifier}"


def test_sample_dma_file_is_what_its_generator_writes():
    """configs/dma/pdms-master.csv is the known material plus the stated noise: the generator
    writes it again (to a relative 1e-9: its moduli's last digits may move with the
    processor), and its rows bracket the truth within the noise."""
    gen = runpy.run_path(str(ROOT / "configs" / "dma" / "make_sample.py"))
    written = np.loadtxt(ROOT / "configs" / "dma" / "pdms-master.csv", delimiter=",",
                         skiprows=1)
    again = np.loadtxt(gen["sample"]().splitlines()[1:], delimiter=",")
    np.testing.assert_allclose(written, again, rtol=1e-9)
    from sweep.materials import MPLRetardation

    E = MPLRetardation(**gen["TRUTH"]).complex_modulus(written[:, 0])
    log_dev = np.log(written[:, 1:] / np.c_[E.real, E.imag])
    assert abs(log_dev.std() - gen["NOISE"]) < 0.3 * gen["NOISE"]
    assert np.abs(log_dev).max() < 5 * gen["NOISE"]

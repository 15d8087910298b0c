"""The distribution installs every package of the source tree, under ``sweep`` only.

pyproject.toml lists the packages by hand (``kernels/`` is installed as ``sweep.kernels``): a
wing added or renamed without its line there would install without it, and a listed package
without a folder breaks ``pip install`` on a fresh clone.
"""
from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def listed_packages() -> set[str]:
    text = (ROOT / "pyproject.toml").read_text()
    block = re.search(r"^packages\s*=\s*\[(.*?)\]", text, re.S | re.M)
    assert block, "pyproject.toml: no [tool.setuptools] packages list"
    return set(re.findall(r'"([\w.]+)"', block.group(1)))


def source_packages() -> set[str]:
    found = {".".join(p.parent.relative_to(ROOT).parts)
             for p in (ROOT / "sweep").rglob("__init__.py")}
    assert (ROOT / "kernels" / "__init__.py").exists()
    return found | {"sweep.kernels"}


def test_every_package_folder_is_installed_and_every_listed_package_exists():
    assert listed_packages() == source_packages()


def test_the_kernels_folder_is_installed_inside_sweep():
    text = (ROOT / "pyproject.toml").read_text()
    assert re.search(r'^"sweep\.kernels"\s*=\s*"kernels"', text, re.M)
    assert all(name.split(".")[0] == "sweep" for name in listed_packages())


def test_the_installed_kernels_are_the_source_folder():
    import sweep.kernels.solve
    assert Path(sweep.kernels.solve.__file__).resolve() == ROOT / "kernels" / "solve.py"


def test_the_package_data_is_declared():
    """Data files inside the package (the model chooser's measured errors) are installed."""
    text = (ROOT / "pyproject.toml").read_text()
    for path in (ROOT / "sweep").rglob("*.json"):
        pkg = ".".join(path.parent.relative_to(ROOT).parts)
        assert re.search(rf'^"{re.escape(pkg)}"\s*=\s*\[[^\]]*"{path.name}"', text, re.M), path


def test_one_version_everywhere_and_sweep_version_prints_it():
    """pyproject, sweep.__version__, ``sweep --version`` (the source's, not the installed
    metadata's), CITATION.cff and the CHANGELOG's latest release name the same version."""
    from click.testing import CliRunner

    from sweep import __version__
    from sweep.cli import cli

    assert re.search(r'^version = "([^"]+)"', (ROOT / "pyproject.toml").read_text(),
                     re.M).group(1) == __version__
    out = CliRunner().invoke(cli, ["--version"])
    assert out.exit_code == 0 and out.output.strip() == f"sweep, version {__version__}"
    cff = (ROOT / "CITATION.cff").read_text()
    assert re.search(r"^version: \"?([\w.]+)\"?$", cff, re.M).group(1) == __version__
    releases = re.findall(r"^## \[?([0-9][\w.]*)\]?", (ROOT / "CHANGELOG.md").read_text(), re.M)
    assert releases and releases[0] == __version__


def test_the_license_file_is_the_license_pyproject_names():
    assert 'license = {text = "MIT"}' in (ROOT / "pyproject.toml").read_text()
    text = (ROOT / "LICENSE").read_text()
    assert text.startswith("MIT License") and "the visco-sweep developers" in text
    assert "THE SOFTWARE IS PROVIDED \"AS IS\"" in text

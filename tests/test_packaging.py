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

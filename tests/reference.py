"""Reference values for the tests, read from ``tests/data/`` (never from outside the clone).

A missing file raises: a test that cannot find its reference value fails, it does not skip.
"""
from __future__ import annotations

from functools import lru_cache
from pathlib import Path

import yaml

DATA = Path(__file__).resolve().parent / "data"


@lru_cache(maxsize=None)
def load(name: str) -> dict:
    """The parsed ``tests/data/<name>.yaml``; FileNotFoundError if it is missing."""
    path = DATA / f"{name}.yaml"
    if not path.is_file():
        raise FileNotFoundError(f"reference data {path} is missing (see tests/data/README.md)")
    return yaml.safe_load(path.read_text())


def independent_solutions() -> dict:
    return load("independent_solutions")


def paper_values() -> dict:
    return load("paper_values")

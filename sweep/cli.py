"""The ``sweep`` command line: a click group with one command per task.

Every command validates its input through :mod:`sweep.errors`; an invalid
value prints one line ``error: <parameter> must be ... (got ...)`` on stderr
and exits with code 2 (runtime failures exit 1). No traceback is shown.
"""
from __future__ import annotations

import json
import sys

import click
import numpy as np

from .errors import InputError


def parse_floats(name: str, text: str) -> list[float]:
    """Parse a comma-separated list of numbers given to option ``name``."""
    from .errors import as_float

    items = [s for s in text.split(",") if s.strip()]
    if not items:
        raise InputError(f"{name} must be a comma-separated list of numbers (got {text!r})")
    return [as_float(name, s.strip()) for s in items]


def to_jsonable(obj):
    """Recursively convert numpy arrays/scalars so ``json.dumps`` accepts them."""
    if isinstance(obj, dict):
        return {str(k): to_jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [to_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return to_jsonable(obj.tolist())
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, float) and not np.isfinite(obj):
        return None
    return obj


def echo_json(obj) -> None:
    click.echo(json.dumps(to_jsonable(obj), indent=None))


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="visco-sweep")
def cli():
    """Viscoelastic adhesive contact of a sphere: BEM scenes, sweeps and theory."""


# ----------------------------------------------------------------------------
# Commands are added below, one section per concept. Edit with str_replace only.
# ----------------------------------------------------------------------------

# == theory & materials commands (pb, material) ==

# == single scene command (scene) ==

# == sweep commands (run, info) ==


def main(argv=None) -> int:
    """Entry point: run the click group, mapping errors to one line + exit code."""
    try:
        cli.main(args=argv, standalone_mode=False)
    except InputError as exc:
        click.echo(f"error: {exc}", err=True)
        return 2
    except click.exceptions.Abort:
        click.echo("error: aborted", err=True)
        return 130
    except click.ClickException as exc:
        msg = exc.format_message().replace("\n", " ")
        click.echo(f"error: {msg}", err=True)
        return exc.exit_code if exc.exit_code else 2
    except SystemExit as exc:  # --help / --version
        return exc.code if isinstance(exc.code, int) else 0
    return 0


def entry() -> None:
    sys.exit(main())


if __name__ == "__main__":  # pragma: no cover
    entry()

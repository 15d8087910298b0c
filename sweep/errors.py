"""Input validation shared by the public API, the config loader and the CLI.

Every check raises :class:`InputError` with a one-line message that names the
parameter, the allowed range and the value received, e.g.::

    n must be > 0 (got -1)

The CLI turns an ``InputError`` into that line on stderr and exit code 2.
"""
from __future__ import annotations

import math
import os
from contextlib import contextmanager
from typing import Iterable

import numpy as np


class InputError(ValueError):
    """Invalid user input (parameter out of range, wrong type, unknown key)."""


def _fmt(value) -> str:
    try:
        return f"{value:.6g}"
    except (TypeError, ValueError):
        return repr(value)


def as_float(name: str, value) -> float:
    """Convert ``value`` to a finite float or raise ``InputError``."""
    if isinstance(value, bool):
        raise InputError(f"{name} must be a number (got {value!r})")
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a number (got {value!r})") from None
    if not math.isfinite(x):
        raise InputError(f"{name} must be a finite number (got {_fmt(x)})")
    return x


def check_range(name: str, value, lo=None, hi=None, lo_open=False, hi_open=False) -> float:
    """Return ``value`` as float, checking ``lo <= value <= hi`` (open ends optional).

    The message states the allowed interval in mathematical notation.
    """
    x = as_float(name, value)
    bad = (lo is not None and (x < lo or (lo_open and x == lo))) or (
        hi is not None and (x > hi or (hi_open and x == hi))
    )
    if bad:
        # the value in full where six digits would print it as the bound it crosses
        got = _fmt(x)
        if got in (_fmt(lo), _fmt(hi)) and x not in (lo, hi):
            got = repr(x)
        if hi is None:
            allowed = f"{'>' if lo_open else '>='} {_fmt(lo)}"
            raise InputError(f"{name} must be {allowed} (got {got})")
        if lo is None:
            allowed = f"{'<' if hi_open else '<='} {_fmt(hi)}"
            raise InputError(f"{name} must be {allowed} (got {got})")
        left = "(" if lo_open else "["
        right = ")" if hi_open else "]"
        raise InputError(f"{name} must be in {left}{_fmt(lo)}, {_fmt(hi)}{right} (got {got})")
    return x


def check_positive(name: str, value) -> float:
    """Return ``value`` as a float > 0."""
    return check_range(name, value, lo=0.0, lo_open=True)


def _exact_int(value) -> int | None:
    """``value`` as an int if it is one exactly: an int, a float with no fraction, or a
    numeric string of either (``"200"``, ``"1e6"``, as YAML 1.1 reads ``1e6``); else None."""
    if isinstance(value, (bool, np.bool_)):
        return None
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, str):
        text = value.strip()
        try:
            return int(text)
        except ValueError:
            try:
                value = float(text)
            except ValueError:
                return None
    if isinstance(value, (float, np.floating)) and math.isfinite(value) and value.is_integer():
        return int(value)
    return None


def check_int(name: str, value, lo=None, hi=None) -> int:
    """Return ``value`` as an int within [lo, hi].

    Parameters
    ----------
    name : str
        The parameter, named in the error.
    value : int, float or str
        An integer, or a float or numeric string that is one exactly (``1000.0``,
        ``"1e3"``, ``"200"``); ``1.5``, ``"1.5"`` and booleans are refused.
    lo, hi : int, optional
        The allowed range, inclusive.

    Raises
    ------
    InputError
        ``<name> must be an integer (got ...)`` or ``... an integer in [lo, hi] (got ...)``.
    """
    v = _exact_int(value)
    if v is None:
        raise InputError(f"{name} must be an integer (got {value!r})")
    if (lo is not None and v < lo) or (hi is not None and v > hi):
        lo_s = "-inf" if lo is None else str(lo)
        hi_s = "inf" if hi is None else str(hi)
        raise InputError(f"{name} must be an integer in [{lo_s}, {hi_s}] (got {v})")
    return v


def check_choice(name: str, value, choices: Iterable[str]) -> str:
    """Return ``value`` if it is one of ``choices``."""
    choices = list(choices)
    if value not in choices:
        raise InputError(f"{name} must be one of {', '.join(map(str, choices))} (got {value!r})")
    return value


def check_array(name: str, values, lo=None, hi=None, lo_open=False, hi_open=False) -> np.ndarray:
    """Return ``values`` as a float64 array, every element checked like :func:`check_range`."""
    try:
        arr = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be numbers (got {values!r})") from None
    for x in arr.ravel():
        check_range(name, x, lo, hi, lo_open, hi_open)
    return arr


#: the first bytes of every HDF5 file (a sweep's results file among them)
_HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"


def check_output(name: str, path, inputs=()) -> None:
    """Refuse, in one line naming option ``name``, an output ``path`` that is one of the
    command's ``inputs`` or an existing HDF5 file (a sweep's results): written over, it
    would be lost (``sweep info R --si --csv R`` had replaced a results file by its table,
    ``sweep fit-dma m.csv --out m.csv`` the DMA data by the fit)."""
    target = os.path.abspath(os.fspath(path))
    for source in inputs:
        if source is not None and os.path.exists(source) and os.path.exists(target) \
                and os.path.samefile(source, target):
            raise InputError(f"{name}: {path} is the input {source}; give another file")
    if os.path.isfile(target):
        try:
            with open(target, "rb") as fh:
                head = fh.read(len(_HDF5_SIGNATURE))
        except OSError:
            return                   # unreadable: writing() gives the reason
        if head == _HDF5_SIGNATURE:
            raise InputError(f"{name}: {path} is an HDF5 file (a sweep's results?); it is "
                             f"not written over: give another file")


@contextmanager
def writing(name: str, path, verb: str = "write"):
    """Turn an ``OSError`` raised while writing ``path`` into a one-line :class:`InputError`.

    Parameters
    ----------
    name : str
        The parameter (option) that gave the path, e.g. ``"out"``.
    path : str or os.PathLike
        The file (or directory) being written.
    verb : str, optional
        What is done to it: ``"write"`` (default) or ``"create"`` (a directory).

    Raises
    ------
    InputError
        ``<name>: cannot <verb> <path> (<reason>)``, the reason the operating system gives
        (and the path it names when that is another one, e.g. a parent that is a file).

    Examples
    --------
    >>> with writing("csv", "/proc/nope/x.csv"):           # doctest: +SKIP
    ...     open("/proc/nope/x.csv", "w")
    """
    try:
        yield
    except OSError as exc:
        if isinstance(exc, FileExistsError):     # a parent directory to create is a file
            reason = f"{exc.filename} is a file, not a directory"
        else:
            reason = exc.strerror or str(exc)
            if exc.filename is not None and str(exc.filename) != str(path):
                reason += f": {exc.filename}"
        raise InputError(f"{name}: cannot {verb} {path} ({reason})") from None


#: exceptions that are numerical or physical failures of a scene (a singular matrix, an
#: overflow, a failed convergence reported as RuntimeError, a model refusing a scene, no memory
#: for the mesh): the engine turns them into a failed Result with the message as reason
NUMERICAL_ERRORS = (InputError, ArithmeticError, np.linalg.LinAlgError, MemoryError, RuntimeError)
#: RuntimeError subclasses that are programming errors
_BUG_RUNTIME_ERRORS = (NotImplementedError, RecursionError)


def is_internal_error(exc: BaseException) -> bool:
    """Whether ``exc`` raised inside a scene is a programming error (TypeError, IndexError,
    KeyError, AttributeError, ValueError, ...): not a result but a bug, which the engine lets
    propagate and ``sweep run`` records as status "error" with its traceback.

    Numerical and physical failures (:data:`NUMERICAL_ERRORS`) are results: a failed row
    with the exception as reason.
    """
    if isinstance(exc, _BUG_RUNTIME_ERRORS):
        return True
    return not isinstance(exc, NUMERICAL_ERRORS)


#: how a failed result's reason begins when the scene has no answer for a physical reason
#: (not a resolution, node-count or budget limit that another model could lift): the
#: relaxed initial state has no contact of the asked radius, or the contact of that radius
#: is not stable under fixed grip (the crack-front model below about 0.5 a_ref)
PHYSICAL_REFUSALS = ("no contact in the initial state", "no stable contact")


def is_physical_refusal(reason: str) -> bool:
    """Whether a failed result's ``reason`` is a physical refusal (:data:`PHYSICAL_REFUSALS`):
    the scene's physics has no answer, as opposed to a numerical failure."""
    return any(reason.startswith(p) for p in PHYSICAL_REFUSALS)


def shortened(reason: str, limit: int) -> str:
    """``reason`` as quoted inside another (a fallback's, a refinement's): whole where it has
    at most ``limit`` characters, else cut at the last word boundary before it, with " ..."
    (a cut mid-word read "... above pull_o)")."""
    if len(reason) <= limit:
        return reason
    cut = reason[:limit].rsplit(" ", 1)[0].rstrip(",;:(")
    return f"{cut} ..."

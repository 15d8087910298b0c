r"""Calibrate an SI scene to measured pull-off force against unloading speed (issue 23).

The reverse of what the engine does: given pull-off forces ``P_i`` [N] measured at unloading
speeds ``v_i`` [m/s] (a lens pulled off a viscoelastic substrate at several speeds), find the
SI fields of :class:`sweep.campaign.si.SIScene` (work of adhesion ``dg`` [J/m^2], MPL exponent
``n``, MPL time ``tau0`` [s], glassy modulus ``Einf`` [Pa], ...) that explain the curve, with
95 % profile-likelihood intervals and a flag for every parameter the data cannot pin down.

Input: a YAML calibration file (:func:`load_calibration`)::

    name: pdms-lens
    data: pulloff.csv        # speed_m_s, pull_off_N[, sigma_N]; one row per test
    fixed: {R: 0.0103, E0: 1.0e6, nu: 0.5, h0: 3.08e-8, preload: 1.5e-3}
    fit: {dg: [0.01, 1.0], n: [0.1, 1.5], tau0: [1.0e-4, 10.0], Einf: [2.0e6, 1.0e10]}
    model: auto              # bem, crack, pb or auto (sweep.campaign.si.run_si)
    numerics: {preset: fast}

Every SI field but ``speed`` is either fixed or fitted (exactly one of ``preload``, ``a0``,
``indentation``). A rate-dependent process zone (issue 35) is optional: ``pz_law`` (``none``,
the default, or ``gent-schultz``) is a ``fixed`` field (a law is chosen, not fitted); with a
law, ``pz_v0`` [m/s] (the crack speed at which the process zone doubles the work of adhesion)
and ``pz_xi`` are fixed or fitted like the other fields (``pz_v0: [1.0e-5, 1.0]`` is searched
in log scale), without one they are not given. A bound pair spanning a decade or more (and > 0) is searched in log scale,
otherwise linearly; ``[lo, hi, log]`` or ``[lo, hi, linear]`` forces the choice. Optional
keys: ``material`` (mpl, sls), ``start`` (a starting point for the local fit), ``search``
(``{points: 64, starts: 3, seed: 0}``, the coarse search), ``profile`` (``{points: 12,
level: 0.95}``), ``diff_step`` (finite-difference step in the unit coordinates),
``truth`` (the known answer of synthetic data: reported beside the estimates).

Method (:func:`calibrate`):

1. Residuals. Without ``sigma_N``: ``r_i = ln P_model(v_i) - ln P_i`` (the noise level is
   estimated from the fit, ``s^2 = SSR/(N - p)``). With ``sigma_N`` (1 sigma, N):
   ``r_i = (P_model - P_i)/sigma_i`` (chi-square). A scene that fails adds a penalty residual
   of :data:`FAILED_RESIDUAL` (log units; times ``P_i/sigma_i`` with sigmas).
2. Coarse global search: a scrambled Sobol sample of the box of bounds (in the unit cube of
   the log/linear coordinates), all its scenes in one parallel batch; the best ``starts``
   points (and ``start`` if given) seed scipy's ``least_squares`` (trf, bounded), whose
   forward-difference Jacobian is evaluated as one parallel batch too. The best end wins.
3. Profile likelihood per free parameter: it is fixed at points of a grid over its bounds,
   walking out from the estimate, and the others re-fitted (warm-started); the statistic is
   ``D = SSR_profile - SSR_min`` with sigmas (threshold chi2(1) at ``level``: 3.84) and
   ``D = (SSR_profile - SSR_min)/s^2`` without (threshold F(1, N - p) at ``level``). The
   interval is where ``D`` stays below the threshold (the crossing refined by one regula-falsi
   step on sqrt(D)); a side that reaches its bound without crossing is open. ``identifiable``
   is true only when both sides close within the bounds; ``status`` says "identifiable",
   "lower limit only", "upper limit only" or "not identifiable" (the profile is flat below the
   threshold over the whole box: these data do not determine the parameter). A profile
   that finds a lower minimum than the local fits (SSR below the estimate's by more than
   :data:`RECENTRE_D` in D) moves the estimate: a local fit from that point, then every
   profile again about the new estimate, so that the estimate, the intervals, the statuses
   and the profile curves are about one point (each interval holds its estimate, where
   D = 0). At most :data:`MAX_RECENTRES` times (``recentred`` in the result lists each move,
   the summary prints a note); a lower point found after that is reported in ``warnings``
   (and printed) and the estimate stays at the centre of the profiles.
4. Correlation matrix: the linearized one at the estimate, ``pinv(J^T J)`` in the unit
   coordinates (the same correlations as in the log/linear coordinates); not meaningful for
   parameters that are not identifiable.
5. Band: the envelope of the predicted curves of every parameter set on the profiles whose
   statistic is below the threshold (the profile-likelihood prediction band).

Scene results are cached by a key of the parameters rounded to :data:`KEY_DIGITS`
significant digits (plus model and numerics), so the Jacobian, the profiles and the band
re-use every scene already run; the scenes of one batch run in parallel over ``jobs``
loky workers with one BLAS/OpenMP/Numba thread each (as the sweep scheduler does).

Synthetic data with a known answer: ``python -m sweep.analysis.calibrate synth FILE.yaml
--speeds LO,HI,N [--repeats R] [--noise S] [--seed K] [--sigma]`` runs the file's model at its
``truth`` and writes the file's ``data`` CSV (multiplicative log-normal noise of standard
deviation ``S``; ``--sigma`` adds a ``sigma_N`` column ``S P``).
"""
from __future__ import annotations

import argparse
import csv
import json
import math
import os
import sys
import time
from collections import Counter
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np
import pandas as pd
import yaml
from joblib import Parallel, delayed, parallel_config
from scipy import stats
from scipy.optimize import least_squares
from scipy.stats import qmc

from ..campaign.config import UniqueKeyLoader
from ..campaign.si import SI_AXES, SIScene, run_si
from ..campaign.store import to_jsonable
from ..engine import bem
from ..errors import InputError, check_choice, check_int, check_range, writing
from ..scene import PZ_LAWS, PZ_PARAMETERS, Numerics
from ..threads import THREAD_VARS, exit_with_parent, limit_env, limit_loaded_pools
from .plots import pyplot, save_figure

__all__ = ["Parameter", "Calibration", "load_calibration", "calibration_from_dict",
           "calibrate", "synthesize", "write_outputs", "SceneEvaluator", "FIT_FIELDS"]

#: the SI fields that may be fixed or fitted (every SI field of an SIScene but the speed)
FIT_FIELDS = ("R", "E0", "Einf", "nu", "n", "tau0", "dg", "h0", "preload", "a0",
              "indentation", *PZ_PARAMETERS)
INITIAL_FIELDS = ("preload", "a0", "indentation")
#: the process zone's law: a ``fixed`` field only (sweep.scene.PZ_LAWS)
LAW_FIELD = "pz_law"
DATA_COLUMNS = ("speed_m_s", "pull_off_N")
CAL_MODELS = ("bem", "crack", "pb", "auto")
TOP_KEYS = ("name", "description", "data", "fixed", "fit", "model", "numerics", "material",
            "start", "search", "profile", "diff_step", "truth")
#: significant digits of the cache key of a scene
KEY_DIGITS = 10
#: residual of a failed scene (log units: a factor e^10 off)
FAILED_RESIDUAL = 10.0
#: a profile point whose SSR is below the estimate's by more than this, in units of the
#: profile statistic D, re-centres the fit there (a smaller drop is within the local fits'
#: own tolerance: their ftol stops when a step changes D by < ~0.02)
RECENTRE_D = 0.1
#: at most this many re-centrings; a lower point found after them is reported as a warning
MAX_RECENTRES = 2


def _one_line(text) -> str:
    return " ".join(str(text).split())


# ----------------------------------------------------------------------------- parameters
@dataclass(frozen=True)
class Parameter:
    """A free parameter: its bounds (SI) and whether it is searched in log scale.

    The fit works in unit coordinates ``u`` in [0, 1]: ``u = (ln x - ln lo)/(ln hi - ln lo)``
    (log) or ``(x - lo)/(hi - lo)`` (linear).
    """

    name: str
    lo: float
    hi: float
    log: bool

    def value(self, u) -> np.ndarray | float:
        u = np.clip(u, 0.0, 1.0)
        if self.log:
            return np.exp(math.log(self.lo) + u * (math.log(self.hi) - math.log(self.lo)))
        return self.lo + u * (self.hi - self.lo)

    def unit(self, x) -> np.ndarray | float:
        if self.log:
            return (np.log(x) - math.log(self.lo)) / (math.log(self.hi) - math.log(self.lo))
        return (np.asarray(x, dtype=float) - self.lo) / (self.hi - self.lo)


@dataclass
class Calibration:
    """A validated calibration problem (:func:`load_calibration`).

    Attributes
    ----------
    speed_m_s, pull_off_N : ndarray
        The measurements, one entry per test [m/s, N].
    sigma_N : ndarray or None
        1-sigma errors of the pull-offs [N]; None: log residuals.
    fixed : dict
        Fixed SI fields (SI units, as in ``units: si`` configs).
    params : tuple of Parameter
        The free parameters, in the order of the file.
    """

    name: str
    speed_m_s: np.ndarray
    pull_off_N: np.ndarray
    sigma_N: np.ndarray | None
    fixed: dict
    params: tuple
    model: str = "auto"
    numerics: object = None
    material: str = "mpl"
    start: dict | None = None
    search_points: int = 64
    search_starts: int = 3
    seed: int = 0
    profile_points: int = 12
    level: float = 0.95
    diff_step: float = 1e-3
    truth: dict | None = None
    source: str = "<dict>"
    data_source: str = "<data>"

    @property
    def names(self) -> list:
        return [p.name for p in self.params]

    def values(self, u) -> dict:
        """The SI fields (fixed and fitted) of unit coordinates ``u``."""
        d = dict(self.fixed)
        for p, ui in zip(self.params, u):
            d[p.name] = float(p.value(ui))
        return d


def _bounds(name, spec, lims) -> Parameter:
    where = f"fit.{name}"
    scale = None
    if isinstance(spec, (list, tuple)) and len(spec) == 3 and isinstance(spec[2], str):
        scale = spec[2]
        if scale not in ("log", "linear"):
            raise InputError(f"{where}: the third entry must be log or linear (got {scale!r})")
        spec = spec[:2]
    if not isinstance(spec, (list, tuple)) or len(spec) != 2:
        raise InputError(f"{where} must be bounds [lo, hi] (optionally [lo, hi, log|linear]) "
                         f"in SI units (got {spec!r})")
    lo_lim, hi_lim, lo_open = lims
    lo = check_range(f"{where} lower bound", spec[0], lo_lim, hi_lim, lo_open=lo_open)
    hi = check_range(f"{where} upper bound", spec[1], lo_lim, hi_lim, lo_open=lo_open)
    if not lo < hi:
        raise InputError(f"{where}: bounds reversed or empty, the lower bound must be < the "
                         f"upper (got [{lo:.6g}, {hi:.6g}])")
    if scale == "log" and lo <= 0.0:
        raise InputError(f"{where}: log scale needs a lower bound > 0 (got {lo:.6g})")
    log = (lo > 0.0 and hi / lo >= 10.0) if scale is None else scale == "log"
    return Parameter(name=name, lo=lo, hi=hi, log=log)


def _limits(name) -> tuple:
    a = SI_AXES[name]
    lo, hi = a.limits
    return lo, hi, a.lo_open


def _read_data(path: Path) -> tuple:
    """The measurements of a calibration's ``data`` CSV: ``speed_m_s``, ``pull_off_N`` and
    ``sigma_N`` (None without that column).

    A ``#`` starts a comment (to the end of its line); blank lines are skipped. Every row has
    as many fields as the header: a row with more or fewer (an unlabelled extra column, a
    trailing comma) is refused, naming the row, rather than read shifted by a column.

    Raises
    ------
    InputError
        One line naming the file, and the row and column of a bad value (the value as
        written in the file).
    """
    where = f"data {str(path)!r}"
    if not path.is_file():
        raise InputError(f"data: no such file {str(path)!r}")
    try:
        # utf-8-sig: a byte-order mark (Excel's "CSV UTF-8") is not part of the header
        lines = path.read_text(encoding="utf-8-sig").splitlines()
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{where}: not a readable CSV ({_one_line(exc)})") from None
    rows = [(number, [f.strip() for f in fields])
            for number, line in enumerate(lines, 1) if line.split("#", 1)[0].strip()
            for fields in csv.reader([line.split("#", 1)[0]], skipinitialspace=True)]
    header = rows[0][1] if rows else []
    for col in DATA_COLUMNS:
        if col not in header:
            raise InputError(f"{where}: missing column {col} (columns speed_m_s, pull_off_N "
                             f"and optional sigma_N; got {', '.join(header) or 'none'})")
    unknown = [col for col in header if col not in (*DATA_COLUMNS, "sigma_N")]
    if unknown:     # a misspelt sigma_N was an unweighted fit, silently
        raise InputError(f"{where}: unknown column(s) {', '.join(unknown)} (columns speed_m_s, "
                         f"pull_off_N and optional sigma_N)")
    for i, (number, fields) in enumerate(rows[1:], 1):
        if len(fields) != len(header):
            raise InputError(f"{where}: row {i} (line {number}) has {len(fields)} fields, the "
                             f"header {len(header)} ({', '.join(header)}): an unlabelled or "
                             f"missing column, or a trailing comma?")
    cols = [*DATA_COLUMNS, *(["sigma_N"] if "sigma_N" in header else [])]
    out = {}
    for col in cols:
        j = header.index(col)
        vals = []
        for i, (_, fields) in enumerate(rows[1:], 1):
            try:
                v = float(fields[j])
            except ValueError:
                v = math.nan
            if not math.isfinite(v) or v <= 0.0:
                raise InputError(f"{where}: {col} must be a number > 0 (row {i}: "
                                 f"{fields[j] or 'empty'})")
            vals.append(v)
        out[col] = np.array(vals, dtype=float)
    if not len(out["speed_m_s"]):
        raise InputError(f"{where}: no data rows")
    return out["speed_m_s"], out["pull_off_N"], out.get("sigma_N")


def load_calibration(path) -> Calibration:
    """Read and validate a YAML calibration file (InputError with one line on any problem).

    The ``data`` CSV is read relative to the YAML file's folder.
    """
    p = Path(path)
    return calibration_from_dict(_read_yaml(p), base=p.parent, source=str(p))


def _read_yaml(p: Path) -> dict:
    try:
        text = p.read_text(encoding="utf-8-sig")
    except FileNotFoundError:
        raise InputError(f"calibration: no such file {str(p)!r}") from None
    except (IsADirectoryError, UnicodeDecodeError, OSError) as exc:
        raise InputError(f"calibration: cannot read {str(p)!r} ({_one_line(exc)})") from None
    try:
        data = yaml.load(text, Loader=UniqueKeyLoader)  # noqa: S506 -- a SafeLoader subclass
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}" if mark else ""
        problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        raise InputError(f"{p}: not valid YAML{where}: {problem}") from None
    return data


def _check_process_zone(law: str, given: set) -> None:
    """The process zone's parameters are given (fixed or fitted) exactly with a law."""
    pz = [f for f in PZ_PARAMETERS if f in given]
    if law == "none" and pz:
        raise InputError(f"{', '.join(pz)}: a process-zone parameter needs fixed.pz_law "
                         f"({', '.join(PZ_LAWS[1:])}; got none)")
    missing = [f for f in PZ_PARAMETERS if f not in given]
    if law != "none" and missing:
        raise InputError(f"{', '.join(missing)}: missing; pz_law {law} needs pz_v0 [m/s] and "
                         "pz_xi, each fixed or fitted")


def calibration_from_dict(data, base=".", source="<dict>", measurements=None) -> Calibration:
    """Validate a calibration mapping (the YAML file's content).

    Parameters
    ----------
    data : dict
    base : path
        Folder the ``data`` CSV path is relative to.
    source : str
        The file's name: every error starts with it and a colon (as a sweep config's do).
    measurements : tuple, optional
        ``(speed_m_s, pull_off_N, sigma_N or None)`` instead of reading ``data``.

    Raises
    ------
    InputError
        One line, ``<source>: <the problem>``.
    """
    try:
        return _calibration_from_dict(data, base, source, measurements)
    except InputError as exc:
        raise InputError(f"{source}: {exc}" if source else str(exc)) from None


def _material(value) -> str:
    """The calibration's material: mpl or sls (a Prony table's moduli are not SI fields)."""
    if isinstance(value, dict) and "prony" in value:
        raise InputError(f"material: a Prony table is not supported in a calibration file "
                         f"(got {value!r}); material must be mpl or sls, its constants E0, "
                         "Einf, n, tau0 fixed or fitted")
    return check_choice("material", value, ("mpl", "sls"))


def _calibration_from_dict(data, base, source, measurements) -> Calibration:
    if not isinstance(data, dict):
        raise InputError("must be a mapping with keys name, data, fixed, fit, ...")
    for key in data:
        if key not in TOP_KEYS:
            raise InputError(f"{key}: unknown key (allowed: {', '.join(TOP_KEYS)})")
    # the material first: a table given instead of the MPL/SLS constants is the problem,
    # not the constants it leaves missing
    material = _material(data.get("material", "mpl"))
    name = data.get("name")
    if not isinstance(name, str) or not name.strip():
        raise InputError("name: required, a short name such as pdms-lens")
    fixed_in = data.get("fixed") or {}
    fit_in = data.get("fit")
    if not isinstance(fixed_in, dict):
        raise InputError(f"fixed must be a mapping of SI fields to values (got {fixed_in!r})")
    if not isinstance(fit_in, dict) or not fit_in:
        raise InputError("fit: required, a mapping of SI fields to bounds [lo, hi] (at least "
                         "one free parameter)")
    fixed = {}
    for key, v in fixed_in.items():
        if key == "speed":
            raise InputError("fixed.speed: the speeds are the data's speed_m_s column")
        if key == LAW_FIELD:
            fixed[key] = check_choice(f"fixed.{key}", v, PZ_LAWS)
            continue
        if key not in FIT_FIELDS:
            raise InputError(f"fixed.{key}: unknown SI field (allowed: "
                             f"{', '.join(FIT_FIELDS)}, pz_law)")
        lo, hi, lo_open = _limits(key)
        fixed[key] = check_range(f"fixed.{key}", v, lo, hi, lo_open=lo_open)
    params = []
    for key, spec in fit_in.items():
        if key == "speed":
            raise InputError("fit.speed: the speeds are the data's speed_m_s column")
        if key == LAW_FIELD:
            raise InputError(f"fit.{key}: a law is chosen, not fitted; give it in fixed "
                             f"({', '.join(PZ_LAWS)})")
        if key not in FIT_FIELDS:
            raise InputError(f"fit.{key}: unknown SI field (allowed: {', '.join(FIT_FIELDS)})")
        if key in fixed:
            raise InputError(f"{key}: both fixed and fitted; give it in one of fixed and fit")
        params.append(_bounds(key, spec, _limits(key)))
    given = set(fixed) | {p.name for p in params}
    _check_process_zone(fixed.get(LAW_FIELD, "none"), given)
    missing = [f for f in FIT_FIELDS if f not in (*INITIAL_FIELDS, *PZ_PARAMETERS)
               and f not in given]
    if missing:
        raise InputError(f"{', '.join(missing)}: missing; every SI field must be fixed or "
                         "fitted")
    init = [f for f in INITIAL_FIELDS if f in given]
    if len(init) != 1:
        raise InputError(f"preload/a0/indentation: give exactly one initial state (got "
                         f"{', '.join(init) or 'none'})")
    by = {p.name: p for p in params}
    if "E0" in fixed and "Einf" in by and by["Einf"].lo < fixed["E0"]:
        raise InputError(f"fit.Einf: lower bound must be >= E0 = {fixed['E0']:.6g} Pa (got "
                         f"{by['Einf'].lo:.6g})")
    if "Einf" in fixed and "E0" in by and by["E0"].hi > fixed["Einf"]:
        raise InputError(f"fit.E0: upper bound must be <= Einf = {fixed['Einf']:.6g} Pa (got "
                         f"{by['E0'].hi:.6g})")
    model = check_choice("model", data.get("model", "auto"), CAL_MODELS)
    num = data.get("numerics", {"preset": "fast"})
    if not isinstance(num, dict):
        raise InputError(f"numerics must be a mapping such as {{preset: fast}} (got {num!r})")
    try:
        numerics = Numerics.from_dict(num)
    except InputError as exc:
        msg = str(exc)
        raise InputError(msg if msg.startswith("numerics") else f"numerics.{msg}") from None
    search = data.get("search") or {}
    profile = data.get("profile") or {}
    for key, d, allowed in (("search", search, ("points", "starts", "seed")),
                            ("profile", profile, ("points", "level"))):
        if not isinstance(d, dict):
            raise InputError(f"{key} must be a mapping (keys {', '.join(allowed)})")
        for k in d:
            if k not in allowed:
                raise InputError(f"{key}.{k}: unknown key (allowed: {', '.join(allowed)})")
    kw = dict(
        search_points=check_int("search.points", search.get("points", 64), 0, 100000),
        search_starts=check_int("search.starts", search.get("starts", 3), 1, 100),
        seed=check_int("search.seed", search.get("seed", 0), 0, 2**32 - 1),
        profile_points=check_int("profile.points", profile.get("points", 12), 3, 1000),
        level=check_range("profile.level", profile.get("level", 0.95), 0.5, 0.9999),
        diff_step=check_range("diff_step", data.get("diff_step",
                                                    1e-3 if model in ("crack", "pb") else 1e-2),
                              1e-8, 0.2))
    points = {}
    for key in ("start", "truth"):
        d = data.get(key)
        if d is None:
            points[key] = None
            continue
        if not isinstance(d, dict):
            raise InputError(f"{key} must be a mapping of the fitted fields to values")
        for k, v in d.items():
            if k not in by:
                raise InputError(f"{key}.{k}: not a fitted field (fitted: "
                                 f"{', '.join(by)})")
            if key == "start":
                check_range(f"start.{k}", v, by[k].lo, by[k].hi)
            else:
                lo, hi, lo_open = _limits(k)
                check_range(f"truth.{k}", v, lo, hi, lo_open=lo_open)
        points[key] = {k: float(v) for k, v in d.items()}
    if measurements is None:
        if not isinstance(data.get("data"), str):
            raise InputError("data: required, the path of a CSV with columns speed_m_s, "
                             "pull_off_N[, sigma_N] (relative to the YAML file)")
        dpath = Path(base) / data["data"]
        speed, po, sigma = _read_data(dpath)
        dsrc = str(dpath)
    else:
        speed, po, sigma = (None if a is None else np.asarray(a, dtype=float)
                            for a in measurements)
        dsrc = "<measurements>"
    if len(po) < len(params):
        raise InputError(f"data: {len(po)} points for {len(params)} free parameters; give at "
                         "least as many points as free parameters")
    if sigma is None and len(po) <= len(params):
        raise InputError(f"data: {len(po)} points for {len(params)} free parameters; without "
                         "sigma_N the noise is estimated from the residuals and needs more "
                         "points than free parameters")
    cal = Calibration(name=name.strip(), speed_m_s=np.asarray(speed, dtype=float),
                      pull_off_N=np.asarray(po, dtype=float), sigma_N=sigma, fixed=fixed,
                      params=tuple(params), model=model, numerics=numerics, material=material,
                      start=points["start"], truth=points["truth"], source=source,
                      data_source=dsrc, **kw)
    # the whole box must be made of valid scenes where one field's bound meets another's
    try:
        SIScene(**cal.values([0.5] * len(params)), speed=float(cal.speed_m_s[0]),
                material=material)
    except InputError as exc:
        raise InputError(f"the scene at the centre of the bounds is invalid: {exc}") from None
    return cal


# ----------------------------------------------------------------------------- scenes
_WORKER_READY = False


def _prepare_worker() -> None:
    """Once per worker process: end with the parent, one BLAS/OpenMP/Numba thread
    (sweep.threads)."""
    global _WORKER_READY
    if not _WORKER_READY:
        exit_with_parent()
        limit_env(THREAD_VARS)
        limit_loaded_pools()
        _WORKER_READY = True


def run_scene_si(fields: dict, model: str, numerics) -> tuple:
    """One SI scene -> ``(pull_off_N or nan, model_used, status, reason)``; never raises."""
    try:
        r = run_si(SIScene(**fields), model, numerics)
        po = r.get("pull_off_N")
        ok = r.get("status") == "ok" and po is not None and math.isfinite(po) and po > 0
        return (float(po) if ok else math.nan, r.get("model", model),
                "ok" if ok else "failed", _one_line(r.get("reason") or ""))
    except Exception as exc:  # a failing scene is a penalty residual, not a stopped fit
        return math.nan, model, "failed", _one_line(f"{type(exc).__name__}: {exc}")


def _run_batch(items, model, numerics, in_worker=True) -> list:
    if in_worker:
        _prepare_worker()
    return [(key, run_scene_si(fields, model, numerics)) for key, fields in items]


def _material_key(fields: dict) -> tuple:
    """Scenes with the same (n, E0, Einf, material) share the crack-front model's
    Persson-Brener table (cached per process, about 0.4 s to build), so they go together."""
    return tuple(fields.get(k) for k in ("n", "E0", "Einf", "material"))


def _chunks(items, jobs: int) -> list:
    """``items`` [(key, fields)] in about ``4 jobs`` chunks of whole material groups,
    the largest groups first, each to the chunk with the fewest scenes so far."""
    groups: dict = {}
    for item in items:
        groups.setdefault(_material_key(item[1]), []).append(item)
    n_chunks = max(1, min(len(groups), 4 * jobs))
    chunks = [[] for _ in range(n_chunks)]
    for g in sorted(groups.values(), key=len, reverse=True):
        min(chunks, key=len).extend(g)
    chunks.sort(key=len, reverse=True)
    return [c for c in chunks if c]


class SceneEvaluator:
    """Pull-off [N] of parameter sets at speeds, with a cache of every scene run.

    Parameters
    ----------
    cal : Calibration
    jobs : int, optional
        Worker processes (default: all cores); 1 runs in this process.
    """

    def __init__(self, cal: Calibration, jobs: int | None = None):
        self.cal = cal
        self.jobs = max(1, int(jobs or os.cpu_count() or 1))
        self.cache: dict = {}
        self.scenes_run = 0
        self.cache_hits = 0
        self.failed = 0
        self.models = Counter()
        self.reasons = Counter()
        self._num_key = tuple(sorted((k, repr(v)) for k, v in cal.numerics.to_dict().items()))

    def key(self, fields: dict) -> tuple:
        vals = tuple((k, v if isinstance(v, str) else float(f"{v:.{KEY_DIGITS}g}"))
                     for k, v in sorted(fields.items()))
        return (self.cal.model, self.cal.material, self._num_key, vals)

    def predict(self, U, speeds=None) -> np.ndarray:
        """Pull-off [N] (NaN where a scene failed) of each row of unit coordinates ``U``
        (shape (m, p)) at ``speeds`` [m/s] (default: the data's distinct speeds): (m, s)."""
        U = np.atleast_2d(np.asarray(U, dtype=float))
        speeds = self.speeds if speeds is None else np.asarray(speeds, dtype=float)
        keys = np.empty((len(U), len(speeds)), dtype=object)
        todo = {}
        for i, u in enumerate(U):
            base = self.cal.values(u)
            for j, s in enumerate(speeds):
                fields = {**base, "speed": float(s)}
                k = self.key(fields)
                keys[i, j] = k
                if k in self.cache:
                    self.cache_hits += 1
                elif k not in todo:
                    # the rounded values run, so that a cached value is exactly the key's
                    todo[k] = {name: v for name, v in k[3]}
                else:
                    self.cache_hits += 1
        if todo:
            self._run(list(todo.items()))
        out = np.empty(keys.shape)
        for idx, k in np.ndenumerate(keys):
            out[idx] = self.cache[k][0]
        return out

    @property
    def speeds(self) -> np.ndarray:
        return np.unique(self.cal.speed_m_s)

    def _run(self, items) -> None:
        cal = self.cal
        for f in items:
            f[1]["material"] = cal.material
        if self.jobs == 1 or len(items) < 2:
            limits = limit_loaded_pools()
            try:
                results = _run_batch(items, cal.model, cal.numerics, in_worker=False)
            finally:
                if limits is not None:
                    limits.restore_original_limits()
        else:
            chunks = _chunks(items, self.jobs)
            n = min(self.jobs, len(chunks))
            with parallel_config(backend="loky", inner_max_num_threads=1):
                parts = Parallel(n_jobs=n, batch_size=1)(
                    delayed(_run_batch)(c, cal.model, cal.numerics) for c in chunks)
            results = [r for part in parts for r in part]
        for k, res in results:
            self.cache[k] = res
            self.scenes_run += 1
            self.models[res[1]] += 1
            if res[2] != "ok":
                self.failed += 1
                self.reasons[res[3][:120]] += 1


# ----------------------------------------------------------------------------- the fit
class _Objective:
    """Residuals of unit coordinates, with batched forward-difference Jacobians."""

    def __init__(self, cal: Calibration, ev: SceneEvaluator):
        self.cal, self.ev = cal, ev
        self.speeds = ev.speeds
        self.row = np.searchsorted(self.speeds, cal.speed_m_s)
        self.data = cal.pull_off_N
        self.sigma = cal.sigma_N
        self.evaluations = 0
        # stop a local fit when a step changes the profile statistic D by < ~0.02: with
        # D = dSSR dof/SSR (or dSSR with sigmas, SSR ~ dof), a relative change of the cost
        # below 0.02/dof
        self.ftol = float(np.clip(0.02 / max(len(cal.pull_off_N) - len(cal.params), 1),
                                  1e-6, 1e-2))

    def residuals_of(self, pred_rows: np.ndarray) -> np.ndarray:
        """Residuals of predictions at the data's distinct speeds (shape (..., s))."""
        p = pred_rows[..., self.row]
        bad = ~np.isfinite(p)
        if self.sigma is None:
            with np.errstate(invalid="ignore", divide="ignore"):
                r = np.log(p) - np.log(self.data)
            return np.where(bad, FAILED_RESIDUAL, r)
        r = (p - self.data) / self.sigma
        return np.where(bad, FAILED_RESIDUAL * self.data / self.sigma, r)

    def residuals(self, U) -> np.ndarray:
        U = np.atleast_2d(U)
        self.evaluations += len(U)
        return self.residuals_of(self.ev.predict(U))

    def ssr(self, U) -> np.ndarray:
        return np.sum(self.residuals(U) ** 2, axis=-1)

    def jacobian(self, u, free) -> np.ndarray:
        """d r / d u[free] by forward differences (backward at the upper bound), one batch."""
        h = self.cal.diff_step
        pts = [np.array(u, dtype=float)]
        steps = []
        for j in free:
            q = np.array(u, dtype=float)
            step = h if q[j] + h <= 1.0 else -h
            q[j] += step
            pts.append(q)
            steps.append(step)
        R = self.residuals(np.array(pts))
        return ((R[1:] - R[0]) / np.array(steps)[:, None]).T

    def fit(self, u0, free=None, max_nfev=60):
        """Bounded least squares over ``u[free]`` (default all) from ``u0``; returns (u, ssr)."""
        u0 = np.clip(np.asarray(u0, dtype=float), 0.0, 1.0)
        free = list(range(len(u0))) if free is None else list(free)
        if not free:
            return u0, float(self.ssr(u0)[0])

        def full(x):
            u = u0.copy()
            u[free] = x
            return u

        res = least_squares(lambda x: self.residuals(full(x))[0],
                            u0[free], jac=lambda x: self.jacobian(full(x), free),
                            bounds=(0.0, 1.0), method="trf", x_scale=1.0, max_nfev=max_nfev,
                            ftol=self.ftol, xtol=1e-3, gtol=1e-8)
        u = full(np.clip(res.x, 0.0, 1.0))
        return u, float(self.ssr(u)[0])


def _threshold(cal: Calibration, dof: int) -> tuple:
    if cal.sigma_N is not None:
        return float(stats.chi2.ppf(cal.level, 1)), "chi2(1)"
    return float(stats.f.ppf(cal.level, 1, dof)), f"F(1, {dof})"


def _profile(obj: _Objective, cal, j, u_best, ssr_best, scale, thr, say) -> dict:
    """Profile of parameter ``j``: walk out from the estimate on a grid over its bounds."""
    p = len(u_best)
    free = [i for i in range(p) if i != j]
    grid = np.linspace(0.0, 1.0, cal.profile_points)
    pts = {float(u_best[j]): (u_best.copy(), ssr_best)}

    def at(uj, warm):
        u0 = warm.copy()
        u0[j] = uj
        u, s = obj.fit(u0, free, max_nfev=30)
        pts[float(uj)] = (u, s)
        return u, s

    ends, open_side = {}, {}
    for side in (+1, -1):
        seq = grid[grid > u_best[j] + 1e-9] if side > 0 else grid[grid < u_best[j] - 1e-9][::-1]
        prev_u, prev_s, warm = float(u_best[j]), ssr_best, u_best
        crossed = False
        for uj in seq:
            warm, s = at(float(uj), warm)
            d_prev = max(prev_s - ssr_best, 0.0) / scale
            d = max(s - ssr_best, 0.0) / scale
            if d > thr:
                # regula falsi on sqrt(D) (linear in u for a quadratic profile), one step
                ga, gb = math.sqrt(d_prev) - math.sqrt(thr), math.sqrt(d) - math.sqrt(thr)
                uc = prev_u + (uj - prev_u) * (-ga) / (gb - ga)
                _, sc = at(uc, warm)
                gc = math.sqrt(max(sc - ssr_best, 0.0) / scale) - math.sqrt(thr)
                if gc > 0:
                    ue = prev_u + (uc - prev_u) * (-ga) / (gc - ga)
                else:
                    ue = uc + (uj - uc) * (-gc) / (gb - gc)
                ends[side] = ue
                crossed = True
                break
            prev_u, prev_s = float(uj), s
        if not crossed:
            ends[side] = 1.0 if side > 0 else 0.0
        open_side[side] = not crossed
        say(f"  profile {cal.params[j].name}: {'upper' if side > 0 else 'lower'} side "
            f"{'open (bound reached)' if not crossed else 'closed'}, "
            f"{obj.ev.scenes_run} scenes so far")
    us = sorted(pts)
    return {"u": us, "ssr": [pts[x][1] for x in us], "U": [pts[x][0] for x in us],
            "ends": (ends[-1], ends[+1]), "open": (open_side[-1], open_side[+1])}


def _status(open_lo: bool, open_hi: bool) -> str:
    if open_lo and open_hi:
        return "not identifiable"
    if open_lo:
        return "upper limit only"
    if open_hi:
        return "lower limit only"
    return "identifiable"


def calibrate(cal: Calibration, jobs: int | None = None,
              progress: Callable[[str], None] | None = None, profiles: bool = True,
              curve_points: int = 25) -> dict:
    """Fit ``cal``'s free parameters to its data; intervals, flags, correlations, band.

    Parameters
    ----------
    cal : Calibration
    jobs : int, optional
        Worker processes for the scenes of a batch (default: all cores; 1: this process).
    progress : callable, optional
        Gets one line of text per stage (the CLI prints them on stderr).
    profiles : bool
        False: the estimate and the correlation matrix only (no intervals, no band).
    curve_points : int
        Speeds of the fitted curve and band (log-spaced over the data's range, widened by
        a factor 2 at each end).

    Returns
    -------
    dict
        ``parameters`` {name: estimate, interval [SI], identifiable, status, bounds, scale,
        truth}, ``correlation``, ``fit`` (ssr, chi2 or rms_log_residual, dof, threshold),
        ``profiles``, ``curve`` (speed_m_s, pull_off_N, band_lo_N, band_hi_N), ``data``,
        ``recentred`` (each move of the estimate to a lower minimum a profile found: the
        profile, the SSR and estimate before and after), ``warnings`` (text),
        ``scenes_run``, ``cache_hits``, ``failed_scenes``, ``models_used``, ``wall_s``.
        See the module docstring for the method.
    """
    t0 = time.perf_counter()
    say = progress or (lambda s: None)

    def log(msg):
        say(f"[{time.perf_counter() - t0:7.1f} s] {msg}")

    ev = SceneEvaluator(cal, jobs)
    obj = _Objective(cal, ev)
    p, N = len(cal.params), len(cal.pull_off_N)
    if cal.model in ("bem", "auto"):
        bem.warm_up()
    log(f"calibrate {cal.name}: {p} free parameters ({', '.join(cal.names)}), {N} points at "
        f"{len(ev.speeds)} speeds, model {cal.model}, {ev.jobs} job(s)")
    # 1. coarse global search
    starts = []
    if cal.search_points > 0:
        sob = qmc.Sobol(d=p, scramble=True, seed=cal.seed)
        m = int(round(math.log2(cal.search_points)))
        U = sob.random_base2(m) if 2**m == cal.search_points else sob.random(cal.search_points)
        S = obj.ssr(U)
        order = np.argsort(S)
        starts = [U[i] for i in order[:cal.search_starts]]
        log(f"search: {len(U)} Sobol points, best SSR {S[order[0]]:.4g}, "
            f"{ev.scenes_run} scenes")
    if cal.start is not None:
        u0 = np.array([0.5] * p)
        for i, prm in enumerate(cal.params):
            if prm.name in cal.start:
                u0[i] = float(prm.unit(cal.start[prm.name]))
        starts.insert(0, u0)
    if not starts:
        starts = [np.full(p, 0.5)]
    fits = []
    for k, u0 in enumerate(starts):
        s0 = float(obj.ssr(u0)[0])
        u, s = obj.fit(u0)
        fits.append({"start": cal.values(u0), "end": cal.values(u), "ssr_start": s0,
                     "ssr": s, "_u": u})
        log(f"local fit {k + 1}/{len(starts)}: SSR {s0:.4g} -> {s:.4g}, "
            f"{ev.scenes_run} scenes")
    best = min(fits, key=lambda f: f["ssr"])
    u_best, ssr_best = best["_u"], best["ssr"]
    dof = N - p
    scale = 1.0 if cal.sigma_N is not None else max(ssr_best / max(dof, 1), 1e-300)
    thr, stat = _threshold(cal, max(dof, 1))

    # 2. profiles, about the estimate: every profile, interval and status is about u_best
    prof = {}
    recentred, warnings = [], []
    while profiles:
        prof = {j: _profile(obj, cal, j, u_best, ssr_best, scale, thr, log) for j in range(p)}
        # a profile may find a lower minimum than the local fits (they end at a local one):
        # fit again from there and redo the profiles about the new estimate
        j_low = min(prof, key=lambda j: min(prof[j]["ssr"]))
        i_low = int(np.argmin(prof[j_low]["ssr"]))
        s_low, u_low = prof[j_low]["ssr"][i_low], prof[j_low]["U"][i_low]
        drop = (ssr_best - s_low) / scale
        if not drop > RECENTRE_D:
            break
        name = cal.params[j_low].name
        at = {cal.params[i].name: float(cal.params[i].value(u_low[i])) for i in range(p)}
        if len(recentred) >= MAX_RECENTRES:
            warnings.append(
                f"after {len(recentred)} re-centrings the profile of {name} still found a "
                f"lower minimum, SSR {s_low:.4g} against the estimate's {ssr_best:.4g} "
                f"(D {drop:.3g} below), at "
                f"{', '.join(f'{k} = {v:.4g}' for k, v in at.items())}: the estimates, "
                "intervals and statuses are about the estimate, not that point; more "
                "search starts, or `start:` there, may settle it")
            log(f"warning: {warnings[-1]}")
            break
        u_new, s_new = obj.fit(u_low)
        if not s_new <= s_low:
            u_new, s_new = u_low, s_low
        recentred.append({"profile": name, "ssr_from": ssr_best, "ssr_profile": s_low,
                          "ssr": s_new, "estimate_from": {
                              prm.name: float(prm.value(u_best[i]))
                              for i, prm in enumerate(cal.params)},
                          "estimate": {prm.name: float(prm.value(u_new[i]))
                                       for i, prm in enumerate(cal.params)}})
        log(f"the profile of {name} found a lower minimum (SSR {ssr_best:.4g} -> "
            f"{s_low:.4g}, refitted {s_new:.4g}): the profiles again about it")
        u_best, ssr_best = u_new, s_new
        scale = 1.0 if cal.sigma_N is not None else max(ssr_best / max(dof, 1), 1e-300)

    # 3. correlation (linearized at the estimate)
    J = obj.jacobian(u_best, list(range(p)))
    cov = np.linalg.pinv(J.T @ J) * (scale if cal.sigma_N is None else 1.0)
    sd = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(sd, sd)
    corr = np.where(np.isfinite(corr), corr, np.nan)

    # 4. parameters, intervals
    params = {}
    for j, prm in enumerate(cal.params):
        d = {"estimate": float(prm.value(u_best[j])), "bounds": [prm.lo, prm.hi],
             "scale": "log" if prm.log else "linear"}
        if j in prof:
            pr = prof[j]
            lo_u, hi_u = pr["ends"]
            # a point below the estimate by less than RECENTRE_D reads as D = 0
            D = np.maximum(np.array(pr["ssr"]) - ssr_best, 0.0) / scale
            d.update(interval=[float(prm.value(lo_u)), float(prm.value(hi_u))],
                     identifiable=not (pr["open"][0] or pr["open"][1]),
                     status=_status(*pr["open"]))
            pr["D"] = D
        if cal.truth and prm.name in cal.truth:
            d["truth"] = cal.truth[prm.name]
            if "interval" in d:
                d["truth_in_interval"] = bool(d["interval"][0] <= d["truth"]
                                              <= d["interval"][1])
        params[prm.name] = d

    # 5. curve and band
    lo_s, hi_s = float(np.min(cal.speed_m_s)) / 2.0, float(np.max(cal.speed_m_s)) * 2.0
    speeds = np.logspace(math.log10(lo_s), math.log10(hi_s), int(curve_points))
    sets = [u_best]
    for j, pr in prof.items():
        sets += [U for U, D in zip(pr["U"], pr["D"]) if D <= thr * (1 + 1e-9)]
    if len(sets) > 41:
        keep = np.unique(np.linspace(1, len(sets) - 1, 40).round().astype(int))
        sets = [sets[0]] + [sets[i] for i in keep]
    log(f"curve and band: {len(sets)} parameter sets x {len(speeds)} speeds")
    C = ev.predict(np.array(sets), speeds)
    fitted_rows = ev.predict(u_best[None, :])[0][obj.row]
    r = obj.residuals(u_best)[0]
    fit = {"ssr": ssr_best, "dof": dof, "points": N, "free": p, "level": cal.level,
           "statistic": stat, "threshold": thr,
           "residuals": "log" if cal.sigma_N is None else "sigma"}
    with np.errstate(invalid="ignore", divide="ignore"):
        fit["rms_log_residual"] = float(np.sqrt(np.nanmean(
            (np.log(fitted_rows) - np.log(cal.pull_off_N)) ** 2)))
    if cal.sigma_N is not None:
        fit["chi2"] = float(np.sum(r**2))
        fit["chi2_per_dof"] = float(np.sum(r**2) / dof) if dof > 0 else None
    else:
        fit["noise_log_sd"] = float(math.sqrt(scale)) if dof > 0 else None
    with np.errstate(all="ignore"):
        band_lo = np.nanmin(C, axis=0) if len(sets) > 1 else C[0]
        band_hi = np.nanmax(C, axis=0) if len(sets) > 1 else C[0]
    out = {
        "name": cal.name, "source": cal.source, "model": cal.model,
        "numerics": cal.numerics.to_dict(), "material": cal.material, "fixed": cal.fixed,
        "parameters": params,
        "correlation": {"names": cal.names, "matrix": corr.tolist(),
                        "coordinates": "log for log-scaled parameters, else linear; "
                                       "linearized at the estimate"},
        "fit": fit,
        "search": {"points": cal.search_points, "seed": cal.seed,
                   "local_fits": [{k: v for k, v in f.items() if k != "_u"} for f in fits]},
        "profiles": {cal.params[j].name: {
            "values": [float(cal.params[j].value(x)) for x in pr["u"]],
            "statistic": [float(x) for x in pr["D"]]} for j, pr in prof.items()},
        "data": {"file": cal.data_source, "speed_m_s": cal.speed_m_s.tolist(),
                 "pull_off_N": cal.pull_off_N.tolist(),
                 "sigma_N": None if cal.sigma_N is None else cal.sigma_N.tolist(),
                 "fitted_N": fitted_rows.tolist()},
        "curve": {"speed_m_s": speeds.tolist(), "pull_off_N": C[0].tolist(),
                  "band_lo_N": np.asarray(band_lo).tolist(),
                  "band_hi_N": np.asarray(band_hi).tolist(),
                  "band": "envelope of the parameter sets on the profiles below the "
                          "threshold" if prof else "none (no profiles)"},
        "recentred": recentred, "warnings": warnings,
        "scenes_run": ev.scenes_run, "cache_hits": ev.cache_hits,
        "failed_scenes": ev.failed, "failure_reasons": dict(ev.reasons.most_common(5)),
        "models_used": dict(ev.models), "jobs": ev.jobs,
        "wall_s": time.perf_counter() - t0,
    }
    log(f"done: {ev.scenes_run} scenes run ({ev.cache_hits} cache hits, {ev.failed} failed) "
        f"in {out['wall_s']:.1f} s")
    return out


# ----------------------------------------------------------------------------- output
def to_json(result: dict, indent: int | None = 1) -> str:
    """``result`` as JSON text (NaN and inf as null)."""
    return json.dumps(to_jsonable(result), indent=indent)


def summary_lines(result: dict) -> list:
    """A short table of the estimates, intervals and flags, and the fit's numbers."""
    lines = [f"{'parameter':<12}{'estimate':>12}{'95% interval':>28}  status"]
    for name, d in result["parameters"].items():
        iv = d.get("interval")
        ivs = f"[{iv[0]:.4g}, {iv[1]:.4g}]" if iv else "-"
        tr = f"  (truth {d['truth']:.4g})" if "truth" in d else ""
        lines.append(f"{name:<12}{d['estimate']:>12.4g}{ivs:>28}  {d.get('status', '-')}{tr}")
    f = result["fit"]
    q = (f"chi2 {f['chi2']:.4g} for {f['dof']} dof" if "chi2" in f
         else f"RMS log residual {f['rms_log_residual']:.4g}")
    lines.append(f"{q}; {result['scenes_run']} scenes run ({result['failed_scenes']} failed, "
                 f"models {result['models_used']}) in {result['wall_s']:.1f} s")
    for m in result.get("recentred", []):
        lines.append(f"note: the profile of {m['profile']} found a lower minimum (SSR "
                     f"{m['ssr_from']:.4g} -> {m['ssr']:.4g}); the estimate moved there and "
                     "the profiles were redone about it")
    lines += [f"warning: {w}" for w in result.get("warnings", [])]
    return lines


def write_outputs(result: dict, out_dir) -> list:
    """Write ``calibration.json``, ``fit.png`` (data, fitted curve, band; log axes) and
    ``profile_<name>.png`` per parameter into ``out_dir``; returns the paths."""
    out = Path(out_dir)
    with writing("out", out, "create"):
        out.mkdir(parents=True, exist_ok=True)
    paths = [out / "calibration.json"]
    with writing("out", paths[0]):
        paths[0].write_text(to_json(result) + "\n")
    plt = pyplot()
    d, c = result["data"], result["curve"]
    fig, ax = plt.subplots(figsize=(6.0, 4.5))
    ax.fill_between(c["speed_m_s"], np.array(c["band_lo_N"], float) * 1e3,
                    np.array(c["band_hi_N"], float) * 1e3, color="C0", alpha=0.25, lw=0,
                    label=f"{100 * result['fit']['level']:.0f}% profile band")
    ax.plot(c["speed_m_s"], np.array(c["pull_off_N"], float) * 1e3, "C0-", label="fit")
    y = np.array(d["pull_off_N"]) * 1e3
    if d.get("sigma_N") is not None:
        ax.errorbar(d["speed_m_s"], y, yerr=np.array(d["sigma_N"]) * 1e3, fmt="ko", ms=4,
                    label="data")
    else:
        ax.plot(d["speed_m_s"], y, "ko", ms=4, label="data")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("unloading speed [m/s]")
    ax.set_ylabel("pull-off force [mN]")
    est = ", ".join(f"{k} = {v['estimate']:.3g}" for k, v in result["parameters"].items())
    ax.set_title(f"{result['name']} ({result['model']}): {est}", fontsize=8)
    ax.legend(fontsize=8)
    fig.tight_layout()
    paths.append(save_figure(fig, out / "fit.png"))
    thr = result["fit"]["threshold"]
    for name, pr in result["profiles"].items():
        prm = result["parameters"][name]
        fig, ax = plt.subplots(figsize=(5.0, 3.6))
        ax.plot(pr["values"], pr["statistic"], "C0o-", ms=3)
        ax.axhline(thr, color="C3", ls="--", lw=1,
                   label=f"threshold {thr:.3g} ({result['fit']['statistic']})")
        for x in prm["interval"]:
            ax.axvline(x, color="C3", lw=0.8, ls=":")
        ax.axvline(prm["estimate"], color="C0", lw=0.8)
        if "truth" in prm:
            ax.axvline(prm["truth"], color="k", lw=1, ls="-.", label="truth")
        if prm["scale"] == "log":
            ax.set_xscale("log")
        ax.set_xlim(*prm["bounds"])
        ax.set_ylim(0.0, max(3.0 * thr, min(max(pr["statistic"] or [0.0]), 10 * thr) * 1.05))
        ax.set_xlabel(name)
        ax.set_ylabel("profile statistic D")
        ax.set_title(f"{name}: {prm['status']}", fontsize=9)
        ax.legend(fontsize=7)
        fig.tight_layout()
        paths.append(save_figure(fig, out / f"profile_{name}.png", dpi=110))
    return paths


# ----------------------------------------------------------------------------- synthetic
def synthesize(cal: Calibration, truth: dict, speeds, repeats: int = 1, noise: float = 0.05,
               seed: int = 0, sigma: bool = False) -> dict:
    """Synthetic measurements of ``cal``'s model at the parameters ``truth`` (SI).

    Each speed [m/s] is tested ``repeats`` times; the pull-off [N] is multiplied by
    ``exp(N(0, noise))``. Returns ``{"speed_m_s", "pull_off_N"[, "sigma_N" = noise P]}``.
    """
    missing = [p.name for p in cal.params if p.name not in truth]
    if missing:
        raise InputError(f"truth: missing {', '.join(missing)} (every fitted field)")
    fields = {**cal.fixed, **{k: float(v) for k, v in truth.items()}}
    speeds = np.repeat(np.asarray(speeds, dtype=float), int(repeats))
    clean = np.empty(len(speeds))
    for i, s in enumerate(speeds):
        po, _, status, reason = run_scene_si({**fields, "speed": float(s),
                                              "material": cal.material},
                                             cal.model, cal.numerics)
        if status != "ok":
            raise InputError(f"truth: the scene at speed {s:.6g} m/s failed ({reason})")
        clean[i] = po
    rng = np.random.default_rng(seed)
    out = {"speed_m_s": speeds, "pull_off_N": clean * np.exp(rng.normal(0.0, noise,
                                                                         len(speeds)))}
    if sigma:
        out["sigma_N"] = noise * clean
    return out


def _synth_main(args) -> int:
    data = _read_yaml(Path(args.config))
    if not isinstance(data, dict) or not isinstance(data.get("data"), str):
        raise InputError(f"{args.config}: data: required, the path of the CSV to write")
    n_free = len(data.get("fit") or {}) + 1
    cal = calibration_from_dict(data, source=args.config,      # the CSV is not read
                                measurements=([1.0] * n_free, [1.0] * n_free, None))
    if not cal.truth:
        raise InputError(f"{args.config}: a `truth` mapping (the parameters to simulate) is "
                         "needed to synthesize data")
    lo, hi, num = (float(x) for x in args.speeds.split(","))
    speeds = np.logspace(math.log10(lo), math.log10(hi), int(num))
    d = synthesize(cal, cal.truth, speeds, args.repeats, args.noise, args.seed, args.sigma)
    path = Path(args.out) if args.out else Path(args.config).parent / data["data"]
    cols = [k for k in ("speed_m_s", "pull_off_N", "sigma_N") if k in d]
    lines = [f"# synthetic: python -m sweep.analysis.calibrate synth {args.config} "
             f"--speeds {args.speeds} --repeats {args.repeats} --noise {args.noise} "
             f"--seed {args.seed}{' --sigma' if args.sigma else ''}",
             f"# truth: {', '.join(f'{k}={v:g}' for k, v in cal.truth.items())}; model "
             f"{cal.model}; log-normal noise sd {args.noise}", ",".join(cols)]
    for i in range(len(d["speed_m_s"])):
        lines.append(",".join(f"{d[c][i]:.8g}" for c in cols))
    path.write_text("\n".join(lines) + "\n")
    print(f"{path}: {len(d['speed_m_s'])} rows")
    return 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m sweep.analysis.calibrate")
    sub = ap.add_subparsers(dest="cmd", required=True)
    s = sub.add_parser("synth", help="write synthetic data of a calibration file's truth")
    s.add_argument("config")
    s.add_argument("--speeds", required=True, help="LO,HI,N: N log-spaced speeds [m/s]")
    s.add_argument("--repeats", type=int, default=1)
    s.add_argument("--noise", type=float, default=0.05, help="log-normal noise sd")
    s.add_argument("--seed", type=int, default=0)
    s.add_argument("--sigma", action="store_true", help="write a sigma_N column")
    s.add_argument("--out", default=None, help="CSV path (default: the file's data)")
    args = ap.parse_args(argv)
    try:
        return _synth_main(args)
    except InputError as exc:
        print(f"error: {_one_line(exc)}", file=sys.stderr)
        return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())

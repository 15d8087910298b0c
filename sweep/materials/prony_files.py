r"""Prony tables from what a lab has: :func:`read_prony` and the :class:`PronyTable` it returns.

A lab characterizes a material by DMA and keeps a Prony (generalized Maxwell) table, written by
a fitting tool. :func:`read_prony` reads one from a file or an inline mapping, checks it, and
returns a :class:`PronyTable`: the :class:`~sweep.materials.Prony` material, its relaxed and
instantaneous moduli, where it came from, and a hash of its numbers
(:meth:`PronyTable.content_hash`).

Conventions (those of :mod:`sweep.materials`)
---------------------------------------------
``E0`` is the RELAXED (long-time) modulus and ``Einf`` the INSTANTANEOUS (glassy) one.
pyvisco and ANSYS call the instantaneous modulus ``E_0``: their ``E_0`` is ``Einf`` here.

* Wiechert (generalized Maxwell, relaxation) form:
  ``R(t) = E0 + sum_i E_i exp(-t/tau_i)``, ``Einf = E0 + sum_i E_i``; ``tau_i`` relaxation times.
* Kelvin (retardation) form: ``C(t) = [1 - sum_i c_i exp(-t/tau_i)] / E0``,
  ``Einf = E0 / (1 - sum_i c_i)``; ``tau_i`` retardation times, ``c_i`` dimensionless.

Units: a file that states its units is converted to Pa and s (moduli ``Pa, kPa, MPa, GPa``;
times ``s, ms, us, min, h``) and the table's ``modulus_unit``/``time_unit`` are ``"Pa"``/``"s"``;
a file that states none is taken as it is and they are ``None``. The material's ``tau0`` is 1
(its times are physical times in the table's time unit).

Accepted formats (recognized by their content; the extension is not needed)
---------------------------------------------------------------------------
``visco-sweep`` -- this project's CSV. Comment lines start with ``#``; the first is
``# visco-sweep prony``; ``# key = value`` lines give ``form`` (``wiechert`` or ``kelvin``;
default from the column names), exactly one of ``E0`` (relaxed) or ``Einf`` (instantaneous),
and optionally ``modulus_unit`` and ``time_unit`` (both or neither). Then a header ``tau,E``
(Wiechert arm moduli, in the modulus unit) or ``tau,c`` (Kelvin weights) and one row per arm::

    # visco-sweep prony
    # form = wiechert
    # E0 = 1.458e6
    # modulus_unit = Pa
    # time_unit = s
    tau,E
    1e-3,2.5e8
    1e-1,3.0e7

A file without the first-line marker whose header is ``tau,E`` or ``tau,c`` is read the same way.
:meth:`PronyTable.to_csv` writes this format.

``pyvisco`` -- the ``df_prony.csv`` of pyvisco (NREL, github.com/NREL/pyvisco): two header
rows, the names then the units, written by ``pyvisco.out.to_csv(prony['df_terms'], units,
index_label='i')``; the columns are ``i, tau_i, alpha_i, E_0, E_i`` (``pyvisco/prony.py``:
``df_prony['E_0'] = E_0``, ``df_prony['E_i'] = E_0 * alpha_i``), i.e.::

    i,tau_i,alpha_i,E_0,E_i
    -,s,-,MPa,MPa
    1,0.001,0.3,1500.0,450.0

``E_0`` is the instantaneous modulus (pyvisco's ``theory.md``: ``E(t=0) = E_0``,
``E_i = E_0 alpha_i``, ``E_inf = E_0 (1 - sum alpha_i)``), ``alpha_i`` the relative moduli:
the Wiechert form. Units as ``pyvisco/load.py`` allows them (``tau_i``: s; moduli Pa, kPa,
MPa, GPa). A shear table (``G_0``, ``G_i``) needs Poisson's ratio ``nu`` and is converted
with ``E = 2 (1 + nu) G`` (a constant nu); without ``nu`` it is refused. The ``i`` column is
optional; a file with ``alpha_i`` or ``E_i`` alone is read too, and with both they must agree.

``ansys`` -- an ANSYS APDL material card holding ``TB,PRONY,MAT,NTEMP,NPTS,SHEAR``
(4-letter abbreviations such as ``TB,PRON,...,SHEA`` as ANSYS writes them) followed by
``TBDATA,STLOC,C1,...`` lines whose constants fill the slots ``a_1, tau_1, a_2, tau_2, ...``
(``a_i`` relative moduli, ``tau_i`` relaxation times; a blank STLOC continues after the last
slot). The instantaneous Young's modulus is ``MP,EX,MAT,value`` (or ``MPDATA,EX,MAT,,value``)
from the card, or ``Einf`` given with the table (a card written by ANSYS's curve fitting holds
only the series; in Pa where the card states its units, else in its own). The format was read from pyvisco's ANSYS comparison
(``pyvisco/verify.py``: ``load_prony_ANSYS`` reads the ``TB`` line's 5th field as the number of
terms and the ``TBDATA`` constants as alternating ``alpha_i, tau_i``; ``prep_prony_ANSYS``
adds the instantaneous modulus the card lacks) and from the ANSYS 2020 R1 card in pyvisco's
``verification/freq_master/prony_terms.MPL`` (``TB,PRON,_MATL,1,27,SHEA`` and
``TBDATA,1,a1,tau1,a2``, ``TBDATA,4,tau2,a3,tau3``, ...). With a constant Poisson's ratio the
shear relative moduli are those of E. A ``BULK`` table alone is refused; beside a ``SHEAR``
table it must be the same series (else nu would change in time). One temperature only. With
``/UNITS,SI`` the numbers are Pa and s, with ``/UNITS,MPA`` MPa and s; otherwise as given.

``abaqus`` -- an Abaqus input deck (or the material's part of one; the keywords as in
Abaqus's Keywords Reference, ``*ELASTIC`` and ``*VISCOELASTIC``) holding
``*VISCOELASTIC, TIME=PRONY``, whose data lines are ``g_i, k_i, tau_i``: the shear and bulk
relative moduli and the relaxation time of each term (Abaqus's ``g_R(t) = 1 - sum_i g_i
(1 - exp(-t/tau_i))``, the Wiechert form with ``E_i = Einf g_i``). The modulus is
``*ELASTIC``'s single data line ``E, nu``: the relaxed (long-term) modulus by default
(``MODULI=LONG TERM``, Abaqus's default), the instantaneous one with
``MODULI=INSTANTANEOUS``; without an ``*ELASTIC`` block ``Einf`` is given with the table.
Keywords and parameters are case-insensitive, ``**`` lines are comments, other keywords
(``*MATERIAL``, ``*DENSITY``, ``*TRS``, ...) are skipped: the table is read at its reference
temperature, and the card's Poisson's ratio is not read (a scene's ``nu`` is its own). With a
constant Poisson's ratio the shear relative moduli are those of E: every ``k_i`` must equal
``g_i``, or be 0 in every row (the bulk does not relax, as for a nearly incompressible
rubber, where E = 3 G). One material, one temperature; Abaqus states no units, so the
numbers are as given.

``fit-dma`` -- the JSON that ``sweep fit-dma FILE.csv --maxwell N --out FIT.json`` writes (and
``--json`` prints): its
``maxwell`` object (``E0`` relaxed [Pa], ``moduli`` [Pa], ``times`` [s]) is the table. A JSON
from ``--maxwell 0`` holds only the MPL fit and is REFUSED, naming its four constants: an MPL
is not a finite table (its Prony series depends on the time window a scene needs, which is
chosen where the scene is built); give the MPL itself as the material, or fit with
``--maxwell N``.

Inline -- a mapping ``{tau: [...], E: [...], E0 or Einf: ..., form: wiechert}`` or
``{tau: [...], c: [...], E0 or Einf: ..., form: kelvin}`` (``form`` defaults from ``E``/``c``;
``modulus_unit``, ``time_unit`` and ``name`` optional); a JSON file holding such a mapping is
read as one. ``{prony: path}`` reads a file (relative to ``base_dir``), with ``nu``, ``Einf``
and ``name`` beside it as needed.

Checks (each a one-line :class:`~sweep.errors.InputError` naming the file or key)
----------------------------------------------------------------------------------
Cells that are not finite numbers; an empty table; lists of different lengths (or an ANSYS
card with an odd number of constants, or NPTS not the number of pairs; an Abaqus data line
with fewer than three values); times ``<= 0``;
moduli, weights or relative moduli ``< 0``; relative moduli (``alpha_i``, ``a_i``, ``c_i``)
summing to ``>= 1`` and an ``Einf`` not above the sum of the arm moduli (both: the relaxed
modulus would be ``<= 0``, a liquid, which has no relaxed adhesive contact), and a relaxed
modulus given as such a difference below :data:`DERIVED_K_MIN` of the instantaneous one
(rounding: relative moduli normalized to sum 1); a metadata value with more than one word
(``# E0 = 1.5 MPa``: the unit has its own line); an ``Einf`` beside a table that gives its
moduli (every format but an ANSYS card or an Abaqus deck without its modulus); a file that is
none of the formats (one line naming the file and the accepted formats). A UTF-8 byte-order
mark (Excel's "CSV UTF-8") is dropped; in this project's CSV a comment line whose text
before ``=`` is more than one word is a comment, not a key.

"Moduli that do not decrease": a relaxation modulus must not increase in time. With every arm
``E_i >= 0`` (or ``c_i >= 0``), ``R(t)`` is a sum of decaying exponentials, non-increasing at
every t (completely monotone), and ``C(t)`` non-decreasing; so the check is the sign of every
arm, and a negative arm is refused even where R would still decrease.

Arms with a zero modulus are dropped (NNLS fits leave some); arms are sorted by time.

The hash
--------
:meth:`PronyTable.content_hash` digests the numbers, not the file: the form, the instantaneous
modulus (Wiechert) or the relaxed one (Kelvin) and the sorted ``(tau_i, E_i or c_i)`` pairs, all
in Pa and s where the units are known, each rounded to 10 significant digits (so that the same
table written by two tools, whose last bits differ, hashes the same, and any change a person
makes to a number changes it). The Wiechert hash uses ``Einf``, a sum of positive numbers in
every format, not ``E0``, which a relative table gives as a difference that loses digits.
"""
from __future__ import annotations

import csv
import hashlib
import io
import json
import math
import os
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from ..errors import InputError, check_range
from .prony_table import Prony

__all__ = ["PronyTable", "read_prony", "hash_rounded", "FORMATS", "MODULUS_UNITS",
           "TIME_UNITS"]

#: The formats :func:`read_prony` recognizes (the values of ``PronyTable.source_format``,
#: besides ``"inline"``).
FORMATS = ("visco-sweep", "pyvisco", "ansys", "abaqus", "fit-dma")
#: Modulus units a file may state, in Pa.
MODULUS_UNITS = {"Pa": 1.0, "kPa": 1e3, "MPa": 1e6, "GPa": 1e9}
#: Time units a file may state, in s.
TIME_UNITS = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "min": 60.0, "h": 3600.0}

_ACCEPTED = ("a visco-sweep Prony CSV ('# visco-sweep prony' first line, header tau,E or "
             "tau,c), pyvisco's df_prony.csv (header i,tau_i,alpha_i,E_0,E_i then a units "
             "row), an ANSYS TB,PRONY card, an Abaqus *VISCOELASTIC, TIME=PRONY block, or "
             "the JSON of sweep fit-dma --json")
_MARKER = "visco-sweep prony"
#: the formats whose file may lack the instantaneous modulus, given as ``Einf`` beside it
_EINF_FORMATS = ("ansys", "abaqus")
_CSV_KEYS = ("form", "E0", "Einf", "modulus_unit", "time_unit")
_INLINE_KEYS = ("tau", "E", "c", "form", "E0", "Einf", "modulus_unit", "time_unit", "name",
                "recorded")
#: the least relaxed modulus, over the instantaneous one, that a table giving it as a
#: difference (Einf minus the arms, or Einf times one minus the relative moduli) resolves:
#: below it the difference is rounding (pyvisco normalizes an overshooting fit's relative
#: moduli to sum 1, which in floating point can leave 1e-16)
DERIVED_K_MIN = 1e-12
#: a recorded table's two moduli (``recorded: true``) agree with each other to this (they
#: were computed from each other when the table was first read)
RECORDED_RTOL = 1e-9
_FILE_KEYS = ("prony", "nu", "Einf", "name")
_FORMS = {"wiechert": "wiechert", "maxwell": "wiechert", "kelvin": "kelvin"}
_HASH_DIGITS = 10


@dataclass(frozen=True, eq=False)
class PronyTable:
    """A checked Prony table and the material it defines.

    Attributes
    ----------
    material : Prony
        The material (``kind="maxwell"`` for the Wiechert form, ``"kelvin"`` for the Kelvin
        form), moduli in ``modulus_unit``, times in ``time_unit``, ``tau0 = 1``.
    form : {"wiechert", "kelvin"}
    times : ndarray
        ``tau_i > 0``, ascending (relaxation times for Wiechert, retardation times for Kelvin).
    weights : ndarray
        Wiechert: arm moduli ``E_i > 0``; Kelvin: weights ``c_i > 0`` (dimensionless).
    E0, Einf : float
        Relaxed and instantaneous moduli, ``0 < E0 <= Einf``.
    source_format : str
        One of :data:`FORMATS` or ``"inline"``.
    name : str
        A human name: the file's stem, ``"inline"``, or the ``name`` given.
    source : str
        The file's path, or ``"inline"``.
    modulus_unit, time_unit : str or None
        ``"Pa"`` and ``"s"`` when the source stated its units (the numbers were converted);
        ``None`` when it stated none (the numbers are as given).
    """

    material: Prony
    form: str
    times: np.ndarray
    weights: np.ndarray
    E0: float
    Einf: float
    source_format: str
    name: str
    source: str
    modulus_unit: str | None = None
    time_unit: str | None = None

    @property
    def n_arms(self) -> int:
        """Number of arms (non-zero terms)."""
        return int(self.times.size)

    @property
    def k(self) -> float:
        """``E0 / Einf`` in (0, 1]."""
        return self.E0 / self.Einf

    def content_hash(self) -> str:
        """16 hex digits of a SHA-256 of the table's numbers (module docstring, "The hash")."""
        lead = self.Einf if self.form == "wiechert" else self.E0
        parts = [self.form, _round(lead)]
        parts += [f"{_round(t)}:{_round(w)}" for t, w in zip(self.times, self.weights)]
        return hashlib.sha256(";".join(parts).encode()).hexdigest()[:16]

    def summary(self) -> str:
        """One line naming the table: name, format, arms, moduli and hash."""
        unit = f" {self.modulus_unit}" if self.modulus_unit else ""
        return (f"{self.name} ({self.source_format}, {self.form}, {self.n_arms} arms, "
                f"E0 = {self.E0:.4g}{unit}, Einf = {self.Einf:.4g}{unit}, "
                f"hash {self.content_hash()})")

    def to_csv(self, path) -> Path:
        """Write the table in this project's CSV format (full precision); returns the path."""
        col = "E" if self.form == "wiechert" else "c"
        lines = [f"# {_MARKER}", f"# form = {self.form}", f"# E0 = {self.E0!r}"]
        if self.modulus_unit:
            lines.append(f"# modulus_unit = {self.modulus_unit}")
        if self.time_unit:
            lines.append(f"# time_unit = {self.time_unit}")
        lines.append(f"tau,{col}")
        lines += [f"{t!r},{w!r}" for t, w in zip(self.times.tolist(), self.weights.tolist())]
        path = Path(path)
        path.write_text("\n".join(lines) + "\n")
        return path

    def __repr__(self):
        return f"PronyTable({self.summary()})"


def _round(x: float) -> str:
    return f"{float(x):.{_HASH_DIGITS - 1}e}"


def hash_rounded(x: float) -> float:
    """``x`` to the significant digits by which :meth:`PronyTable.content_hash` reads a
    table's numbers: what the same table gives in every format (a relative table's relaxed
    modulus, a difference, differs in its last digits from a format that states it)."""
    return float(_round(x))


# ============================================================================ the entry point

def read_prony(spec, *, base_dir=None, nu=None, Einf=None) -> PronyTable:
    """Read and check a Prony table (module docstring: formats, units, checks).

    Parameters
    ----------
    spec : str, path-like, dict or PronyTable
        A file path; ``{"prony": path, ...}``; or an inline table
        ``{"tau": [...], "E": [...] or "c": [...], "E0" or "Einf": ..., "form": ...}``.
    base_dir : str or path-like, optional
        Directory a relative path is resolved against (e.g. a config's folder); default the
        working directory.
    nu : float, optional
        Poisson's ratio in (-1, 0.5], needed to read a shear table (pyvisco ``G_0, G_i``);
        a ``nu`` key of ``spec`` takes precedence.
    Einf : float, optional
        The instantaneous Young's modulus for an ANSYS card without ``MP,EX`` or an Abaqus
        deck without ``*ELASTIC`` (> 0: in Pa where the card states its units, ``/UNITS``,
        else in the card's own); an ``Einf`` key of ``spec`` takes precedence. Refused with
        the other formats, which give their moduli.

    Returns
    -------
    PronyTable

    Raises
    ------
    InputError
        One line naming the file (or key) and what is allowed.
    """
    if isinstance(spec, PronyTable):
        return spec
    name = None
    if isinstance(spec, dict):
        if "prony" not in spec:
            return _inline(spec, "prony", "inline", "inline", "inline")
        _check_keys("material", spec, _FILE_KEYS)
        nu = spec.get("nu", nu)
        Einf = spec.get("Einf", Einf)
        name = spec.get("name")
        spec = spec["prony"]
    if not isinstance(spec, (str, os.PathLike)):
        raise InputError(f"prony must be a file path or a table {{tau: [...], E: [...], "
                         f"E0: ...}} (got {spec!r})")
    path = Path(spec)
    if base_dir is not None and not path.is_absolute():
        path = Path(base_dir) / path
    try:
        text = path.read_text(encoding="utf-8-sig")     # a BOM (Excel's CSV UTF-8) dropped
    except UnicodeDecodeError:
        raise InputError(f"{path}: not a Prony table (a binary file); "
                         f"accepted: {_ACCEPTED}") from None
    except OSError as exc:
        raise InputError(f"{path}: cannot read the Prony table ({exc.strerror})") from None
    nu = None if nu is None else check_range("nu", nu, -1.0, 0.5, lo_open=True)
    Einf = None if Einf is None else check_range("Einf", Einf, 0.0, lo_open=True)
    fmt = _detect(path, text)
    if Einf is not None and fmt not in _EINF_FORMATS:
        raise InputError(f"{path}: Einf is given with a table only for an ANSYS card without "
                         f"MP,EX or an Abaqus deck without *ELASTIC; this {fmt} table gives its "
                         f"moduli itself (got Einf = {Einf:g})")
    reader = {"visco-sweep": _read_project_csv, "pyvisco": _read_pyvisco,
              "ansys": _read_ansys, "abaqus": _read_abaqus, "fit-dma": _read_json}[fmt]
    table = reader(path, text, nu=nu, Einf=Einf)
    return table if name is None else replace(table, name=str(name))


def _detect(path: Path, text: str) -> str:
    """The format of a file, from its content."""
    stripped = text.lstrip()
    if not stripped:
        raise InputError(f"{path}: empty file, not a Prony table; accepted: {_ACCEPTED}")
    if stripped.startswith("{"):
        return "fit-dma"
    lines = [ln.strip() for ln in text.splitlines() if ln.strip()]
    if lines[0].lstrip("#").strip().lower().startswith(_MARKER):
        return "visco-sweep"
    for ln in lines:
        f = [x.strip().upper() for x in ln.split("!")[0].split(",")]
        if len(f) > 1 and f[0] == "TB" and f[1].startswith("PRON"):
            return "ansys"
        if _abaqus_keyword(ln)[0] == "VISCOELASTIC":
            return "abaqus"
    first = next((ln for ln in lines if not ln.startswith("#")), "")
    cols = [c.strip() for c in first.split(",")]
    if "tau_i" in cols and ("alpha_i" in cols or "E_i" in cols or "G_i" in cols):
        return "pyvisco"
    if cols[:1] == ["tau"] and len(cols) == 2 and cols[1] in ("E", "c"):
        return "visco-sweep"
    raise InputError(f"{path}: not a Prony table in any accepted format; accepted: {_ACCEPTED}")


# ============================================================================ the common core

def _make(form, tau, w, *, E0=None, Einf=None, where, fmt, name, source, units_known):
    """Check a table's arrays, drop zero arms, sort, and build the :class:`PronyTable`.

    ``tau``, ``w`` are already floats in the final units; exactly one of E0/Einf is given.
    """
    tau = np.asarray(tau, dtype=float)
    w = np.asarray(w, dtype=float)
    col = "E" if form == "wiechert" else "c"
    if tau.size == 0:
        raise InputError(f"{where}: empty table (needs at least one row of tau and {col})")
    if tau.size != w.size:
        raise InputError(f"{where}: tau and {col} must have the same length (got {tau.size} "
                         f"and {w.size})")
    for label, arr in (("tau", tau), (col, w)):
        bad = np.flatnonzero(~np.isfinite(arr))
        if bad.size:
            raise InputError(f"{where}: {label}[{bad[0]}] must be a finite number "
                             f"(got {arr[bad[0]]})")
    bad = np.flatnonzero(tau <= 0.0)
    if bad.size:
        raise InputError(f"{where}: times tau must be > 0 (got tau[{bad[0]}] = {tau[bad[0]]:g})")
    bad = np.flatnonzero(w < 0.0)
    if bad.size:
        what = "moduli E" if form == "wiechert" else "weights c"
        raise InputError(f"{where}: {what} must be >= 0, so that the relaxation modulus never "
                         f"increases (got {col}[{bad[0]}] = {w[bad[0]]:g})")
    keep = w > 0.0
    if not keep.any():
        what = "moduli E" if form == "wiechert" else "weights c"
        raise InputError(f"{where}: every one of the {what} is 0 (a table needs one arm > 0; "
                         f"without one the material is elastic, k = 1)")
    order = np.argsort(tau[keep], kind="stable")
    tau, w = tau[keep][order], w[keep][order]
    recorded = E0 is not None and Einf is not None     # both: a table as it was read
    derived_E0 = E0 is None
    if form == "kelvin":
        s = float(w.sum())
        if not s < 1.0:
            raise InputError(f"{where}: Kelvin weights c must sum to < 1 (the relaxed modulus "
                             f"is Einf (1 - sum c)) (got sum {s:.6g})")
        if E0 is None:
            E0 = Einf * (1.0 - s)
        derived = E0 / (1.0 - s)
        kind = "kelvin"
    else:
        s = float(w.sum())
        if E0 is None:
            E0 = Einf - s
            if not E0 > 0.0:
                raise InputError(f"{where}: Einf = {Einf:.6g} must exceed the sum of the arm "
                                 f"moduli {s:.6g} (the relaxed modulus Einf - sum E must be "
                                 f"> 0; a liquid has no relaxed contact)")
        derived = E0 + s
        kind = "maxwell"
    if recorded and not math.isclose(derived, Einf, rel_tol=RECORDED_RTOL):
        raise InputError(f"{where}: E0 = {E0:.6g} and Einf = {Einf:.6g} disagree (the table "
                         f"gives Einf = {derived:.10g} from E0); give one of them")
    Einf = Einf if recorded else derived
    if not (math.isfinite(E0) and E0 > 0.0):
        raise InputError(f"{where}: the relaxed modulus E0 must be > 0 (got {E0:.6g})")
    if derived_E0 and E0 < DERIVED_K_MIN * Einf:
        raise InputError(f"{where}: the arms sum to the instantaneous modulus within rounding "
                         f"(the relaxed modulus, their difference, is {E0 / Einf:.2g} Einf, "
                         f"below {DERIVED_K_MIN:g} Einf): a liquid, which has no relaxed "
                         f"contact (a fit normalized to sum 1 describes one)")
    material = Prony(w, tau, E0=E0, kind=kind)
    for arr in (tau, w):
        arr.setflags(write=False)
    return PronyTable(material=material, form=form, times=tau, weights=w, E0=float(E0),
                      Einf=float(Einf), source_format=fmt, name=name, source=source,
                      modulus_unit="Pa" if units_known else None,
                      time_unit="s" if units_known else None)


def _relative(arms, tau, Einf, *, where, label, **kw):
    """A Wiechert table from its arm moduli ``E_i = Einf alpha_i`` and the instantaneous
    modulus ``Einf``, checking the relative moduli ``alpha_i`` (named ``label``)."""
    arms = np.asarray(arms, dtype=float)
    if arms.size and np.all(np.isfinite(arms)):
        bad = np.flatnonzero(arms < 0.0)
        if bad.size:
            raise InputError(f"{where}: relative moduli {label} must be >= 0 "
                             f"(got {label}[{bad[0]}] = {arms[bad[0]] / Einf:g})")
        s = float(arms.sum()) / Einf
        if not s < 1.0:
            raise InputError(f"{where}: the relative moduli {label} must sum to < 1 (the "
                             f"relaxed modulus is E_0 (1 - sum {label}); 1 is a liquid) "
                             f"(got sum {s:.12g})")
    return _make("wiechert", tau, arms, Einf=Einf, where=where, **kw)


def _number(where, text) -> float:
    try:
        x = float(str(text).strip())
    except (TypeError, ValueError):
        raise InputError(f"{where}: must be a number (got {text!r})") from None
    if not math.isfinite(x):
        raise InputError(f"{where}: must be a finite number (got {str(text).strip()})")
    return x


def _unit(where, text, table, what) -> float:
    if text not in table:
        raise InputError(f"{where}: {what} unit must be one of {', '.join(table)} (got {text!r})")
    return table[text]


def _check_keys(where, mapping, allowed):
    unknown = [k for k in mapping if k not in allowed]
    if unknown:
        raise InputError(f"{where} has unknown key {unknown[0]!r} (allowed: {', '.join(allowed)})")


def _form(where, value, col):
    if value is None:
        return "wiechert" if col == "E" else "kelvin"
    form = _FORMS.get(str(value).strip().lower())
    if form is None:
        raise InputError(f"{where}: form must be wiechert or kelvin (got {value!r})")
    if (col == "E") != (form == "wiechert"):
        need = "E" if form == "wiechert" else "c"
        raise InputError(f"{where}: form {form} needs the column {need} (got {col}: E for "
                         f"Wiechert arm moduli, c for Kelvin weights)")
    return form


# ============================================================================ inline

def _inline(spec, where, fmt, name, source):
    _check_keys(where, spec, _INLINE_KEYS)
    has_e, has_c = "E" in spec, "c" in spec
    if has_e == has_c:
        raise InputError(f"{where} needs exactly one of E (Wiechert arm moduli) or c (Kelvin "
                         f"weights) beside tau (got {'both' if has_e else 'neither'})")
    col = "E" if has_e else "c"
    form = _form(where, spec.get("form"), col)
    if "tau" not in spec:
        raise InputError(f"{where} needs tau, the list of times (got keys {', '.join(spec)})")
    tau = _numbers(f"{where} tau", spec["tau"])
    w = _numbers(f"{where} {col}", spec[col])
    E0, Einf, m_scale = _plateau(where, spec.get("E0"), spec.get("Einf"),
                                 spec.get("modulus_unit"), recorded=bool(spec.get("recorded")))
    t_scale = 1.0
    if spec.get("time_unit") is not None:
        t_scale = _unit(where, spec["time_unit"], TIME_UNITS, "time_unit: time")
    known = spec.get("modulus_unit") is not None and spec.get("time_unit") is not None
    if not known and (spec.get("modulus_unit") is not None or spec.get("time_unit") is not None):
        raise InputError(f"{where}: give both modulus_unit and time_unit, or neither")
    if form == "wiechert":
        w = w * m_scale
    return _make(form, tau * t_scale, w, E0=E0, Einf=Einf, where=where, fmt=fmt,
                 name=str(spec.get("name", name)), source=source, units_known=known)


def _numbers(where, values) -> np.ndarray:
    if isinstance(values, (str, bytes)) or not hasattr(values, "__len__"):
        raise InputError(f"{where} must be a list of numbers (got {values!r})")
    return np.array([_number(f"{where}[{i}]", v) for i, v in enumerate(values)], dtype=float)


def _plateau(where, E0, Einf, modulus_unit, recorded=False):
    """The given plateau modulus, scaled by the modulus unit: (E0, Einf, scale), one of them
    None; both where ``recorded`` (a table as a results file records it, both moduli as they
    were read, so that it reads back to the same numbers: :func:`_make` checks they agree)."""
    if (E0 is None) == (Einf is None) and not (recorded and E0 is not None):
        raise InputError(f"{where} needs exactly one of E0 (relaxed modulus) or Einf "
                         f"(instantaneous modulus) (got {'both' if E0 is not None else 'neither'})")
    scale = 1.0
    if modulus_unit is not None:
        scale = _unit(where, modulus_unit, MODULUS_UNITS, "modulus_unit: modulus")
    out = []
    for name, value in (("E0", E0), ("Einf", Einf)):
        if value is None:
            out.append(None)
            continue
        x = _number(f"{where} {name}", value)
        if not x > 0.0:
            raise InputError(f"{where}: {name} must be > 0 (got {x:g})")
        out.append(x * scale)
    return out[0], out[1], scale


# ============================================================================ visco-sweep CSV

def _read_project_csv(path, text, **_):
    meta, header, rows = {}, None, []
    for no, line in enumerate(text.splitlines(), start=1):
        s = line.strip()
        if not s:
            continue
        if s.startswith("#"):
            body = s.lstrip("#").strip()
            key, eq, value = (x.strip() for x in body.partition("="))
            # "# key = value" is metadata; a comment whose text before "=" is not one word
            # ("# DMA master curve at T_ref = 20 C") is a comment
            if eq and key and len(key.split()) == 1:
                if key not in _CSV_KEYS:
                    raise InputError(f"{path} line {no}: unknown key {key!r} (allowed: "
                                     f"{', '.join(_CSV_KEYS)})")
                if len(value.split()) > 1:
                    raise InputError(f"{path} line {no}: {key} must be one value (got "
                                     f"{value!r}; a modulus's unit goes on its own line, "
                                     f"# modulus_unit = ..., with # time_unit = ...)")
                meta[key] = value
            continue
        cells = [c.strip() for c in s.split(",")]
        if header is None:
            header = (no, cells)
        else:
            rows.append((no, cells))
    if header is None or header[1][:1] != ["tau"] or len(header[1]) != 2 \
            or header[1][1] not in ("E", "c"):
        got = "none" if header is None else ",".join(header[1])
        raise InputError(f"{path}: the header must be tau,E (Wiechert) or tau,c (Kelvin) "
                         f"(got {got})")
    col = header[1][1]
    where = str(path)
    tau, w = [], []
    for no, cells in rows:
        if len(cells) != 2:
            raise InputError(f"{path} line {no}: needs 2 cells tau,{col} (got {len(cells)})")
        tau.append(_number(f"{path} line {no}, column tau", cells[0]))
        w.append(_number(f"{path} line {no}, column {col}", cells[1]))
    spec = {"tau": tau, col: w, **meta}
    return _inline(spec, where, "visco-sweep", path.stem, str(path))


# ============================================================================ pyvisco

def _read_pyvisco(path, text, *, nu=None, **_):
    rows = [r for r in csv.reader(io.StringIO(text)) if any(c.strip() for c in r)]
    names = [c.strip() for c in rows[0]]
    units = None
    data = rows[1:]
    if data and any(_is_text(c) for c in data[0]):
        units = dict(zip(names, (c.strip() for c in data[0])))
        data = data[1:]
    mod = "G" if "G_0" in names else "E"
    inst, arm = f"{mod}_0", f"{mod}_i"
    if inst not in names:
        raise InputError(f"{path}: a pyvisco df_prony.csv needs the column E_0 (or G_0), the "
                         f"instantaneous modulus (got columns {','.join(names)})")
    if "alpha_i" not in names and arm not in names:
        raise InputError(f"{path}: a pyvisco df_prony.csv needs alpha_i or {arm} (got columns "
                         f"{','.join(names)})")
    first = 3 if units is not None else 2

    def column(name):
        j = names.index(name)
        out = []
        for r, row in enumerate(data):
            cell = row[j] if j < len(row) else ""
            out.append(_number(f"{path} line {first + r}, column {name}", cell))
        return np.array(out, dtype=float)

    tau = column("tau_i")
    E_inst = column(inst)
    m_scale, t_scale = 1.0, 1.0
    if units is not None:
        t_scale = _unit(f"{path} units row, column tau_i", units.get("tau_i"), TIME_UNITS, "time")
        for c in (inst, arm):
            if c in units:
                m_scale = _unit(f"{path} units row, column {c}", units[c], MODULUS_UNITS, "modulus")
        if inst in units and arm in units and units[inst] != units[arm]:
            raise InputError(f"{path} units row: {inst} and {arm} must have the same unit (got "
                             f"{units[inst]} and {units[arm]})")
    if E_inst.size == 0:
        raise InputError(f"{path}: empty table (no rows below the header)")
    if not np.all(E_inst == E_inst[0]):
        raise InputError(f"{path}: column {inst} (the instantaneous modulus) must be the same on "
                         f"every row (got {E_inst.min():g} .. {E_inst.max():g})")
    E_0 = float(E_inst[0])
    if not E_0 > 0.0:
        raise InputError(f"{path}: {inst} (the instantaneous modulus) must be > 0 (got {E_0:g})")
    if "alpha_i" in names:
        alpha = column("alpha_i")
        if arm in names:
            Ei = column(arm)
            bad = np.flatnonzero(np.abs(alpha * E_0 - Ei) > 1e-9 * E_0)
            if bad.size:
                i = bad[0]
                raise InputError(f"{path} line {first + i}: {arm} must equal {inst} x alpha_i "
                                 f"(got {Ei[i]:g}, expected {alpha[i] * E_0:g})")
    arms = column(arm) if arm in names else alpha * E_0
    scale = m_scale
    if mod == "G":
        if nu is None:
            raise InputError(f"{path}: a shear table (G_0, G_i) needs Poisson's ratio nu to give "
                             f"E = 2 (1 + nu) G; give nu with the table")
        scale *= 2.0 * (1.0 + nu)
    return _relative(arms * scale, tau * t_scale, E_0 * scale, where=str(path), label="alpha_i",
                     fmt="pyvisco", name=path.stem, source=str(path),
                     units_known=units is not None)


def _is_text(cell: str) -> bool:
    try:
        float(cell)
        return False
    except ValueError:
        return True


# ============================================================================ ANSYS

_ANSYS_UNITS = {"SI": 1.0, "MPA": 1e6}


def _read_ansys(path, text, *, Einf=None, **_):
    tables = []          # [{"opt", "npts", "slots", "line", "temps"}]
    current = None
    ex = None
    units = None
    for no, raw in enumerate(text.splitlines(), start=1):
        line = raw.split("!")[0].strip()
        if not line:
            continue
        f = [x.strip() for x in line.split(",")]
        cmd = f[0].upper()
        if cmd == "TB":
            current = None
            if len(f) > 1 and f[1].upper().startswith("PRON"):
                opt = f[5].upper() if len(f) > 5 else ""
                if not opt or not ("SHEAR".startswith(opt) or "BULK".startswith(opt)):
                    raise InputError(f"{path} line {no}: TB,PRONY needs TBOPT SHEAR or BULK "
                                     f"(got {opt!r})")
                npts = f[4] if len(f) > 4 and f[4] else None
                if npts is not None:
                    npts = _number(f"{path} line {no}, NPTS", npts)
                current = {"opt": "SHEAR" if "SHEAR".startswith(opt) else "BULK", "npts": npts,
                           "slots": {}, "next": 1, "line": no, "temps": 0}
                tables.append(current)
        elif cmd in ("TBTEMP", "TBFIELD") and current is not None:
            current["temps"] += 1
            if current["temps"] > 1:
                raise InputError(f"{path} line {no}: the Prony table has more than one "
                                 f"temperature; give a card with one (a master curve at the "
                                 f"reference temperature)")
        elif cmd == "TBDATA" and current is not None:
            start = current["next"]
            if len(f) > 1 and f[1]:
                start = int(_number(f"{path} line {no}, STLOC", f[1]))
            values = f[2:]
            while values and not values[-1]:
                values.pop()
            for j, v in enumerate(values):
                if v:
                    current["slots"][start + j] = _number(f"{path} line {no}, constant {j + 1}", v)
            current["next"] = start + len(values)
        elif cmd in ("MP", "MPDATA") and len(f) > 1 and f[1].upper() == "EX":
            cells = [c for c in f[3 if cmd == "MP" else 4:] if c]
            if not cells:
                raise InputError(f"{path} line {no}: {cmd},EX without a value")
            if len(cells) > 1 and any(_number(f"{path} line {no}", c) != 0.0 for c in cells[1:]):
                raise InputError(f"{path} line {no}: {cmd},EX with more than one value "
                                 f"(temperature-dependent); give one instantaneous modulus")
            ex = _number(f"{path} line {no}, EX", cells[0])
        elif cmd.startswith("/UNITS"):
            units = f[1].upper() if len(f) > 1 else None
    shear = [t for t in tables if t["opt"] == "SHEAR"]
    bulk = [t for t in tables if t["opt"] == "BULK"]
    if not shear:
        raise InputError(f"{path}: the card has no TB,PRONY,...,SHEAR table (a BULK table alone "
                         f"does not give E(t))")
    if len(shear) > 1:
        raise InputError(f"{path}: the card has {len(shear)} TB,PRONY SHEAR tables (lines "
                         f"{', '.join(str(t['line']) for t in shear)}); give one material")
    alpha, tau = _ansys_pairs(path, shear[0])
    for b in bulk:
        a2, t2 = _ansys_pairs(path, b)
        if a2.size != alpha.size or not (np.allclose(a2, alpha, rtol=1e-9, atol=0)
                                         and np.allclose(t2, tau, rtol=1e-9, atol=0)):
            raise InputError(f"{path} line {b['line']}: the BULK Prony table differs from the "
                             f"SHEAR one (Poisson's ratio would change in time; only a constant "
                             f"nu is supported)")
    # the card's numbers in Pa where it states its units (/UNITS); an Einf given with the
    # table is the table's modulus as read: in Pa then, else in the card's own units
    scale = _ANSYS_UNITS.get(units, 1.0)
    if ex is not None:
        if not ex > 0.0:
            raise InputError(f"{path}: MP,EX (the instantaneous modulus) must be > 0 (got {ex:g})")
        ex = ex * scale
    if ex is not None and Einf is not None and abs(ex - Einf) > 1e-12 * ex:
        raise InputError(f"{path}: Einf = {Einf:g} given with the card differs from its MP,EX "
                         f"= {ex:g}{' Pa' if units in _ANSYS_UNITS else ''}; give one")
    E_inst = ex if ex is not None else Einf
    if E_inst is None:
        raise InputError(f"{path}: the card gives no instantaneous modulus (no MP,EX line); "
                         f"give Einf (the instantaneous Young's modulus) with the table")
    return _relative(alpha * E_inst, tau, E_inst, where=str(path), label="a_i", fmt="ansys",
                     name=path.stem, source=str(path), units_known=units in _ANSYS_UNITS)


def _ansys_pairs(path, table):
    slots = table["slots"]
    where = f"{path} line {table['line']}"
    if not slots:
        raise InputError(f"{where}: empty Prony table (no TBDATA constants)")
    n = max(slots)
    missing = [i for i in range(1, n + 1) if i not in slots]
    if missing:
        raise InputError(f"{where}: TBDATA constant {missing[0]} is missing (the constants are "
                         f"a_1, tau_1, a_2, tau_2, ...)")
    if n % 2:
        raise InputError(f"{where}: {n} TBDATA constants, an odd number: every relative modulus "
                         f"a_i needs its time tau_i")
    if table["npts"] is not None and table["npts"] != n // 2:
        raise InputError(f"{where}: NPTS = {table['npts']:g} but TBDATA gives {n // 2} pairs "
                         f"(a_i, tau_i)")
    v = np.array([slots[i] for i in range(1, n + 1)])
    a = v[0::2]
    bad = np.flatnonzero(a < 0.0)
    if bad.size:
        raise InputError(f"{where}: relative moduli a_i must be >= 0 (got a_{bad[0] + 1} = "
                         f"{a[bad[0]]:g})")
    return a, v[1::2]


# ============================================================================ Abaqus

def _abaqus_keyword(line: str) -> tuple[str, dict]:
    """The keyword and parameters of an Abaqus keyword line (``*Elastic, moduli=LONG TERM``:
    ``("ELASTIC", {"MODULI": "LONG TERM"})``, upper case, blanks collapsed); ``("", {})``
    for a data or comment line."""
    line = line.strip()
    if not line.startswith("*") or line.startswith("**"):
        return "", {}
    name, *params = line[1:].split(",")
    out = {}
    for p in params:
        key, _, value = p.partition("=")
        if key.strip():
            out[" ".join(key.upper().split())] = " ".join(value.upper().split())
    return " ".join(name.upper().split()), out


def _read_abaqus(path, text, *, Einf=None, **_):
    where = str(path)
    blocks = {"VISCOELASTIC": [], "ELASTIC": []}     # [(line, params, [(line, cells)])]
    block = None
    for no, raw in enumerate(text.splitlines(), start=1):
        line = raw.strip()
        if not line or line.startswith("**"):
            continue
        if line.startswith("*"):
            keyword, params = _abaqus_keyword(line)
            block = (no, params, []) if keyword in blocks else None
            if block is not None:
                blocks[keyword].append(block)
        elif block is not None:
            cells = [c.strip() for c in line.split(",")]
            while cells and not cells[-1]:
                cells.pop()
            block[2].append((no, cells))
    visco, elastic = blocks["VISCOELASTIC"], blocks["ELASTIC"]
    if len(visco) > 1 or len(elastic) > 1:
        many = "VISCOELASTIC" if len(visco) > 1 else "ELASTIC"
        lines = ", ".join(str(b[0]) for b in blocks[many])
        raise InputError(f"{where}: the deck has {len(blocks[many])} *{many} blocks (lines "
                         f"{lines}); give one material")
    no, params, rows = visco[0]
    if params.get("TIME") != "PRONY":
        got = ", ".join(f"{k}={v}" if v else k for k, v in params.items()) or "none"
        raise InputError(f"{where} line {no}: *VISCOELASTIC needs TIME=PRONY, the Prony series "
                         f"itself (got {got})")
    if params.get("TYPE", "ISOTROPIC") != "ISOTROPIC":
        raise InputError(f"{where} line {no}: *VISCOELASTIC TYPE must be ISOTROPIC (got "
                         f"{params['TYPE']})")
    if not rows:
        raise InputError(f"{where} line {no}: empty Prony table (no data lines g_i, k_i, tau_i)")
    g, k, tau = [], [], []
    for row_no, cells in rows:
        if len(cells) < 3:
            raise InputError(f"{where} line {row_no}: needs 3 values g_i, k_i, tau_i (got "
                             f"{len(cells)})")
        for label, out, cell in zip(("g_i", "k_i", "tau_i"), (g, k, tau), cells):
            out.append(_number(f"{where} line {row_no}, {label}", cell))
    g, k, tau = np.array(g), np.array(k), np.array(tau)
    if np.any(k != 0.0) and not np.allclose(k, g, rtol=1e-9, atol=0.0):
        i = int(np.flatnonzero(~np.isclose(k, g, rtol=1e-9, atol=0.0))[0])
        raise InputError(f"{where} line {rows[i][0]}: the bulk ratio k_i = {k[i]:g} differs from "
                         f"the shear ratio g_i = {g[i]:g} (Poisson's ratio would change in time; "
                         f"only a constant nu is supported: give k_i = g_i, or 0 in every row)")
    E_inst, relaxed = Einf, None
    if elastic:
        e_no, e_params, e_rows = elastic[0]
        if e_params.get("TYPE", "ISOTROPIC") != "ISOTROPIC":
            raise InputError(f"{where} line {e_no}: *ELASTIC TYPE must be ISOTROPIC (got "
                             f"{e_params['TYPE']})")
        if len(e_rows) != 1:
            raise InputError(f"{where} line {e_no}: *ELASTIC needs one data line E, nu (got "
                             f"{len(e_rows)}: temperature-dependent moduli are not supported)")
        moduli = e_params.get("MODULI", "LONG TERM")
        if moduli not in ("LONG TERM", "INSTANTANEOUS"):
            raise InputError(f"{where} line {e_no}: *ELASTIC MODULI must be LONG TERM or "
                             f"INSTANTANEOUS (got {moduli})")
        e_row, e_cells = e_rows[0]
        if not e_cells:
            raise InputError(f"{where} line {e_row}: *ELASTIC without a modulus")
        E = _number(f"{where} line {e_row}, E", e_cells[0])
        if not E > 0.0:
            raise InputError(f"{where} line {e_row}: the modulus E must be > 0 (got {E:g})")
        if moduli == "INSTANTANEOUS":
            E_inst = E
        else:
            relaxed = E
        if Einf is not None:
            raise InputError(f"{where}: Einf = {Einf:g} given with a deck whose *ELASTIC gives "
                             f"the modulus; give one")
    elif Einf is None:
        raise InputError(f"{where}: the deck gives no modulus (no *ELASTIC block); give Einf "
                         f"(the instantaneous Young's modulus) with the table")
    kw = dict(fmt="abaqus", name=path.stem, source=where, units_known=False)
    if relaxed is None:
        return _relative(g * E_inst, tau, E_inst, where=where, label="g_i", **kw)
    # long-term moduli: the relaxed modulus is given, the arms are g_i E_inst with
    # E_inst = E (1 - sum g_i)^-1
    s = float(g.sum())
    if not s < 1.0:
        raise InputError(f"{where}: the relative moduli g_i must sum to < 1 (the relaxed "
                         f"modulus is E_inst (1 - sum g_i); 1 is a liquid) (got sum {s:.12g})")
    bad = np.flatnonzero(g < 0.0)
    if bad.size:
        raise InputError(f"{where}: relative moduli g_i must be >= 0 (got g_i[{bad[0]}] = "
                         f"{g[bad[0]]:g})")
    return _make("wiechert", tau, g * (relaxed / (1.0 - s)), E0=relaxed, where=where, **kw)


# ============================================================================ JSON

def _read_json(path, text, **_):
    try:
        doc = json.loads(text)
    except json.JSONDecodeError as exc:
        raise InputError(f"{path}: not valid JSON (line {exc.lineno}: {exc.msg}); accepted: "
                         f"{_ACCEPTED}") from None
    if not isinstance(doc, dict):
        raise InputError(f"{path}: not a Prony table in any accepted format; accepted: {_ACCEPTED}")
    if "tau" in doc:
        return _inline(doc, str(path), "inline", path.stem, str(path))
    if "mpl" not in doc and "maxwell" not in doc:
        raise InputError(f"{path}: JSON without a Prony table (neither the maxwell object of "
                         f"sweep fit-dma --json nor tau/E lists); accepted: {_ACCEPTED}")
    mx = doc.get("maxwell")
    if mx is None:
        m = doc.get("mpl") or {}
        consts = ", ".join(f"{k} = {m[k]:.6g}" for k in ("E0", "Einf", "n", "tau0")
                           if isinstance(m.get(k), (int, float)))
        raise InputError(f"{path}: holds only an MPL fit ({consts}), not a table: give the MPL "
                         f"as the material, or rerun sweep fit-dma with --maxwell N for an "
                         f"N-arm table")
    if not isinstance(mx, dict) or not all(k in mx for k in ("E0", "moduli", "times")):
        raise InputError(f"{path}: the maxwell object needs E0, moduli and times")
    where = f"{path} maxwell"
    E0 = _number(f"{where} E0", mx["E0"])
    if not E0 > 0.0:
        raise InputError(f"{where}: E0 (the relaxed modulus of the fit) must be > 0 (got {E0:g}; "
                         f"a fit without an equilibrium spring is a liquid)")
    tau = _numbers(f"{where} times", mx["times"])
    w = _numbers(f"{where} moduli", mx["moduli"])
    return _make("wiechert", tau, w, E0=E0, where=where, fmt="fit-dma", name=path.stem,
                 source=str(path), units_known=True)

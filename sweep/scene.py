"""Plain, serializable values that describe one simulation: ``Scene``, ``Numerics``, ``Result``.

Units are those of docs/design.md section 2 (see :mod:`sweep.units`):

* radii ``a0`` in ``a_ref = (pi R^2 dg / E0*)^(1/3)``;
* indentation ``delta0`` in ``d_ref = a_ref^2 / R`` (the paper's delta-hat);
* ``rate`` is the paper's r-hat = r tau0 / h0 (indenter speed in units of h0 per tau0);
* time in tau0; loads in pi dg R; crack speed in a_ref / tau0.

A ``Scene`` is the physics (what a user varies in a sweep), ``Numerics`` is how it is
discretized (what a user trades for speed). Both are frozen dataclasses of plain numbers
and strings, so they hash, pickle to workers and serialize to JSON/HDF5 unchanged.
All tunable numerical defaults live here, in :data:`PRESETS`, documented once.
"""
from __future__ import annotations

import dataclasses
import hashlib
import json
import math
import os
from dataclasses import dataclass, field
from functools import lru_cache
from types import MappingProxyType

import numpy as np

from .errors import InputError, check_choice, check_int, check_range

#: The named materials; a scene's material may also be a Prony table (:class:`SceneTable`).
MATERIALS = ("mpl", "sls")
#: the ``material`` value (and results column prefix) of a scene whose material is a table
TABLE_MATERIAL = "prony"
MESHES = ("uniform", "graded")
#: nodes of a uniform mesh whose ``Numerics.nodes`` is None (:attr:`Numerics.uniform_nodes`)
UNIFORM_NODES = 500
STOPS = ("pulloff", "separation")
#: Models a scene can ask for (sweep.engine.models maps each to its simulate function).
MODEL_NAMES = ("bem", "crack", "pb", "elastic", "auto")
#: Process-zone laws of the interface: none (the rate-independent work of adhesion dg) or
#: Gent-Schultz, Gamma_pz(v) = dg (1 + (v/pz_v0)^pz_xi) at crack speed v > 0
#: (:mod:`sweep.engine.crack_front`)
PZ_LAWS = ("none", "gent-schultz")
#: the Scene fields of a process zone's parameters (given exactly when ``pz_law`` is not none)
PZ_PARAMETERS = ("pz_v0", "pz_xi")
#: what the dwell of a test protocol holds (``dwell_hold``)
DWELL_HOLDS = ("force", "depth")


def axis(default=dataclasses.MISSING, *, help: str, unit: str = "", limits=None,
         lo_open: bool = False, choices=None, label: str = "", order: int,
         plot_group: bool = True, cli_default=None):
    """A Scene field with the metadata every other part of the package derives from.

    Parameters
    ----------
    default : optional
        The field's default (none: required; ``None``: optional, absent unless given).
    help : str
        One-line meaning (CLI help, docs).
    unit : str
        Unit of the value (docs/design.md section 2), "" if dimensionless.
    limits : (lo, hi), optional
        Accepted interval; ``lo_open`` excludes the lower end.
    choices : tuple of str, optional
        Accepted values of a categorical field.
    label : str
        Axis label for figures (matplotlib mathtext); default the name.
    order : int
        Position of the axis in the expansion of a config grid (the last one varies fastest).
    plot_group : bool
        Whether figures draw one line per value of this axis.
    cli_default : optional
        Default of ``sweep scene --<name>`` for a required field (a convenience of the CLI).
    """
    meta = {"help": help, "unit": unit, "limits": limits, "lo_open": lo_open,
            "choices": choices, "label": label, "order": order, "plot_group": plot_group,
            "cli_default": cli_default}
    return field(default=default, metadata={"axis": meta})


@dataclass(frozen=True)
class Protocol:
    """A test as the lab runs it: approach, dwell, retract (dimensionless, docs/design.md
    section 2; run by :mod:`sweep.engine.protocol`).

    Parameters
    ----------
    approach_rate : float
        The approach's r-hat, d delta/dt = approach_rate h0 (the unloading rate's units).
    preload : float
        The load (pi dg R, compressive positive) at the end of the approach; > 0.
    dwell : float
        The dwell's duration (tau0), >= 0.
    hold : {"force", "depth"}
        What the instrument holds during the dwell.
    """

    approach_rate: float
    preload: float
    dwell: float
    hold: str = "force"

    def __post_init__(self):
        check_range("approach_rate", self.approach_rate, lo=0.0, lo_open=True)
        check_range("preload", self.preload, lo=0.0, lo_open=True)
        check_range("dwell", self.dwell, lo=0.0)
        check_choice("dwell_hold", self.hold, DWELL_HOLDS)


def check_protocol(approach_rate, preload, dwell, dwell_hold) -> bool:
    """Whether the fields give a test protocol (approach, dwell, retract); InputError unless
    ``approach_rate``, ``preload`` and ``dwell`` are given together, or none of them (and
    ``dwell_hold`` then at its default)."""
    values = {"approach_rate": approach_rate, "preload": preload, "dwell": dwell}
    given = [k for k, v in values.items() if v is not None]
    if given and len(given) < len(values):
        missing = [k for k in values if k not in given]
        raise InputError(f"{'/'.join(missing)}: a protocol needs approach_rate, preload and "
                         f"dwell together (missing {', '.join(missing)})")
    if not given and dwell_hold != "force":
        raise InputError(f"dwell_hold: {dwell_hold!r} needs a protocol (approach_rate, preload, "
                         f"dwell); without one the scene starts relaxed")
    return bool(given)


def check_process_zone(pz_law, pz_v0, pz_xi, speed_unit: str) -> None:
    """InputError unless the process-zone parameters are given exactly with a law:
    ``pz_v0`` (a crack speed in ``speed_unit``) and ``pz_xi`` with a ``pz_law`` other than
    "none", neither without one (their ranges are checked on their own)."""
    values = {"pz_v0": pz_v0, "pz_xi": pz_xi}
    given = [p for p in PZ_PARAMETERS if values[p] is not None]
    if pz_law == "none" and given:
        raise InputError(f"{'/'.join(given)}: a process-zone parameter needs a pz_law "
                         f"({', '.join(PZ_LAWS[1:])}; got pz_law none)")
    if pz_law != "none" and len(given) < len(PZ_PARAMETERS):
        missing = [p for p in PZ_PARAMETERS if p not in given]
        raise InputError(f"{'/'.join(missing)}: pz_law {pz_law} needs pz_v0 > 0 "
                         f"({speed_unit}) and pz_xi > 0 (missing {', '.join(missing)})")


@dataclass(frozen=True, eq=False)
class SceneTable:
    """A Prony table as a scene's material, normalized (docs/design.md sections 3 and 7).

    Build it with :func:`scene_table` (or give the table to :class:`Scene` as its
    ``material``). The solvers read the Kelvin form in units of tau0; the scene id reads
    ``digest``, a hash of the table's numbers (not of its path or file format).

    Attributes
    ----------
    weights : tuple of float
        Kelvin weights ``c_i > 0`` with ``sum c_i < 1``:
        ``Chat(t) = 1 - sum_i c_i exp(-t/theta_i)``, ``k = 1 - sum c_i``.
    times : tuple of float
        Retardation times ``theta_i`` in units of tau0, ascending.
    tau0 : float
        The scene's time unit in the table's time unit (s where the table states its units):
        1 unless given (``{"prony": path, "tau0": ...}``).
    E0, Einf : float
        The table's relaxed and instantaneous moduli (Pa where it states its units).
    name : str
        The table's name (its file's stem, ``inline``, or the ``name`` given).
    digest : str
        16 hex digits: :meth:`sweep.materials.PronyTable.content_hash` of the table (with
        ``tau0`` where it is not 1): equal for the same table in every format, different
        when any of its numbers changes beyond 10 significant digits.
    units_known : bool
        Whether the table stated its units (moduli in Pa, times in s).
    spec : dict
        The table as an inline mapping that :func:`scene_table` reads back to the same
        digest (a config's ``to_dict``).
    """

    weights: tuple
    times: tuple
    tau0: float
    E0: float
    Einf: float
    name: str
    digest: str
    units_known: bool = False
    spec: dict = field(default_factory=dict, repr=False)

    def __eq__(self, other):
        return isinstance(other, SceneTable) and other.digest == self.digest

    def __hash__(self):
        return hash(self.digest)

    @property
    def k(self) -> float:
        """``1 - sum c_i`` = E0/Einf."""
        return float(1.0 - math.fsum(self.weights))

    @property
    def label(self) -> str:
        """``prony:<name>:<digest>``: the scene's ``material`` column in a results file."""
        return f"{TABLE_MATERIAL}:{self.name}:{self.digest}"

    def __str__(self):
        return self.label

    def __repr__(self):
        return (f"SceneTable({self.label}, k={self.k:.6g}, {len(self.weights)} terms, "
                f"tau0={self.tau0:g})")

    def __format__(self, spec):
        return format(self.label, spec)

    def fixed_k(self, k, default) -> float:
        """The scene's k: the table's; InputError if ``k`` is given (not ``default``) and
        differs from it by more than 1e-9 relative."""
        mine = self.k
        if k is not None and k != default:
            k = check_range("k", k, 0.0, 1.0, lo_open=True)
            if not math.isclose(k, mine, rel_tol=1e-9):
                raise InputError(f"k: the Prony table {self.name} fixes k = E0/Einf = "
                                 f"{mine:.10g}; leave k out (got {k:g})")
        return mine


def check_material_name(name: str) -> str:
    """``name`` if it names a material (:data:`MATERIALS`); else InputError (one line, saying
    how a Prony table is given: a plain string is never read as a file's path)."""
    if name not in MATERIALS:
        raise InputError(f"material must be {', '.join(MATERIALS)} or a Prony table: a file "
                         "as {'prony': path} or a pathlib.Path, inline as {'tau': [...], "
                         f"'E': [...], 'E0': ...}} (got {name!r})")
    return name


def scene_table(value, *, base_dir=None, nu=None) -> SceneTable:
    """The :class:`SceneTable` of a table: a :class:`SceneTable`, a
    :class:`~sweep.materials.PronyTable`, a file's path (path-like) or a mapping
    :func:`~sweep.materials.read_prony` reads (``{"prony": path, ...}`` or inline ``{"tau": [...], "E": [...], "E0": ...}``),
    with an optional ``"tau0"`` key (the scene's time unit in the table's, s where the table
    states its units (it was converted to s), > 0, default 1).

    ``base_dir`` resolves a relative path (default the working directory); ``nu`` reads a
    shear table. InputError (one line) for anything else or a bad table.
    """
    if isinstance(value, SceneTable):
        return value
    from .materials import PronyTable, read_prony  # lazy: sweep.materials loads numba

    tau0 = 1.0
    if isinstance(value, dict) and "tau0" in value:
        value = dict(value)
        tau0 = check_range("tau0", value.pop("tau0"), 0.0, lo_open=True)
    if isinstance(value, (dict, os.PathLike)):
        value = read_prony(value, base_dir=base_dir, nu=nu)
    if not isinstance(value, PronyTable):
        raise InputError(f"material must be {', '.join(MATERIALS)} or a Prony table "
                         f"({{prony: file}} or {{tau: [...], E: [...], E0: ...}}) "
                         f"(got {value!r})")
    mat = value.material
    c, theta = mat.kelvin_weights, mat.kelvin_times / tau0
    keep = c > 0.0
    order = np.argsort(theta[keep], kind="stable")
    digest = value.content_hash()
    if tau0 != 1.0:
        digest = hashlib.sha256(f"{digest};tau0={tau0:.9e}".encode()).hexdigest()[:16]
    col = "E" if value.form == "wiechert" else "c"
    # both moduli as read, so that the spec reads back to the same numbers, E0 to the last
    # digit (derived from Einf, a Wiechert table's E0 moved by one: an SI scene's mu, its id)
    spec = {"form": value.form, "tau": value.times.tolist(), col: value.weights.tolist(),
            "E0": float(value.E0), "Einf": float(value.Einf), "recorded": True,
            "name": value.name}
    if value.modulus_unit is not None:
        spec.update(modulus_unit=value.modulus_unit, time_unit=value.time_unit)
    if tau0 != 1.0:
        spec["tau0"] = tau0
    return SceneTable(weights=tuple(c[keep][order].tolist()),
                      times=tuple(theta[keep][order].tolist()), tau0=float(tau0),
                      E0=float(value.E0), Einf=float(value.Einf), name=value.name,
                      digest=digest, units_known=value.modulus_unit is not None, spec=spec)


@dataclass(frozen=True, kw_only=True)
class Scene:
    """One unloading experiment of a rigid sphere from a fully relaxed half-space.

    Parameters
    ----------
    n : float
        MPL exponent (spectrum broadness), in (0, 5]. Ignored for ``material="sls"``
        (kept for bookkeeping).
    k : float
        Ratio of relaxed to glassy modulus E0/Einf, in (0, 1]; ``k = 1`` is elastic.
    mu : float
        Tabor parameter (R dg^2 / (E0*^2 h0^3))^(1/3), in [0.01, 1e6]: the hereditary BEM
        takes [0.01, 100] (sweep.engine.problem.BEM_MU_RANGE; above about 8 on a mesh that follows
        the crack tip, :mod:`sweep.engine.tip_following`), the elastic branch is validated up to
        100, the crack-front model (the mu -> infinity limit: large contacts against l0, e.g.
        the paper's PDMS at mu = 103, or mu in the thousands from a physical h0 of a few
        angstroms) and the pb model take the whole range; "auto" sends a scene beyond the
        BEM's range to the crack-front model and says so in the row's reason.
    rate : float
        Dimensionless unloading rate r-hat = r tau0 / h0, in (0, 1e12].
    a0 : float, optional
        Initial contact radius (max-tension radius, gap = 3^(1/6) h0) of the relaxed
        state, in a_ref units. Give exactly one of ``a0`` and ``delta0``.
    delta0 : float, optional
        Initial indentation in d_ref units (delta-hat). In units of h0 it is
        ``delta0 / h0_hat(mu)`` (see :func:`sweep.units.delta0_from_h0_units`).
    material : {"mpl", "sls"} or a Prony table
        "mpl": MPL retardation spectrum, Chat = 1 - (1-k) 2 t^(n/2) K_n(2 sqrt t)/Gamma(n);
        "sls": standard linear solid, Chat = 1 - (1-k) exp(-t);
        a Prony table (a :class:`~sweep.materials.PronyTable`, a file that
        :func:`~sweep.materials.read_prony` reads given as ``{"prony": path}`` or a
        :class:`pathlib.Path` (a plain string names "mpl" or "sls" only), or an inline
        ``{"tau": [...], "E": [...], "E0": ...}``, optionally with ``"tau0"``, the time unit
        of the scene in the table's time unit, s where the table states its units, default
        1), normalized on construction into a
        :class:`SceneTable`: Chat = 1 - sum c_i exp(-t/theta_i). The table fixes k (a k other
        than the default 0.1 must equal it) and n is unused, as for "sls".
    stop : {"pulloff", "separation"}
        Stop right after the load minimum has passed and recovered ("pulloff"), or follow
        the whole curve until the contact is lost ("separation").
    model : {"bem", "crack", "pb", "elastic", "auto"}
        Which model runs the scene (:mod:`sweep.engine.models`): the BEM (default), the crack-front
        model, the paper's closed-form PB estimate, the quasi-static elastic branch (k = 1), or
        "auto" (the cheapest whose measured error meets ``pull_off_rtol``, else the BEM, and the
        crack-front model where the BEM fails for a reason it lifts: docs/models.md);
        ``Result.model_used`` records it.
    pz_law : {"none", "gent-schultz"}
        Rate-dependent process zone of the interface: "none" (default; the work of adhesion
        dg is rate independent, the BEM's Lennard-Jones law) or "gent-schultz",
        Gamma_pz(v) = dg (1 + (v/pz_v0)^pz_xi) at an opening crack speed v > 0 and dg at
        v <= 0. The crack-front model multiplies it with the bulk's Persson-Brener factor
        (:mod:`sweep.engine.crack_front`); the BEM runs it as a local law on the opening
        rate (:mod:`sweep.engine.process_zone`); the pb estimate refuses it, "auto" runs the
        crack-front model and the BEM where that row's error misses ``pull_off_rtol``.
    pz_v0 : float, optional
        Crack speed at which the process zone doubles the work of adhesion, in a_ref/tau0
        (the crack-speed unit of docs/design.md section 2), > 0; given exactly when
        ``pz_law`` is not "none".
    pz_xi : float, optional
        Exponent of the Gent-Schultz law, in (0, 10]; given exactly when ``pz_law`` is not
        "none".
    approach_rate, preload, dwell : float, optional
        A test protocol, given together (:mod:`sweep.engine.protocol`): the scene starts at
        first contact (neither ``a0`` nor ``delta0``), approaches at d delta/dt =
        approach_rate h0 until the load is ``preload`` (pi dg R), dwells for ``dwell``
        (tau0), then retracts at ``rate``. Only the BEM runs it.
    dwell_hold : {"force", "depth"}
        What the dwell holds: the load at ``preload`` (default) or the indentation.
    machine_stiffness : float, optional
        Stiffness K of the machine in series with the sphere (its force sensor), in pi dg R
        per d_ref, > 0; None (default) is a rigid machine. The machine drives its own
        displacement D at the unloading rate, dD/dt = -rate h0, and the sphere's indentation
        is delta = D - P/K (docs/design.md, "Machine compliance"). Only the BEM runs it.
    """

    n: float = axis(help="MPL exponent (spectrum broadness); unused by sls", limits=(0.0, 5.0),
                    lo_open=True, label="$n$", order=2, cli_default=0.8)
    k: float = axis(0.1, help="E0/Einf, relaxed over glassy modulus; 1 is elastic",
                    limits=(0.0, 1.0), lo_open=True, label="$k$", order=3)
    mu: float = axis(3.24, help="Tabor parameter (the hereditary BEM 0.01-100, on a "
                     "tip-following mesh where its fixed crack band exceeds max_nodes; "
                     "elastic scenes (k = 1) up to 100; the crack-front model, the mu -> "
                     "infinity limit, and the pb model the whole range: auto sends a scene "
                     "beyond the BEM's range to the crack-front model)", limits=(0.01, 1e6),
                     label=r"$\mu$", order=4)
    rate: float = axis(help="unloading rate r-hat = r tau0 / h0", limits=(0.0, 1e12),
                       lo_open=True, label=r"unloading rate $\hat r = r\tau_0/h_0$", order=7,
                       plot_group=False)
    a0: float | None = axis(None, help="initial contact radius (max-tension radius); give a0 "
                            "or delta0", unit="a_ref", limits=(0.3, 50.0), label=r"$\hat a_0$",
                            order=5)
    delta0: float | None = axis(None, help="initial indentation; alternative to a0",
                                unit="d_ref", limits=(-5.0, 2500.0), label=r"$\hat\delta_0$",
                                order=6)
    material: str = axis("mpl", help="creep compliance: MPL retardation spectrum, SLS, or a "
                         "Prony table ({prony: file} or inline; k from the table, n unused)",
                         choices=MATERIALS, order=0)
    stop: str = axis("pulloff", help="stop after the pull-off, or follow the curve to "
                     "separation", choices=STOPS, order=1, plot_group=False)
    model: str = axis("bem", help="model that runs the scene (sweep.engine.models) and the "
                      "ranges it accepts: bem, the BEM (mu 0.01-100); crack, the crack-front "
                      "model, the mu -> infinity limit (any mu, a0 >= 0.5); pb, the "
                      "closed-form PB estimate (every scene); elastic, the quasi-static "
                      "elastic branch (k = 1, mu 0.01-100); auto, the cheapest whose measured "
                      "error meets pull_off_rtol (every scene)",
                      choices=MODEL_NAMES, order=-1)
    pz_law: str = axis("none", help="rate-dependent process zone: none (rate-independent dg, "
                       "the LJ law) or gent-schultz, Gamma_pz(v) = dg (1 + (v/pz_v0)^pz_xi) "
                       "(models bem, crack and auto; pb and elastic refuse it)", choices=PZ_LAWS,
                       order=-4)
    pz_v0: float | None = axis(None, help="process zone: crack speed at which it doubles the "
                               "work of adhesion (with pz_law gent-schultz)",
                               unit="a_ref/tau0", limits=(0.0, 1e30), lo_open=True,
                               label=r"$v_0$", order=-3)
    pz_xi: float | None = axis(None, help="process zone: exponent of Gamma_pz(v) (with pz_law "
                               "gent-schultz)", limits=(0.0, 10.0), lo_open=True,
                               label=r"$\xi$", order=-2)
    approach_rate: float | None = axis(None, help="protocol: approach rate r-hat, d delta/dt "
                                       "= approach_rate h0 (with preload and dwell; the "
                                       "scene then starts at first contact, neither a0 nor "
                                       "delta0)", limits=(0.0, 1e12), lo_open=True,
                                       label=r"approach rate $\hat r_a$", order=-9)
    preload: float | None = axis(None, help="protocol: the load at the end of the approach "
                                 "(sweep scene --si: newtons, and without --dwell the "
                                 "relaxed contact at that load)", unit="pi dg R",
                                 limits=(0.0, 1e6), lo_open=True, label=r"$\hat P_0$",
                                 order=-8)
    dwell: float | None = axis(None, help="protocol: the dwell after the approach",
                               unit="tau0", limits=(0.0, 1e15), label=r"dwell $\hat t_d$",
                               order=-7)
    dwell_hold: str = axis("force", help="protocol: what the dwell holds, the load (force) or "
                           "the indentation (depth)", choices=DWELL_HOLDS, order=-6)
    machine_stiffness: float | None = axis(None, help="stiffness of the machine (force "
                                           "sensor) in series with the sphere: the machine "
                                           "drives D(t), the sphere's indentation is D - P/K "
                                           "(none: a rigid machine; models bem and auto)",
                                           unit="pi dg R/d_ref", limits=(0.0, 1e30),
                                           lo_open=True, label=r"$\hat K$", order=-5)

    def __post_init__(self):
        info = _axes_of(type(self))
        protocol = check_protocol(self.approach_rate, self.preload, self.dwell, self.dwell_hold)
        table = None
        if isinstance(self.material, str):
            check_material_name(self.material)
        else:
            table = scene_table(self.material)
            object.__setattr__(self, "material", table)
            object.__setattr__(self, "k", table.fixed_k(self.k, info["k"].default))
        for f in dataclasses.fields(self):
            if f.name == "a0" and not protocol and (self.a0 is None) == (self.delta0 is None):
                raise InputError("a0/delta0: give exactly one of a0 (initial contact radius) "
                                 "and delta0 (initial indentation)")
            if f.name == "a0" and protocol and (self.a0, self.delta0) != (None, None):
                raise InputError("a0/delta0: a scene with a protocol (approach_rate, preload, "
                                 "dwell) starts at first contact: give neither a0 nor delta0")
            if f.name == "material" and table is not None:
                continue
            object.__setattr__(self, f.name, info[f.name].check(getattr(self, f.name)))
        check_process_zone(self.pz_law, self.pz_v0, self.pz_xi, "a_ref/tau0")
        if protocol and self.machine_stiffness is not None:
            raise InputError("machine_stiffness: a compliant machine runs the unloading from a "
                             "relaxed contact (a0 or delta0), not a test protocol (approach_rate, "
                             "preload, dwell); leave one of them unset")

    def protocol(self) -> "Protocol | None":
        """The test protocol (:class:`Protocol`), or None for the relaxed start."""
        if self.dwell is None:
            return None
        return Protocol(self.approach_rate, self.preload, self.dwell, self.dwell_hold)

    @property
    def table(self) -> "SceneTable | None":
        """The scene's Prony table (None for "mpl" and "sls")."""
        return self.material if isinstance(self.material, SceneTable) else None

    def to_dict(self) -> dict:
        """The fields as plain values; a table material as its label
        (:attr:`SceneTable.label`, ``prony:<name>:<hash>``: the results column)."""
        d = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        if self.table is not None:
            d["material"] = self.table.label
        return d

    @classmethod
    def from_dict(cls, d: dict) -> "Scene":
        names = {f.name for f in dataclasses.fields(cls)}
        unknown = set(d) - names
        if unknown:
            raise InputError(f"scene: unknown key(s) {', '.join(sorted(unknown))} "
                             f"(allowed: {', '.join(sorted(names))})")
        if str(d.get("material", "")).startswith(f"{TABLE_MATERIAL}:"):
            raise InputError(f"material: {d['material']} is a table's label (a results row); "
                             f"give the table itself ({{prony: file}} or inline)")
        return cls(**d)


@dataclass(frozen=True)
class Axis:
    """What a Scene field is, read from its :func:`axis` metadata (see there)."""

    name: str
    default: object
    required: bool
    help: str
    unit: str
    limits: tuple | None
    lo_open: bool
    choices: tuple | None
    label: str
    order: int
    plot_group: bool
    cli_default: object

    @property
    def numeric(self) -> bool:
        return self.choices is None

    def check(self, value):
        """The validated value (float for numeric axes; None passes for optional ones)."""
        if self.choices is not None:
            return check_choice(self.name, value, self.choices)
        if value is None and not self.required:
            return None
        lo, hi = self.limits if self.limits else (None, None)
        return check_range(self.name, value, lo, hi, lo_open=self.lo_open)

    def allowed(self) -> str:
        """The accepted values in words: ``(0, 5]``, ``mpl, sls``."""
        if self.choices is not None:
            return ", ".join(self.choices)
        lo, hi = self.limits
        return f"{'(' if self.lo_open else '['}{lo:g}, {hi:g}]"

    def describe(self) -> str:
        """``help (unit); allowed`` (CLI help and docs)."""
        unit = f" ({self.unit} units)" if self.unit else ""
        return f"{self.help}{unit}; {self.allowed()}"


@lru_cache(maxsize=None)
def _axes_of(cls) -> dict:
    out = {}
    for f in dataclasses.fields(cls):
        m = f.metadata["axis"]
        required = f.default is dataclasses.MISSING
        out[f.name] = Axis(name=f.name, default=None if required else f.default,
                           required=required, help=m["help"], unit=m["unit"],
                           limits=m["limits"], lo_open=m["lo_open"], choices=m["choices"],
                           label=m["label"] or f.name, order=m["order"],
                           plot_group=m["plot_group"], cli_default=m["cli_default"])
    return out


#: The scene parameters, in field order (n, k, mu, rate, a0, delta0, material, stop): the
#: grid axes of a config, the scene columns of a results file, the options of `sweep scene`.
AXES: dict[str, Axis] = _axes_of(Scene)
#: Their names, in field order.
SCENE_AXES = tuple(AXES)
#: Physical ranges accepted by :class:`Scene` (derived from the field metadata).
SCENE_LIMITS = {a.name: a.limits for a in AXES.values() if a.limits}


#: Named numerical presets. Each is a complete set of :class:`Numerics` fields.
#: Their measured error and cost are in the README ("Speed and accuracy"). The Newton
#: tolerance of fast and balanced, 1e-6 h0: on the v0.1 threshold grid at balanced it moves
#: the pull-offs by at most 2.2e-5 (median 4e-8) and the crack speeds by 6.8e-4 against
#: 1e-7, for 82 % of the Newton iterations (session 25). Each preset is
#: the cheapest numerics of the measured trade (``make tradeoff``, results/tradeoff/) whose
#: worst pull-off error over its scenes meets the preset's target
#: (``sweep.bench.tradeoff.PRESET_TARGETS``: 5e-3, 1e-3, 1e-4) and whose worst crack-speed
#: error meets ``CRACK_SPEED_TARGETS`` (1e-2, 5e-3, 1e-3), among those carrying the error
#: estimate and not refused on scenes beyond the three (``REFUSED_BEYOND_THE_SCENES``: the
#: error-coverage sample of ``make error-coverage``, the paper scene): accurate's
#: previous finer steps and Newton tolerance (step 0.05, da_max 0.25, tol 1e-9) cost 2.6
#: times as much for no smaller error; its grading 1.05 stays, for at 1.1 low-mu scenes of
#: the sample had errors (1-2e-5) that the estimate, whose coarser solve has the same
#: grading, did not cover (issue 24 item 5). Balanced bounds the crack tip's motion by a
#: spacing per step and by 0.6 near the pull-off (``da_max_pulloff``, where the crack
#: speed is read): the v0.1 threshold grid at balanced took 50 s instead of 60 s, every
#: pull-off within its row's error estimate of the previous da_max 0.6 throughout, crack
#: speeds within 3e-3 (docs/performance.md, issue 24 item 1). The larger indentation steps
#: that are cheaper on the tradeoff's three scenes (balanced 0.2 h0, fast 0.5 h0) are
#: refused on scenes beyond them (``tradeoff.REFUSED_BEYOND_THE_SCENES``, session 25).
#: (read-only: a preset is changed by overrides, ``Numerics.preset("fast", step=0.5)``)
PRESETS = MappingProxyType({name: MappingProxyType(values) for name, values in {
    "fast": dict(mesh="graded", band_resolution=9.0, grading=1.1, step=0.25, da_max=1.0,
                 prony_rtol=1e-3, tol=1e-6, pull_off_rtol=0.03, max_nodes=400),
    "balanced": dict(mesh="graded", band_resolution=16.0, grading=1.1, step=0.1, da_max=1.0,
                     da_max_pulloff=0.6, prony_rtol=1e-4, tol=1e-6, pull_off_rtol=0.01,
                     max_nodes=1000),
    "accurate": dict(mesh="graded", band_resolution=36.0, grading=1.05, step=0.2, da_max=0.6,
                     prony_rtol=1e-6, tol=1e-7, pull_off_rtol=0.003, max_nodes=2500),
}.items()})


#: the most refinements a scene may ask for
MAX_REFINEMENTS = 6
#: refinements of :meth:`Numerics.for_tolerance` (an accuracy asked for, not a preset)
REFINEMENTS_ON_REQUEST = 3
#: the node cap of an accuracy asked for (:meth:`Numerics.for_tolerance`) where the request
#: gives none: the finest preset's, whatever preset it starts from, for its refinements reach
#: the finer presets' resolutions (a request of 3e-2 starting from fast's max_nodes 400 could
#: not refine a small contact whose relaxed start the fast mesh cannot hold: n 0.3724,
#: k 0.001749, mu 9.684, a0 0.6012, rate 0.0012 needs a 523-node window at band resolution 18)
REQUEST_MAX_NODES = max(p["max_nodes"] for p in PRESETS.values())
#: numerics given by these keys alone, ``pull_off_rtol`` among them, ask for an accuracy:
#: :meth:`Numerics.from_dict` resolves them with :meth:`Numerics.for_tolerance`
TOLERANCE_REQUEST_KEYS = frozenset({"pull_off_rtol", "time_budget_s", "max_nodes", "max_steps",
                                    "refinements"})


def preset_for_tolerance(pull_off_rtol: float) -> str:
    """The cheapest preset whose own ``pull_off_rtol`` is at most ``pull_off_rtol`` (the
    finest, "accurate", below all of them: its refinements do the rest)."""
    fits = [name for name in ("fast", "balanced", "accurate")
            if PRESETS[name]["pull_off_rtol"] <= pull_off_rtol]
    return fits[0] if fits else "accurate"


@dataclass(frozen=True, kw_only=True)
class Numerics:
    """Discretization and solver settings of one scene.

    Parameters
    ----------
    nodes : int or None
        Number of mesh nodes N (node 0 at r = 0), in [20, 5000]. Uniform mesh: ``None``
        means 500 (:attr:`uniform_nodes`). Graded mesh: ``None`` (default of the presets) sizes the mesh from
        ``band_resolution``; a number gives the graded mesh of that many nodes (its fine
        spacing follows).
    mesh : {"uniform", "graded"}
        "uniform": equal spacing from 0 to the domain. "graded" (the presets): fine spacing
        across the crack band the tip sweeps (from just outside the initial contact radius
        down to below the pull-off radius), element lengths growing by ``grading`` per
        element inside the contact and outside it (see :mod:`sweep.engine.mesh`).
    band_resolution : float
        Graded mesh: node spacings per process zone l0 = 1.693/mu^2 a_ref in the crack band
        (the fine spacing is l0 / band_resolution).
    grading : float
        Graded mesh: growth factor of neighbouring element lengths outside the band, in
        [1, 1.5].
    max_nodes : int
        Largest graded mesh accepted; a scene whose crack band needs more nodes (large a0
        at a large Tabor parameter) is refused with the count it needs.
    pull_off_rtol : float
        Tolerance of the error estimate ``Result.error_estimate``: the pull-off change
        against a solve at half the resolution in space and time (half the band resolution
        or nodes, twice the step; sqrt 2 where that mesh cannot hold the initial contact)
        over (factor^0.65 - 1), plus the Prony fit's error (:mod:`sweep.engine.resolution`). A
        result whose estimate exceeds the tolerance is not ``ok`` (``failed``, reason
        "unresolved: ..."); "auto" also runs a cheaper model where its measured error meets
        it. 0 skips the estimate and its second solve (then ``error_estimate`` is NaN).
    domain : float or None
        Mesh radius in a_ref units. ``None`` (default) chooses it from the scene: large
        enough that the gap at the mesh edge is ``tail_gap`` h0 at the start of unloading;
        the Lennard-Jones attraction beyond the edge is added to the load in closed form
        (the gap continued rigidly: :func:`sweep.kernels.interface.tail_load`).
    tail_gap : float
        Gap at the mesh edge, in units of h0, used by the automatic domain (>= 10).
    lj_tail : bool
        Add the Lennard-Jones attraction beyond the BEM's mesh edge to every load the BEM
        forms (default True; :func:`sweep.kernels.interface.tail_load`). False drops it: the
        truncated model of the results computed before it (session 49), for comparisons
        with references that drop it too (its pull-off is low by about (h0/h_edge)^2, 2.8e-4
        at the relaxed limit at ``tail_gap`` 60). The elastic branch (``model="auto"`` at
        k = 1, :mod:`sweep.engine.quasistatic`) always has the tail.
    step : float
        Largest indentation step, in units of h0, where the crack tip moves or the load
        evolves fast (the adaptive step exceeds it, up to 8 times, only where the
        predictor's load error is below 1e-3: sweep.engine.bem.STEP_TOL).
    min_step : float
        Smallest indentation step in units of h0 before a run is declared failed.
    da_max : float
        Largest change of the contact radius per step, in node spacings.
    da_max_pulloff : float or None
        Largest change of the contact radius per step, in node spacings, once the load
        minimum is near (the first two steps, where a contact that starts at or beyond its
        pull-off reads its crack speed; the load rose over the last step; or the minimum
        predicted from the last three records lies within
        ``sweep.engine.bem.PULLOFF_ZONE_SPACINGS`` spacings of crack-tip travel,
        ``kernels.solve.near_pulloff``): the records the crack speed at pull-off is read
        from are as dense as at this value, while the crack's travel before runs at
        ``da_max``. ``None`` (default): ``da_max`` throughout.
    prony_rtol : float
        Maximum relative error of the Prony approximation of Chat over the scene's time
        window (ignored with ``exact=True``).
    tol : float
        Newton tolerance on the gap, in units of h0 (max norm of the residual; computed, or
        predicted below a tenth of it from the measured contraction of the iteration,
        ``kernels.solve.PREDICTED_RESIDUAL``).
    max_steps : int
        Hard cap on the number of time steps (a run that hits it is ``failed``).
    time_budget_s : float
        Wall-time budget of one scene, in seconds (0: none). A run that exceeds it ends
        ``failed`` with reason "time budget ..." and what it would need, rather than
        thrashing; the budget is checked between chunks of time steps.
    exact : bool
        Use the exact hereditary integral (integrated compliance, O(steps^2 N)) instead
        of the Prony recursion. For validation on small problems. It marches fixed
        indentation steps of ``step`` h0, without the Prony run's control of the contact
        radius's change per step (``da_max``): compare the two at a step fine enough that
        the exact row no longer moves (docs/scenes.md).
    zone_nodes : float
        Fewest node spacings across the cohesive (process) zone, l0 = 1.693/mu^2 a_ref
        (docs/design.md section 2). A coarser mesh traps the crack tip between nodes (jagged
        P(t), spurious minima, failed Newton solves), so such a scene is refused with a
        ``failed`` status that says how many nodes it needs.
    refinements : int
        How many times the BEM (or the elastic branch) may solve a scene again at a finer
        resolution where its error estimate exceeds ``pull_off_rtol`` (0: never; the row is
        then "unresolved"). Each
        refinement divides the spacing and the indentation step by the factor the estimate
        asks for (its second-order convergence, between sqrt 2 and 2) and the Prony
        tolerance by 10 where the Prony error takes half the tolerance
        (:func:`sweep.engine.resolution.refined`), within ``max_nodes`` and the time budget.
        The row records what it took (``Result.refinements``, ``band_resolution_used``,
        ``step_used``). :meth:`for_tolerance` sets it.
    """

    nodes: int | None = None
    domain: float | None = None
    tail_gap: float = 60.0
    step: float = 0.1
    min_step: float = 1e-4
    da_max: float = 0.5
    prony_rtol: float = 1e-4
    tol: float = 1e-8
    max_steps: int = 200_000
    exact: bool = False
    zone_nodes: float = 2.0
    mesh: str = "uniform"
    band_resolution: float = 16.0
    grading: float = 1.1
    max_nodes: int = 2000
    pull_off_rtol: float = 0.02
    time_budget_s: float = 300.0
    da_max_pulloff: float | None = None
    refinements: int = 0
    lj_tail: bool = True

    def __post_init__(self):
        set_ = lambda name, v: object.__setattr__(self, name, v)  # noqa: E731
        if self.nodes is not None:
            set_("nodes", check_int("nodes", self.nodes, 20, 5000))
        check_choice("mesh", self.mesh, MESHES)
        set_("band_resolution", check_range("band_resolution", self.band_resolution, 2.0, 500.0))
        set_("grading", check_range("grading", self.grading, 1.0, 1.5))
        set_("max_nodes", check_int("max_nodes", self.max_nodes, 20, 20000))
        set_("pull_off_rtol", check_range("pull_off_rtol", self.pull_off_rtol, 0.0, 1.0))
        if self.domain is not None:
            set_("domain", check_range("domain", self.domain, 0.5, 500.0))
        set_("tail_gap", check_range("tail_gap", self.tail_gap, 10.0, 1e5))
        set_("step", check_range("step", self.step, 1e-4, 10.0))
        set_("min_step", check_range("min_step", self.min_step, 1e-9, self.step))
        set_("da_max", check_range("da_max", self.da_max, 0.01, 1e9))
        if self.da_max_pulloff is not None:
            set_("da_max_pulloff", check_range("da_max_pulloff", self.da_max_pulloff, 0.01, 1e9))
        set_("prony_rtol", check_range("prony_rtol", self.prony_rtol, 1e-9, 0.1))
        set_("tol", check_range("tol", self.tol, 1e-14, 1e-3))
        set_("max_steps", check_int("max_steps", self.max_steps, 10, 10_000_000))
        set_("time_budget_s", check_range("time_budget_s", self.time_budget_s, 0.0, 1e7))
        if not isinstance(self.exact, (bool, np.bool_)):
            raise InputError(f"exact must be true or false (got {self.exact!r})")
        set_("exact", bool(self.exact))
        if not isinstance(self.lj_tail, (bool, np.bool_)):
            raise InputError(f"lj_tail must be true or false (got {self.lj_tail!r})")
        set_("lj_tail", bool(self.lj_tail))
        set_("zone_nodes", check_range("zone_nodes", self.zone_nodes, 0.0, 100.0))
        set_("refinements", check_int("refinements", self.refinements, 0, MAX_REFINEMENTS))

    @property
    def uniform_nodes(self) -> int:
        """Nodes of the uniform mesh: ``nodes``, or :data:`UNIFORM_NODES` when unset (the one
        place that resolves ``nodes=None`` on a uniform mesh, e.g. numerics given by fields
        without a preset)."""
        return self.nodes if self.nodes is not None else UNIFORM_NODES

    @classmethod
    def for_tolerance(cls, pull_off_rtol: float, **overrides) -> "Numerics":
        """Numerics that deliver a pull-off within ``pull_off_rtol`` (relative, as the
        row's ``error_estimate`` measures it) at the least cost: the cheapest preset whose
        own tolerance meets it (:func:`preset_for_tolerance`; the presets are the measured
        front of ``make tradeoff``), with ``pull_off_rtol`` and up to
        :data:`REFINEMENTS_ON_REQUEST` refinements where a scene's estimate says no, within
        :data:`REQUEST_MAX_NODES` nodes unless ``max_nodes`` is given.

        Parameters
        ----------
        pull_off_rtol : float
            Relative pull-off tolerance, in (0, 1].
        **overrides
            Other :class:`Numerics` fields (``time_budget_s``, ``max_nodes``, ...).
        """
        rtol = check_range("pull_off_rtol", pull_off_rtol, 0.0, 1.0, lo_open=True)
        fields = {"pull_off_rtol": rtol, "refinements": REFINEMENTS_ON_REQUEST,
                  "max_nodes": REQUEST_MAX_NODES, **overrides}
        return cls.preset(preset_for_tolerance(rtol), **fields)

    @classmethod
    def preset(cls, name: str = "balanced", **overrides) -> "Numerics":
        """Numerics of a named preset ("fast", "balanced", "accurate"), with overrides (an
        unknown one: InputError naming the allowed fields, as :meth:`from_dict`)."""
        check_choice("preset", name, PRESETS)
        names = {f.name for f in dataclasses.fields(cls)}
        unknown = set(overrides) - names
        if unknown:
            raise InputError(f"numerics: unknown key(s) {', '.join(sorted(unknown))} "
                             f"(allowed: {', '.join(sorted(names))})")
        return cls(**{**PRESETS[name], **overrides})

    def to_dict(self) -> dict:
        return dataclasses.asdict(self)

    @classmethod
    def from_dict(cls, d: dict) -> "Numerics":
        d = dict(d)
        names = {f.name for f in dataclasses.fields(cls)}
        preset = d.pop("preset", None)
        unknown = set(d) - names
        if unknown:
            raise InputError(f"numerics: unknown key(s) {', '.join(sorted(unknown))} "
                             f"(allowed: preset, {', '.join(sorted(names))})")
        if preset is not None:
            return cls.preset(preset, **d)
        if "pull_off_rtol" in d and set(d) <= TOLERANCE_REQUEST_KEYS:
            return cls.for_tolerance(d.pop("pull_off_rtol"), **d)
        return cls(**d)


#: Version of the id form below. Version 1: the JSON of ``{"scene": ..., "numerics": ...}``
#: with every field of :data:`ID_V1_FIELDS` and, of fields added since, those not at their
#: default. A change of the form itself (not the addition of a defaulted field, which keeps
#: every id) must raise this number and teach :mod:`sweep.campaign.store` to migrate older files.
SCENE_ID_VERSION = 1

#: Revision of the engine's numbers for an unchanged scene id, recorded in every results row
#: (column ``engine_revision``; rows written before it have none: revision 1). Revision 1:
#: the hereditary BEM's load left out the Lennard-Jones attraction beyond its mesh
#: (visco-sweep 0.2.0 and earlier); revision 2: that tail is in every load
#: (``Numerics.lj_tail``), pull-offs up to about 3e-4 higher (docs/design.md, "Meshes");
#: revision 3: an unloading whose Prony recursion would ring starts with a lead-in
#: (:func:`sweep.engine.bem.ringing_lead_in`; docs/design.md section 4). Raise it, and say what changed in :data:`REVISION_CHANGES`, where the numbers of unchanged
#: ids move by design; resuming a file with rows of an earlier revision says so.
ENGINE_REVISION = 3

#: What each earlier engine revision computed otherwise than :data:`ENGINE_REVISION`
REVISION_CHANGES = {
    1: "loads without the Lennard-Jones tail beyond the mesh: pull-offs lower, by up to about "
       "3e-4 on the default domain; and revision 2's start",
    2: "unloadings whose Prony recursion rings (a small k with a narrow spectrum, or an SLS) "
       "started without a lead-in: their first steps' load alternated, and a pull-off could "
       "be read at its first dip; every other scene is the same",
}

#: The fields of Scene and Numerics when ids were introduced (version 1). They are always
#: part of the id, so that the ids of files written then stay what they were.
ID_V1_FIELDS = {
    "scene": ("n", "k", "mu", "rate", "a0", "delta0", "material", "stop"),
    "numerics": ("nodes", "domain", "tail_gap", "step", "min_step", "da_max", "prony_rtol",
                 "tol", "max_steps", "exact", "zone_nodes"),
}


def _canonical(obj) -> str:
    def norm(v):
        if isinstance(v, float):
            return float(repr(v)) if math.isfinite(v) else str(v)
        if isinstance(v, dict):
            return {k: norm(x) for k, x in v.items()}
        return v
    return json.dumps(norm(obj), sort_keys=True, separators=(",", ":"))


def id_form(obj, always=()) -> dict:
    """The fields of a Scene or Numerics that enter its id.

    Every field named in ``always`` (the version-1 fields), and any other field whose value
    differs from its declared default: a field added later with a default therefore leaves
    the ids of all existing scenes unchanged. Never change such a field's default (the old
    default would then be read as the new one); add a field instead.
    """
    out = {}
    for f in dataclasses.fields(obj):
        value = getattr(obj, f.name)
        if f.name in always or f.default is dataclasses.MISSING or value != f.default:
            out[f.name] = value
    return out


def scene_id(scene: Scene, numerics: Numerics) -> str:
    """Stable id of a (scene, numerics) pair: 16 hex digits of the SHA-1 of canonical JSON.

    The same parameters always map to the same id (sorted keys, repr'd floats), which
    makes resume and de-duplication of sweeps trivial. The hashed form is that of
    :data:`SCENE_ID_VERSION` (see :func:`id_form`): adding a field with a default to Scene or
    Numerics renames no scene, so existing results files keep resuming. A scene whose
    material is a Prony table hashes the table's :attr:`SceneTable.digest` (its numbers, not
    its path) in place of the material and k.
    """
    form = id_form(scene, ID_V1_FIELDS["scene"])
    if scene.table is not None:
        # a table scene (after version 1; no older id to keep): the table by its digest, and
        # no k, which the table fixes (its float may differ in the last bit between formats)
        form["material"] = {TABLE_MATERIAL: scene.table.digest}
        form.pop("k")
    text = _canonical({"scene": form,
                       "numerics": id_form(numerics, ID_V1_FIELDS["numerics"])})
    return hashlib.sha1(text.encode()).hexdigest()[:16]


@dataclass(eq=False)
class Result:
    """Outcome of one scene. Scalars are NaN when a run failed before reaching them.

    Results compare by identity (``==`` is ``is``): two runs of one scene differ in
    ``wall_s``, NaN never equals NaN and the trajectory holds arrays. To compare two runs'
    numbers, compare :meth:`scalars` (NaN-aware, e.g. with ``numpy.testing``) or
    :meth:`to_row` less ``wall_s``.

    Attributes
    ----------
    status : {"ok", "failed", "error"}
        "failed": a numerical or physical failure the engine reports with a reason;
        "error": an internal error (a bug, e.g. a TypeError) that ``sweep run`` caught and
        logged with its traceback in ``<out>.errors.log``.
    reason : str
        Why the run failed (Newton failure, step limit, ...); on an ``ok`` row empty or a
        note on how it was reached (e.g. "tip-following mesh: 20 meshes of at most 324
        nodes"): select good rows by ``status``, never by an empty reason.
    pull_off : float
        |min P| over the unloading, in units of pi dg R.
    a_pulloff, a_inner_pulloff : float
        Max-tension radius (gap = 3^(1/6) h0) and inner radius (gap = h0) at pull-off, a_ref.
    delta_pulloff, t_pulloff : float
        Indentation (d_ref) and time (tau0) at pull-off: since the start of unloading, or
        with a test protocol since first contact (the records' clock runs through the
        approach, the dwell and the retraction; the retraction's start is the first record
        of ``trajectory["phase"] == 2``).
    crack_speed : float
        v_a = -da/dt at pull-off, in a_ref / tau0 (local fit of a(t)).
    vhat : float
        Crack speed in Persson-Brener units v tau0 / l0 (alpha = pi/9).
    rhat_pb : float
        Unloading rate in the units of the paper's v-r fit: rate * h0_hat = r tau0 / d_ref.
    a0_result, a0_inner, delta0_result : float
        Initial state actually simulated: contact radius, inner radius, indentation.
    steps, newton_iterations, factorizations : int
        Accepted time steps, total Newton iterations, Jacobian factorizations.
    prony_terms : int
        Number of Prony modes used (0 in exact mode).
    prony_error : float
        Max relative error of the Prony Chat over the scene's window (0 in exact mode).
    spacing, domain_used : float
        Node spacing (the fine spacing of a graded mesh) and mesh radius (a_ref units).
    nodes_used : int
        Number of mesh nodes.
    error_estimate : float
        Estimated relative pull-off error: for the BEM the change against a solve at half
        the resolution in space and time over (factor^0.65 - 1) plus the Prony fit's error
        (about five times the error of a second-order discretization, 1.76 times a first-order
        one's; :mod:`sweep.engine.resolution`),
        for the crack-front model and the PB estimate their measured difference from the BEM
        at the scene's mu (:func:`sweep.engine.models.measured_error`). NaN when not estimated.
    wall_s : float
        Wall-clock time of the run in seconds.
    model_used : str
        The model that ran ("bem", "crack", "pb"; "" when a model's simulate function was
        called directly rather than through :func:`sweep.engine.models.simulate`).
    model_reason : str
        Why that model ran, in a few words (the scene asked for it; or what "auto" weighed:
        e.g. "auto: crack-front model, measured error 0.4 % <= pull_off_rtol 1 % at mu = 40").
    refinements : int
        How many times the BEM (or the elastic branch) solved the scene again at a finer
        resolution because its error estimate exceeded ``pull_off_rtol``
        (``Numerics.refinements`` allows it).
    band_resolution_used, step_used : float
        The BEM's resolution behind the row: spacings per process zone (the graded mesh's
        band resolution; NaN on a mesh given by its node count, whose ``nodes_used`` says it)
        and the largest indentation step (h0); the elastic branch's spacings per process zone
        at its tip (at least its default 16, at fast too; NaN before session 49) and no step
        (NaN). NaN for the other models.
    hysteresis_energy : float
        A scene with a test protocol: the work the machine did on the sphere over the whole
        path, int P d delta (pi dg R d_ref; :func:`sweep.engine.postprocess.cycle_work`), to
        the pull-off where the scene stops there (``stop`` "pulloff"), to the last record
        where it follows the curve to separation; NaN without a protocol.
    hysteresis_error : float
        The estimated relative error of ``hysteresis_energy``: its change against the error
        estimate's coarser solve, over the same factor as the pull-off's (the BEM's f^0.65 -
        1, the elastic branch's sqrt 2 - 1); NaN without a protocol or an estimate. Not part
        of ``error_estimate``, which is the pull-off's, nor of the row's status.
    trajectory : dict of arrays
        ``t``, ``delta``, ``P``, ``a``, ``a_inner`` per accepted step (including t = 0; the
        elastic branch's per scanned radius, fewer than its ``steps``, which count every
        equilibrium solve); with a protocol also ``phase`` (0 approach, 1 dwell, 2
        retraction).
    """

    scene: Scene
    numerics: Numerics
    status: str = "failed"
    reason: str = ""
    pull_off: float = math.nan
    a_pulloff: float = math.nan
    a_inner_pulloff: float = math.nan
    delta_pulloff: float = math.nan
    t_pulloff: float = math.nan
    crack_speed: float = math.nan
    vhat: float = math.nan
    rhat_pb: float = math.nan
    a0_result: float = math.nan
    a0_inner: float = math.nan
    delta0_result: float = math.nan
    steps: int = 0
    newton_iterations: int = 0
    factorizations: int = 0
    prony_terms: int = 0
    prony_error: float = math.nan
    spacing: float = math.nan
    nodes_used: int = 0
    error_estimate: float = math.nan
    domain_used: float = math.nan
    wall_s: float = 0.0
    model_used: str = ""
    model_reason: str = ""
    refinements: int = 0
    band_resolution_used: float = math.nan
    step_used: float = math.nan
    hysteresis_energy: float = math.nan
    hysteresis_error: float = math.nan
    trajectory: dict = field(default_factory=dict)

    @property
    def ok(self) -> bool:
        return self.status == "ok"

    @property
    def scene_id(self) -> str:
        return scene_id(self.scene, self.numerics)

    def __repr__(self) -> str:
        """A one-line summary: status (and reason), pull-off (pi dg R), crack speed
        (a_ref/tau0), model, steps, the trajectory's length (never its arrays) and the
        scene's axes (the process zone and the machine's stiffness where given); the full
        rows are :meth:`to_row` and :meth:`to_dict`."""
        points = len(next(iter(self.trajectory.values()), ()))
        reason = self.reason if len(self.reason) <= 80 else self.reason[:77] + "..."
        sc = self.scene
        if sc.protocol() is not None:
            start = (f"approach_rate={sc.approach_rate:g} preload={sc.preload:g} "
                     f"dwell={sc.dwell:g} ({sc.dwell_hold})")
        else:
            start = f"a0={sc.a0:g}" if sc.a0 is not None else f"delta0={sc.delta0:g}"
        pz = (f" pz_law={sc.pz_law} pz_v0={sc.pz_v0:g} pz_xi={sc.pz_xi:g}"
              if sc.pz_law != "none" else "")
        if sc.machine_stiffness is not None:
            pz += f" machine_stiffness={sc.machine_stiffness:g}"
        return (f"Result({self.status}{' (' + reason + ')' if reason else ''}: "
                f"pull_off={self.pull_off:.6g} crack_speed={self.crack_speed:.6g} "
                f"model={self.model_used or sc.model} steps={self.steps} "
                f"trajectory={points} points; scene {sc.material} n={sc.n:g} k={sc.k:g} "
                f"mu={sc.mu:g} rate={sc.rate:g} {start}{pz})")

    __str__ = __repr__

    def scalars(self) -> dict:
        """The scalar results (no scene parameters), keyed as in :data:`RESULT_SCALARS`."""
        return {name: getattr(self, name) for name in RESULT_SCALARS}

    def to_row(self) -> dict:
        """One flat row: scene id, scene parameters, numerics (prefixed ``num_``), results."""
        row = {"scene_id": self.scene_id}
        row.update(self.scene.to_dict())
        row.update({f"num_{k}": v for k, v in self.numerics.to_dict().items()})
        row.update(self.scalars())
        return row

    def to_dict(self, trajectory: bool = False) -> dict:
        d = self.to_row()
        if trajectory:
            d["trajectory"] = {k: np.asarray(v).tolist() for k, v in self.trajectory.items()}
        return d


#: Scalar result fields, in the order they are stored (HDF5 ``runs`` table columns): every
#: field of :class:`Result` with a number or string default (not the scene, numerics,
#: trajectory or arrays), so a new result field is a new column.
RESULT_SCALARS = tuple(f.name for f in dataclasses.fields(Result)
                       if isinstance(f.default, (int, float, str)))

r"""Scenes in SI units: a sphere, a material, an interface, an initial state and an unloading
speed, converted to the dimensionless scene (docs/design.md section 2, via :mod:`sweep.units`) and
results converted back.

Inputs (SI): sphere radius ``R`` [m]; relaxed and glassy Young's moduli ``E0``, ``Einf`` [Pa];
Poisson's ratio ``nu``; MPL exponent ``n`` and time ``tau0`` [s]; work of adhesion ``dg``
[J/m^2]; LJ equilibrium distance ``h0`` [m]; the initial state as exactly one of a preload
force ``preload`` [N] (compressive, reached after full relaxation: the relaxed JKR contact at
that load), a contact radius ``a0`` [m] or an indentation ``indentation`` [m]; the unloading
speed ``speed`` [m/s]; optionally a rate-dependent process zone, ``pz_law`` ("none" or
"gent-schultz"), ``pz_v0`` [m/s] (the crack speed at which it doubles the work of adhesion)
and ``pz_xi`` (its exponent), converted to ``pz_v0`` in a_ref/tau0
(:meth:`sweep.units.PhysicalScale.crack_speed_hat`); optionally the test as run, a protocol:
``approach_speed`` [m/s], ``preload`` [N] (then the force at the end of the approach),
``dwell`` [s] and ``dwell_hold`` ("force" or "depth"), converted to the Scene's
``approach_rate`` (r-hat), ``preload`` (pi dg R) and ``dwell`` (tau0); ``speed`` is then the
retraction's; optionally a compliant machine, ``machine_stiffness`` [N/m] (the force
sensor's stiffness in series with the sphere), converted to pi dg R / d_ref.

Derived: ``k = E0/Einf``, ``mu`` (Tabor), ``rate = speed tau0 / h0`` (the paper's r-hat), the
initial ``a0_hat`` (a_ref) or ``delta0_hat`` (d_ref).

A Prony table as the material (``material={"prony": path}``, an inline table, a
:class:`~sweep.materials.PronyTable` or a :class:`sweep.scene.SceneTable`) replaces ``E0``,
``Einf``, ``n`` and ``tau0``: ``E0`` and ``Einf`` are the table's relaxed and instantaneous
moduli, in Pa (a table that states no units is taken as Pa and s), ``tau0`` is 1 s (the
scene's time unit; its times are the table's retardation times in s) and ``n`` is unused
(:data:`TABLE_N` in the dimensionless scene, for bookkeeping). The reference modulus of
the scales (``a_ref``, ``mu``, ``l0``) is the relaxed ``E0* = E0 / (1 - nu^2)``, as for the
MPL. The moduli are read at the 10 significant digits of the table's hash
(:func:`sweep.materials.prony_files.hash_rounded`), so that the same table in any format
gives the same scene. Giving ``E0``, ``Einf`` or ``tau0`` with a table is an error unless it
equals the table's. The dimensionless scene holds everything
a model needs; a :class:`sweep.Scene` is built when its parameters are within the Scene's
ranges (the BEM's), the crack-front and pb models run on the plain parameters at any ``mu``.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass

from .. import units
from ..engine.crack_front import scene_law, unload
from ..engine.models import (MACHINE_REFUSALS, PROCESS_ZONE_REFUSALS, PROTOCOL_REFUSALS,
                             TABLE_REFUSALS, choose_model, pb_estimate, simulate_model)
from ..errors import InputError, as_float, check_choice, check_positive, check_range
from ..materials.prony_files import hash_rounded
from ..scene import (AXES, DWELL_HOLDS, PZ_LAWS, SCENE_LIMITS, Axis, Numerics,
                     Scene, SceneTable, check_material_name, check_process_zone,
                     scene_table)
from ..theory import jkr_contact_radius, jkr_pull_off
from ..units import PhysicalScale

__all__ = ["SIScene", "run_si", "SI_MODELS", "SI_AXES", "si_row", "si_point"]

SI_MODELS = ("bem", "crack", "pb", "elastic", "auto")


def _si_axis(name, unit, help, lo=0.0, hi=None, lo_open=True, required=True, order=0):
    return Axis(name=name, default=None, required=required, help=help, unit=unit,
                limits=(lo, hi), lo_open=lo_open, choices=None, label=name, order=order,
                plot_group=True, cli_default=None)


#: The SI fields of a ``units: si`` config grid (and of :class:`SIScene`), in the order of
#: expansion (the last varies fastest); ``model``, ``material`` and ``stop`` are the Scene's.
#: Exactly one of ``preload``, ``a0``, ``indentation`` is given.
SI_AXES = {a.name: a for a in (
    _si_axis("R", "m", "sphere radius", order=3),
    _si_axis("E0", "Pa", "relaxed Young's modulus", order=4),
    _si_axis("Einf", "Pa", "glassy Young's modulus (>= E0)", order=5),
    _si_axis("nu", "", "Poisson's ratio", hi=0.5, lo_open=False, order=6),
    _si_axis("n", "", "MPL exponent", hi=5.0, order=7),
    _si_axis("tau0", "s", "MPL time", order=8),
    _si_axis("dg", "J/m^2", "work of adhesion", order=9),
    _si_axis("h0", "m", "LJ equilibrium distance", order=10),
    _si_axis("preload", "N", "compressive preload: the relaxed start at that load (or a0 or "
             "indentation); with dwell, the force at the end of the approach",
             lo_open=False, required=False, order=11),
    _si_axis("a0", "m", "initial contact radius (or preload or indentation)",
             required=False, order=12),
    _si_axis("indentation", "m", "initial indentation (or preload or a0)", lo=None,
             lo_open=False, required=False, order=13),
    _si_axis("speed", "m/s", "unloading (retraction) speed", order=14),
    _si_axis("approach_speed", "m/s", "test protocol: approach speed (with preload and dwell)",
             required=False, order=1),
    _si_axis("dwell", "s", "test protocol: dwell at the preload (with approach_speed; "
             "dwell_hold says what is held)", lo_open=False, required=False, order=1),
    _si_axis("pz_v0", "m/s", "process zone: crack speed at which it doubles the work of "
             "adhesion (with pz_law gent-schultz)", required=False, order=2),
    _si_axis("pz_xi", "", "process zone: exponent of Gamma_pz(v) (with pz_law gent-schultz)",
             hi=AXES["pz_xi"].limits[1], required=False, order=2),
    _si_axis("machine_stiffness", "N/m", "stiffness of the machine (force sensor) in series "
             "with the sphere (unset: a rigid machine)", required=False, order=2),
)}
#: Categorical Scene axes an SI grid (and ``sweep scene --si``) takes as they are.
SI_SCENE_AXES = ("model", "material", "stop", "pz_law", "dwell_hold")
#: Of those, the ones the SI scene holds (the rest pass to the Scene as they are).
SI_SCENE_FIELDS = ("material", "pz_law", "dwell_hold")
#: The initial-state fields of an SI grid: exactly one is given.
SI_INITIAL = ("preload", "a0", "indentation")
#: The SI fields a Prony table replaces (its moduli and times).
TABLE_FIELDS = ("E0", "Einf", "n", "tau0")
#: ``n`` of the dimensionless scene of a table material (unused, as for "sls")
TABLE_N = 1.0


@dataclass(frozen=True, kw_only=True)
class SIScene:
    """One unloading experiment in SI units (module docstring for the fields)."""

    R: float
    E0: float | None = None
    Einf: float | None = None
    nu: float
    n: float | None = None
    tau0: float | None = None
    dg: float
    h0: float
    speed: float
    preload: float | None = None
    a0: float | None = None
    indentation: float | None = None
    material: str | SceneTable = "mpl"
    pz_law: str = "none"
    pz_v0: float | None = None
    pz_xi: float | None = None
    approach_speed: float | None = None
    dwell: float | None = None
    dwell_hold: str = "force"
    machine_stiffness: float | None = None

    def __post_init__(self):
        set_ = lambda name, v: object.__setattr__(self, name, v)  # noqa: E731
        set_("nu", check_range("nu", self.nu, 0.0, 0.5))
        if isinstance(self.material, str):
            check_material_name(self.material)
            missing = [f for f in TABLE_FIELDS if getattr(self, f) is None]
            if missing:
                raise InputError(f"{', '.join(missing)}: required for material "
                                 f"{self.material} (or give a Prony table as the material)")
        else:
            if isinstance(self.material, dict) and self.material.get("nu") is not None \
                    and as_float("material nu", self.material["nu"]) != self.nu:
                raise InputError(f"nu: the table's Poisson's ratio {self.material['nu']} "
                                 f"differs from the scene's nu = {self.nu:g}; give one")
            table = scene_table(self.material, nu=self.nu)
            set_("material", table)
            if self.n is not None:
                raise InputError(f"n: unused with a Prony table (material {table.label}); "
                                 f"leave it out")
            for name, value in (("E0", table.E0), ("Einf", table.Einf), ("tau0", table.tau0)):
                given = getattr(self, name)
                if given is not None and not math.isclose(as_float(name, given), value,
                                                          rel_tol=1e-12):
                    raise InputError(f"{name}: the Prony table {table.name} gives {name} = "
                                     f"{value:.6g}; leave {name} out (got {given!r})")
                # the moduli at the digits the table's hash reads: the same table from any
                # format derives the same scales, hence the same scene ids
                set_(name, value if name == "tau0" else hash_rounded(value))
        for name in ("R", "E0", "Einf", "tau0", "dg", "h0", "speed"):
            set_(name, check_positive(name, getattr(self, name)))
        if self.n is not None:
            set_("n", check_positive("n", self.n))
        if self.Einf < self.E0:
            raise InputError(f"Einf must be >= E0 = {self.E0:.6g} Pa (got {self.Einf:.6g})")
        given = [f for f in ("preload", "a0", "indentation") if getattr(self, f) is not None]
        if self.has_protocol or self.approach_speed is not None:
            missing = [name for name in ("approach_speed", "preload", "dwell")
                       if getattr(self, name) is None]
            if missing:
                raise InputError(f"{'/'.join(missing)}: a test protocol needs approach_speed "
                                 f"[m/s], preload [N] and dwell [s] together (missing "
                                 f"{', '.join(missing)})")
            set_("approach_speed", check_positive("approach_speed", self.approach_speed))
            set_("dwell", check_range("dwell", self.dwell, lo=0.0))
            check_choice("dwell_hold", self.dwell_hold, DWELL_HOLDS)
            if given != ["preload"]:
                raise InputError("a0/indentation: a test protocol (approach_speed, preload, "
                                 "dwell) starts at first contact: give neither a0 nor "
                                 "indentation")
        elif self.dwell_hold != "force":
            raise InputError(f"dwell_hold: {self.dwell_hold!r} needs a test protocol "
                             f"(approach_speed, preload, dwell)")
        if len(given) != 1:
            raise InputError("preload/a0/indentation: give exactly one initial state (a preload "
                             f"force [N], a contact radius [m] or an indentation [m]; got "
                             f"{', '.join(given) or 'none'})")
        if self.preload is not None:
            set_("preload", check_range("preload", self.preload, lo=0.0))
        if self.a0 is not None:
            set_("a0", check_positive("a0", self.a0))
        if self.indentation is not None:
            set_("indentation", check_range("indentation", self.indentation))
        check_choice("pz_law", self.pz_law, PZ_LAWS)
        if self.pz_v0 is not None:
            set_("pz_v0", check_positive("pz_v0", self.pz_v0))
        if self.pz_xi is not None:
            set_("pz_xi", AXES["pz_xi"].check(self.pz_xi))
        check_process_zone(self.pz_law, self.pz_v0, self.pz_xi, "m/s")
        if self.machine_stiffness is not None:
            set_("machine_stiffness", check_positive("machine_stiffness",
                                                     self.machine_stiffness))

    # ---- scales ------------------------------------------------------------------------------
    @property
    def scale(self) -> PhysicalScale:
        return PhysicalScale.from_moduli(self.R, self.dg, self.E0, self.nu, self.h0)

    @property
    def k(self) -> float:
        """``E0/Einf`` (a table's own, ``1 - sum c_i``)."""
        if isinstance(self.material, SceneTable):
            return self.material.k
        return self.E0 / self.Einf

    @property
    def table(self) -> SceneTable | None:
        """The Prony table of the material (None for "mpl" and "sls")."""
        return self.material if isinstance(self.material, SceneTable) else None

    @property
    def mu(self) -> float:
        return self.scale.mu

    @property
    def rate(self) -> float:
        """The paper's r-hat, ``speed tau0 / h0``."""
        return float(self.scale.rate_hat(self.speed, self.tau0))

    @property
    def has_protocol(self) -> bool:
        """Whether the scene is a test protocol (approach, dwell, retract)."""
        return self.dwell is not None

    def dimensionless(self) -> dict:
        """``n, k, mu, rate, material``, ``a0`` (a_ref) or ``delta0`` (d_ref), and the process
        zone ``pz_law``, ``pz_v0`` (a_ref/tau0), ``pz_xi`` (None without one); with a test
        protocol ``approach_rate`` (r-hat), ``preload`` (pi dg R), ``dwell`` (tau0) and
        ``dwell_hold`` instead of ``a0`` and ``delta0``; ``machine_stiffness`` (pi dg R/d_ref,
        None for a rigid machine).

        Without a protocol a preload becomes the relaxed JKR contact radius at that load.
        """
        sc = self.scale
        n = TABLE_N if self.table is not None else self.n
        d = {"n": n, "k": self.k, "mu": sc.mu, "rate": self.rate, "material": self.material,
             "a0": None, "delta0": None, "pz_law": self.pz_law,
             "pz_v0": (None if self.pz_v0 is None
                       else float(sc.crack_speed_hat(self.pz_v0, self.tau0))),
             "pz_xi": self.pz_xi,
             "machine_stiffness": (None if self.machine_stiffness is None
                                   else float(sc.load_hat(self.machine_stiffness * sc.d_ref)))}
        if self.has_protocol:
            d.update(approach_rate=float(sc.rate_hat(self.approach_speed, self.tau0)),
                     preload=float(sc.load_hat(self.preload)), dwell=self.dwell / self.tau0,
                     dwell_hold=self.dwell_hold)
        elif self.preload is not None:
            d["a0"] = float(jkr_contact_radius(load=float(sc.load_hat(self.preload))))
        elif self.a0 is not None:
            d["a0"] = float(sc.radius_hat(self.a0))
        else:
            d["delta0"] = float(sc.normal_hat(self.indentation))
        return d

    def to_scene(self, **extra):
        """The :class:`sweep.Scene` (raises InputError outside the Scene's ranges, e.g. mu)."""
        d = {k: v for k, v in self.dimensionless().items()
             if not (k in ("a0", "delta0") and v is None)}
        return Scene(**d, **extra)

    @classmethod
    def from_dimensionless(cls, *, n, k, mu, rate, R, E0, nu, tau0, dg, a0=None, delta0=None,
                           material="mpl", pz_law="none", pz_v0=None, pz_xi=None,
                           approach_rate=None, preload=None, dwell=None,
                           dwell_hold="force", machine_stiffness=None) -> "SIScene":
        """The SI scene of a dimensionless one for a chosen sphere and material.

        ``h0`` follows from ``mu`` (``mu^3 = R dg^2 / (E0*^2 h0^3)``), the speed from ``rate``,
        the initial state from ``a0`` (-> contact radius [m]) or ``delta0`` (-> indentation);
        a process zone's ``pz_v0`` (a_ref/tau0 -> m/s); a test protocol's ``approach_rate``
        (-> ``approach_speed`` [m/s]), ``preload`` (pi dg R -> N) and ``dwell`` (tau0 -> s)
        instead of ``a0`` and ``delta0``; a compliant machine's ``machine_stiffness``
        (pi dg R/d_ref -> N/m).
        """
        E0s = check_positive("E0", E0) / (1.0 - check_range("nu", nu, 0.0, 0.5) ** 2)
        h0 = (check_positive("R", R) * check_positive("dg", dg) ** 2 / E0s**2) ** (1.0 / 3.0) \
            / check_positive("mu", mu)
        sc = PhysicalScale(R=R, dg=dg, E0_star=E0s, h0=h0)
        kw = {"pz_law": pz_law, "pz_xi": pz_xi, "dwell_hold": dwell_hold}
        if pz_v0 is not None:
            kw["pz_v0"] = float(sc.crack_speed_physical(pz_v0, tau0))
        if machine_stiffness is not None:
            kw["machine_stiffness"] = float(sc.load_physical(machine_stiffness)) / sc.d_ref
        if dwell is not None or approach_rate is not None:
            if a0 is not None or delta0 is not None or None in (approach_rate, preload, dwell):
                raise InputError("approach_rate/preload/dwell: a protocol gives all three, and "
                                 "neither a0 nor delta0")
            kw.update(approach_speed=float(sc.rate_physical(approach_rate, tau0)),
                      preload=float(sc.load_physical(preload)), dwell=float(dwell) * tau0)
        elif (a0 is None) == (delta0 is None):
            raise InputError("a0/delta0: give exactly one of a0 and delta0")
        elif a0 is not None:
            kw["a0"] = float(sc.radius_physical(a0))
        else:
            kw["indentation"] = float(sc.normal_physical(delta0))
        return cls(R=R, E0=E0, Einf=E0 / check_range("k", k, 0.0, 1.0, lo_open=True), nu=nu,
                   n=n, tau0=tau0, dg=dg, h0=h0,
                   speed=float(sc.rate_physical(rate, tau0)), material=material, **kw)

    def to_dict(self) -> dict:
        """The fields as plain values (a table material as its label ``prony:<name>:<hash>``)."""
        d = asdict(self)
        if self.table is not None:
            d["material"] = self.table.label
        return d


def si_point(point: dict, where: str) -> tuple[SIScene, Scene]:
    """The SI scene of one point and the dimensionless :class:`sweep.Scene` it derives to,
    both checked: what a ``units: si`` config and ``sweep scene --si`` run.

    Parameters
    ----------
    point : dict
        SI fields (:data:`SI_AXES`) and the Scene axes :data:`SI_SCENE_AXES` (``model``,
        ``material``, ``stop``, ``pz_law``, ``dwell_hold``).
    where : str
        Where the point comes from (``grid``, ``grid[1]``, ``--si``), named in the error.

    Returns
    -------
    tuple of (SIScene, Scene)

    Raises
    ------
    InputError
        One line naming ``where`` and the SI point, for a bad SI field or a derived scene
        outside the Scene's ranges (e.g. a rate above 1e12, an a0 below 0.3 a_ref): every
        model's scene passes the same checks, whichever model then runs it.
    """
    extra = {a: point[a] for a in SI_SCENE_AXES if a in point and a not in SI_SCENE_FIELDS}
    phys = {a: v for a, v in point.items() if a not in SI_SCENE_AXES}
    try:
        si = SIScene(**phys, **{a: point[a] for a in SI_SCENE_FIELDS if a in point})
        return si, si.to_scene(**extra)
    except InputError as exc:
        desc = ", ".join(f"{a}={v:g}" for a, v in phys.items() if v is not None)
        raise InputError(f"{where} (SI point {desc}): {exc}") from None


def _si_of(si: SIScene, dimless: dict) -> dict:
    """SI values of a dimensionless result (pull-off, radii, speeds) and the scales."""
    sc = si.scale
    out = {
        "mu": sc.mu, "k": si.k, "rate": si.rate, "l0_m": sc.l0, "a_ref_m": sc.a_ref,
        "d_ref_m": sc.d_ref, "load_ref_N": sc.load_ref,
        "jkr_pull_off_N": float(sc.load_physical(jkr_pull_off())),
    }
    conv = {"pull_off": ("pull_off_N", sc.load_physical),
            "a_pulloff": ("a_pulloff_m", sc.radius_physical),
            "a0": ("a0_m", sc.radius_physical),
            "delta_pulloff": ("delta_pulloff_m", sc.normal_physical),
            "delta0": ("delta0_m", sc.normal_physical),
            "crack_speed": ("crack_speed_m_s", lambda v: sc.crack_speed_physical(v, si.tau0)),
            "t_pulloff": ("t_pulloff_s", lambda t: sc.time_physical(t, si.tau0)),
            # a test protocol's work (pi dg R d_ref): load_ref times d_ref
            "hysteresis_energy": ("hysteresis_energy_J", lambda w: w * sc.load_ref * sc.d_ref)}
    for key, (name, f) in conv.items():
        v = dimless.get(key)
        out[name] = None if v is None or (isinstance(v, float) and math.isnan(v)) else float(f(v))
    return out


def run_si(si: SIScene, model: str = "crack", numerics=None) -> dict:
    """Run an SI scene with a model and return the results in both systems.

    Parameters
    ----------
    si : SIScene
    model : {"bem", "crack", "pb", "elastic", "auto"}
        "bem" and "elastic" need a :class:`sweep.Scene` (its ranges, e.g. mu <= 100); "crack"
        runs as :func:`sweep.simulate` runs it within the Scene's ranges and on its law
        beyond them, and "pb" at any Tabor parameter; "auto" is :func:`sweep.engine.models.choose_model` within the Scene's
        ranges and "crack" beyond them (``model`` in the output says which ran).
    numerics : sweep.Numerics, optional
        BEM discretization (default: the balanced preset); read by "bem" and "auto" only.

    Returns
    -------
    dict
        ``model``, ``status``, ``reason``, the SI inputs (``si``), the dimensionless scene
        (``scene``), the dimensionless results (``pull_off``, ``a_pulloff``, ``crack_speed``,
        ``vhat``, ``a0``, ``delta0`` ...) and their SI values (``pull_off_N``, ``a_pulloff_m``,
        ``crack_speed_m_s``, ...; a test protocol's ``hysteresis_energy_J`` with its relative
        ``hysteresis_error``) with ``mu``, ``l0_m``, ``jkr_pull_off_N``.
    """
    model = check_choice("model", model, SI_MODELS)
    if numerics is not None and not isinstance(numerics, Numerics):
        raise TypeError("numerics must be a sweep.Numerics (e.g. Numerics.preset('fast')), "
                        f"got {type(numerics).__name__}")
    d = si.dimensionless()
    if model == "auto":
        lo, hi = SCENE_LIMITS["mu"]
        model = choose_model(si.to_scene(), numerics) if lo <= d["mu"] <= hi else "crack"
    res = {"model": model}
    if model == "bem":
        # engine.problem loads the compiled kernels (numba): imported on this path only, so
        # that a sweep worker (which imports this module through the config) sets its thread
        # limits before numba loads (sweep.campaign.scheduler._prepare_worker)
        from ..engine.problem import BEM_MU_RANGE

        lo, hi = BEM_MU_RANGE
        if d["k"] < 1.0 and not lo <= d["mu"] <= hi:
            raise InputError(f"mu must be in [{lo:g}, {hi:g}] for the BEM (got {d['mu']:.6g}): "
                             "outside the BEM's scene ranges; use model crack or pb")
        try:
            scene = si.to_scene()
        except InputError as exc:
            raise InputError(f"{exc}: outside the BEM's scene ranges; use model crack or pb") \
                from None
        r = simulate_model(scene, "bem", numerics)
        dim = _dimensionless_row(r)
    elif model == "elastic":
        try:
            scene = si.to_scene()
        except InputError as exc:
            raise InputError(f"{exc}: outside the elastic branch's scene ranges") from None
        dim = _dimensionless_row(simulate_model(scene, "elastic", numerics))
    elif model in PROTOCOL_REFUSALS and si.has_protocol:
        dim = {"status": "failed", "reason": PROTOCOL_REFUSALS[model], "a0": None,
               "delta0": None}
    elif model in MACHINE_REFUSALS and si.machine_stiffness is not None:
        dim = {"status": "failed", "reason": MACHINE_REFUSALS[model], "a0": d["a0"],
               "delta0": d["delta0"]}
    elif model in TABLE_REFUSALS and si.table is not None:
        dim = {"status": "failed", "reason": TABLE_REFUSALS[model], "a0": d["a0"],
               "delta0": d["delta0"]}
    elif model == "pb" and d["pz_law"] != "none":
        dim = {"status": "failed", "reason": PROCESS_ZONE_REFUSALS["pb"].format(**d),
               "a0": d["a0"], "delta0": d["delta0"]}
    elif model == "crack":
        try:
            scene = si.to_scene()
        except InputError:
            scene = None
        if scene is not None:
            # the front door that `sweep run` takes (its nearly elastic and relaxed limits,
            # the time budget): one answer per scene
            dim = _dimensionless_row(simulate_model(scene, "crack", numerics))
        else:       # beyond the Scene's ranges: the crack-front model's law itself
            law = scene_law(d["n"], d["k"], d["mu"], d["material"], d["pz_law"], d["pz_v0"],
                            d["pz_xi"])
            s = unload(law, rate=d["rate"], mu=d["mu"], a0=d["a0"], delta0=d["delta0"])
            dim = {"status": s.status, "reason": s.reason, "pull_off": s.pull_off,
                   "a_pulloff": s.a_pulloff, "delta_pulloff": s.delta_pulloff,
                   "t_pulloff": s.t_pulloff, "crack_speed": s.crack_speed,
                   "vhat": float(units.vhat_from_crack_speed(s.crack_speed, d["mu"])),
                   "gamma_pulloff": s.gamma_pulloff, "a0": s.a0, "delta0": s.delta0}
    else:
        e = pb_estimate(d["n"], d["k"], d["mu"], d["rate"], d["material"])
        dim = {"status": "ok", "reason": "", "pull_off": float(e["pull_off"]),
               "crack_speed": float(e["crack_speed"]), "vhat": float(e["vhat"]),
               "gamma_pulloff": float(e["gamma"]), "a0": d["a0"], "delta0": d["delta0"]}
    res.update(dim)
    res["scene"] = d
    res["si"] = si.to_dict()
    res.update(_si_of(si, dim))
    return res


def _dimensionless_row(r) -> dict:
    """The dimensionless results of a :class:`sweep.Result` that :func:`run_si` reports."""
    return {"status": r.status, "reason": r.reason, "pull_off": r.pull_off,
            "a_pulloff": r.a_pulloff, "delta_pulloff": r.delta_pulloff,
            "t_pulloff": r.t_pulloff, "crack_speed": r.crack_speed, "vhat": r.vhat,
            "a0": r.a0_result, "delta0": r.delta0_result,
            "hysteresis_energy": r.hysteresis_energy, "hysteresis_error": r.hysteresis_error}


def si_row(si: SIScene, row) -> dict:
    """SI inputs and outputs of one stored row (a mapping with the Result columns)."""
    def get(key):
        v = row.get(key)
        return None if v is None or (isinstance(v, float) and math.isnan(v)) else v

    dim = {"pull_off": get("pull_off"), "a_pulloff": get("a_pulloff"),
           "delta_pulloff": get("delta_pulloff"), "crack_speed": get("crack_speed"),
           "t_pulloff": get("t_pulloff"), "a0": get("a0_result"),
           "delta0": get("delta0_result"), "hysteresis_energy": get("hysteresis_energy")}
    out = {f"si_{k}": v for k, v in si.to_dict().items() if v is not None}
    out.update(_si_of(si, dim))
    return out

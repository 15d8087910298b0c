"""Sweep configurations: YAML files under ``configs/`` that describe a grid of scenes.

Format (all keys; unknown keys are errors)::

    name: threshold                 # required; letters, digits, "-", "_", "."
    description: free text          # optional
    units: dimensionless            # optional: or "si" (grid in SI fields, see below)
    grid:                           # required: one grid, or a list of grids (see below)
      n: [0.4, 0.6, 0.8, 1.6]       # a list of values ...
      k: 0.1                        # ... or a single value ...
      a0: {linspace: [1, 8, 15]}    # ... or a range {linspace: [start, stop, num]}
      rate: {log10: [0, 6, 7]}      # ... or {log10: [start, stop, num]} = 10**linspace
    numerics: {preset: balanced}    # optional: a preset and/or explicit Numerics fields
    store: {trajectories: false}    # optional: also keep t, delta, P, a, a_inner per scene
    output: results/threshold.h5    # optional: HDF5 file; relative to the working directory

Grid axes: the fields of :class:`sweep.scene.Scene`, with the defaults, limits, units and
meaning declared there once (:data:`sweep.scene.AXES`; listed in docs/configs.md and by
``sweep scene --help``). ``n`` and ``rate`` are required, and exactly one of ``a0`` and
``delta0``.

The scenes are the Cartesian product of the axes. ``grid`` may also be a *list* of such
mappings (e.g. the three panels of the paper's Fig. 3): the sweep is then the union of the
sub-grids, de-duplicated by scene id (first occurrence kept, order preserved). Every scene
of a sweep uses the same ``numerics`` (default: the "balanced" preset); ``numerics`` may
combine a ``preset`` with explicit overrides (``{preset: fast, nodes: 120}``).
``output`` defaults to ``results/<name>.h5``.

``units: si``: the grid holds the SI fields of :data:`sweep.campaign.si.SI_AXES` (``R, E0, Einf, nu,
n, tau0, dg, h0, speed``, one of ``preload``, ``a0``, ``indentation``, and ``pz_v0`` [m/s],
``pz_xi`` with a ``pz_law``) besides ``model``, ``material``, ``stop``, ``pz_law``; every
point becomes a :class:`sweep.campaign.si.SIScene` and its
dimensionless :class:`Scene` (the one hashed, stored and run; :meth:`SweepConfig.si_tasks`
maps ids back to the SI points, :func:`sweep.campaign.store.si_table` gives stored rows in SI).

YAML 1.1 reads ``1e6`` as a string; numeric strings such as ``"1e6"`` are accepted as
numbers wherever a number is expected. Configs are read with a safe loader (no Python
objects, no code) that also rejects duplicate keys. Validation collects every problem
and raises one :class:`~sweep.errors.InputError` that lists them all, each naming its key.
"""
from __future__ import annotations

import dataclasses
import decimal
import hashlib
import itertools
import json
import os
import re
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path

import numpy as np
import yaml

from ..errors import InputError, as_float, check_choice, check_int, check_range
from ..scene import AXES as SCENE_AXIS_INFO
from ..scene import Numerics, Scene, SceneTable, scene_id, scene_table
from .si import SI_AXES, SI_INITIAL, SI_SCENE_AXES, TABLE_FIELDS, SIScene, si_point

#: Top-level keys of a config file.
TOP_KEYS = ("name", "description", "units", "grid", "numerics", "store", "output")
#: Values of ``units``: the grid in the dimensionless Scene axes, or in SI (sweep.campaign.si.SI_AXES).
UNITS = ("dimensionless", "si")
#: Grid axes, in the order the Cartesian product iterates them (last varies fastest).
#: Grid axes in the order of expansion (the last varies fastest): the Scene fields by their
#: ``order`` metadata.
AXES = tuple(sorted(SCENE_AXIS_INFO, key=lambda a: SCENE_AXIS_INFO[a].order))
#: Defaults of axes left out of a grid.
AXIS_DEFAULTS = {a.name: a.default for a in SCENE_AXIS_INFO.values() if a.default is not None}
STORE_KEYS = ("trajectories",)
RANGE_KINDS = ("log10", "linspace")


def powers_of_ten(start: float, stop: float, num: int) -> list[float]:
    """10**x at ``num`` exponents x evenly spaced from ``start`` to ``stop`` (``np.linspace``'s,
    exact to IEEE arithmetic), each power correctly rounded (decimal arithmetic to 40 digits),
    so that a grid, and the ids of its scenes, are the same on every machine.

    ``np.logspace`` evaluates the powers with the processor's own vector code, whose last bit
    differs between processors: 10^2.5 came out 316.2277660168379 on the machine that made
    the committed campaigns of 2026-11-27 and 316.22776601683796 (correctly rounded) on
    another, so that the same config gave other scene ids there and a file could not be
    resumed on the other machine. Files written before this keep resuming: a stored scene
    that differs from the config's in the last bits of a float counts as that scene
    (:func:`sweep.campaign.scheduler.rounding_twins`)."""
    with decimal.localcontext() as ctx:
        ctx.prec = 40
        return [float(decimal.Decimal(10) ** decimal.Decimal(float(x)))
                for x in np.linspace(start, stop, num)]
MAX_SCENES = 200_000
MAX_RANGE_NUM = 10_000
_NAME_RE = re.compile(r"^[A-Za-z0-9_.-]+$")


@dataclass(frozen=True)
class SweepConfig:
    """A validated sweep: name, grids of axis values, numerics, storage options, output.

    Build it with :func:`load_config` (file), :func:`parse_config` (YAML text) or
    :func:`config_from_dict` (mapping). ``grids`` is a tuple of ``{axis: tuple(values)}``
    with every axis filled in (defaults applied; the unused one of a0/delta0 absent).
    """

    name: str
    grids: tuple
    numerics: Numerics
    trajectories: bool = False
    output: str = ""
    description: str = ""
    text: str = field(default="", repr=False, compare=False)
    source: str = field(default="<dict>", compare=False)
    units: str = "dimensionless"

    def scenes(self) -> list[Scene]:
        """The scenes of the sweep, de-duplicated by scene id, in grid order."""
        return [s for _, s in self.tasks()]

    def tasks(self) -> list[tuple[str, Scene]]:
        """``(scene_id, scene)`` pairs of the sweep, de-duplicated, in grid order."""
        return list(self._tasks)

    def copies_by_unused_n(self) -> int:
        """How many of the sweep's scenes differ from an earlier one only in ``n``, which
        their material does not use ("sls", a Prony table): a grid over n crossed with such
        a material runs each of its scenes once per n, to the same numbers."""
        seen, copies = set(), 0
        for _, scene in self._tasks:
            if scene.material == "mpl":
                continue
            key = scene_id(dataclasses.replace(scene, n=1.0), self.numerics)
            copies += key in seen
            seen.add(key)
        return copies

    def si_tasks(self) -> list:
        """``(scene_id, SIScene)`` pairs of a ``units: si`` sweep (empty otherwise): the SI
        point that made each scene (the first one, if several give the same scene)."""
        return [(sid, si) for sid, (_, si) in self._expanded.items() if si is not None]

    @cached_property
    def _tasks(self) -> tuple:
        return tuple((sid, scene) for sid, (scene, _) in self._expanded.items())

    @cached_property
    def _expanded(self) -> dict:
        # the grid is expanded and hashed once per config object (a frozen value)
        seen: dict[str, tuple] = {}
        for gi, grid in enumerate(self.grids):
            if self.units == "si":
                order = sorted(grid, key=_si_order)
            else:
                order = [a for a in AXES if a in grid]
            for values in itertools.product(*(grid[a] for a in order)):
                point = dict(zip(order, values))
                si = None
                if self.units == "si":
                    si, scene = si_point(point, f"grid[{gi}]" if len(self.grids) > 1 else "grid")
                else:
                    scene = Scene(**point)
                sid = scene_id(scene, self.numerics)
                if sid not in seen:
                    seen[sid] = (scene, si)
        return seen

    @cached_property
    def config_hash(self) -> str:
        """Hash of what the results depend on: the scene ids and the trajectory flag.

        Renaming the sweep, reformatting the file or moving the output does not change it;
        any change of a scene, of the numerics or of ``store.trajectories`` does.
        """
        ids = sorted(sid for sid, _ in self.tasks())
        text = json.dumps({"scenes": ids, "trajectories": bool(self.trajectories)},
                          sort_keys=True, separators=(",", ":"))
        return hashlib.sha1(text.encode()).hexdigest()[:16]

    @property
    def recorded_text(self) -> str:
        """The config text a results file records: ``text`` itself, or where a material is
        a Prony table read from a file (``{prony: path}``), the config with every table
        inline (:meth:`to_dict`) as it was read. The file then says what it holds on its
        own: a table edited since grows the file's grid like any changed axis value (its
        earlier scenes had been taken for the edited table's, "4 finished of 2"), and
        ``sweep info --si`` reads the file where the table is not (it had refused, "cannot
        read the Prony table")."""
        if not _names_a_file(yaml.safe_load(self.text) if self.text else None):
            return self.text
        return (f"# {self.source}, as run: its Prony tables inline as they were read\n"
                + yaml.safe_dump(self.to_dict(), sort_keys=False))

    def output_path(self, out: str | os.PathLike | None = None) -> Path:
        """Absolute output path (``out`` overrides ``output``; relative to the cwd)."""
        p = Path(out if out is not None else self.output).expanduser()
        return p if p.is_absolute() else Path.cwd() / p

    def to_dict(self) -> dict:
        """A plain mapping that :func:`config_from_dict` turns back into this config."""
        grids = []
        for g in self.grids:
            grids.append({a: [x.spec if isinstance(x, SceneTable) else x for x in v]
                          for a, v in g.items()})
        return {
            "name": self.name,
            "description": self.description,
            **({"units": self.units} if self.units != "dimensionless" else {}),
            "grid": grids[0] if len(grids) == 1 else grids,
            "numerics": self.numerics.to_dict(),
            "store": {"trajectories": self.trajectories},
            "output": self.output,
        }


def _names_a_file(data) -> bool:
    """Whether parsed config ``data`` holds a Prony table given by a file (``{prony: ...}``)."""
    if isinstance(data, dict):
        return "prony" in data or any(_names_a_file(v) for v in data.values())
    if isinstance(data, list):
        return any(_names_a_file(v) for v in data)
    return False


class UniqueKeyLoader(getattr(yaml, "CSafeLoader", yaml.SafeLoader)):
    """Safe loader (plain data only) that rejects duplicate mapping keys; libyaml's parser
    where PyYAML has it (a 200-scene listed grid parses in 8 ms against 50 ms)."""


def _construct_mapping(loader, node, deep=False):
    seen = set()
    for key_node, _ in node.value:
        key = loader.construct_object(key_node, deep=deep)
        try:
            dup = key in seen
        except TypeError:
            dup = False
        if dup:
            mark = key_node.start_mark
            raise yaml.constructor.ConstructorError(
                None, None, f"duplicate key {key!r}", mark)
        try:
            seen.add(key)
        except TypeError:
            pass
    return yaml.SafeLoader.construct_mapping(loader, node, deep=deep)


UniqueKeyLoader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG,
                                 _construct_mapping)


def load_config(path: str | os.PathLike) -> SweepConfig:
    """Read and validate a YAML config file."""
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise InputError(f"config: no such file {str(p)!r}") from None
    except IsADirectoryError:
        raise InputError(f"config: {str(p)!r} is a directory, not a YAML file") from None
    except UnicodeDecodeError:
        raise InputError(f"config: {str(p)!r} is not UTF-8 text") from None
    except OSError as exc:
        raise InputError(f"config: cannot read {str(p)!r} ({exc.strerror or exc})") from None
    return parse_config(text, source=str(p))


def parse_config(text: str, source: str = "<string>") -> SweepConfig:
    """Parse YAML ``text`` (safe loader) and validate it."""
    try:
        data = yaml.load(text, Loader=UniqueKeyLoader)  # noqa: S506 -- a SafeLoader subclass
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None) or getattr(exc, "context_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        raise InputError(f"{source}: not valid YAML{where}: {problem}") from None
    return config_from_dict(data, text=text, source=source)


def _fmt_choices(items) -> str:
    return ", ".join(items)


def _axis_values(where: str, axis: str, spec, problems: list[str], info=None,
                 nu=None) -> tuple | None:
    """Expand one axis spec into a tuple of validated values (None on error); ``info`` is the
    axis (default the Scene's); ``nu``, an SI grid's single Poisson's ratio, reads a shear
    Prony table of the ``material`` axis."""
    info = info or SCENE_AXIS_INFO[axis]
    if not info.numeric:
        allowed = info.choices
        vals = spec if isinstance(spec, list) else [spec]
        if not vals:
            problems.append(f"{where}: must not be an empty list")
            return None
        out = []
        for i, v in enumerate(vals):
            w = f"{where}[{i}]" if isinstance(spec, list) else where
            try:
                if axis == "material" and v not in allowed:   # a table, or what is allowed
                    out.append(_table(w, v, nu))
                else:
                    out.append(check_choice(w, v, allowed))
            except InputError as exc:
                problems.append(str(exc))
        return tuple(out) if len(out) == len(vals) else None

    lo, hi = info.limits
    lo_open = info.lo_open
    if isinstance(spec, dict):
        kinds = [k for k in spec if k in RANGE_KINDS]
        unknown = [str(k) for k in spec if k not in RANGE_KINDS]
        if unknown or len(kinds) != 1:
            problems.append(f"{where}: a range must be {{log10: [start, stop, num]}} or "
                            f"{{linspace: [start, stop, num]}} (got keys "
                            f"{', '.join(map(str, spec)) or 'none'})")
            return None
        kind = kinds[0]
        args = spec[kind]
        if not isinstance(args, list) or len(args) != 3:
            problems.append(f"{where}.{kind}: must be a list [start, stop, num] (got {args!r})")
            return None
        try:
            start = as_float(f"{where}.{kind}[0] (start)", args[0])
            stop = as_float(f"{where}.{kind}[1] (stop)", args[1])
            num = check_int(f"{where}.{kind}[2] (num)", args[2], 1, MAX_RANGE_NUM)
        except InputError as exc:
            problems.append(str(exc))
            return None
        if kind == "log10":
            if max(abs(start), abs(stop)) > 300:
                problems.append(f"{where}.log10: start and stop are exponents of 10 and must "
                                f"be in [-300, 300] (got {start:g}, {stop:g})")
                return None
            vals = powers_of_ten(start, stop, num)
        else:
            vals = [float(v) for v in np.linspace(start, stop, num)]
        label = lambda i: f"{where} ({kind} value {i})"  # noqa: E731
    elif isinstance(spec, list):
        if not spec:
            problems.append(f"{where}: must not be an empty list")
            return None
        vals = spec
        label = lambda i: f"{where}[{i}]"  # noqa: E731
    elif isinstance(spec, (int, float, str)) and not isinstance(spec, bool):
        vals = [spec]
        label = lambda i: where  # noqa: E731
    else:
        problems.append(f"{where}: must be a number, a list of numbers, {{log10: [start, "
                        f"stop, num]}} or {{linspace: [start, stop, num]}} (got {spec!r})")
        return None
    out = []
    for i, v in enumerate(vals):
        if isinstance(v, (list, dict)):
            problems.append(f"{label(i)} must be a number (got {v!r})")
            continue
        try:
            out.append(check_range(label(i), v, lo, hi, lo_open=lo_open))
        except InputError as exc:
            problems.append(str(exc))
    return tuple(out) if len(out) == len(vals) else None


def _table(where: str, spec, nu=None) -> SceneTable:
    """A ``material`` value that is a Prony table (``{prony: path}``, relative to the working
    directory, or an inline table; :func:`sweep.scene.scene_table`), a shear table read with
    ``nu`` (an SI grid's), which a ``nu`` given with the table must equal: InputError naming
    it."""
    if not isinstance(spec, (dict, SceneTable)):
        raise InputError(f"{where} must be mpl, sls or a Prony table, given as {{prony: path}} "
                         f"or inline {{tau: [...], E: [...], E0: ...}} (got {spec!r})")
    if nu is not None and isinstance(spec, dict) and spec.get("nu") is not None:
        mine = as_float(f"{where}.nu", spec["nu"])
        if mine != nu:
            raise InputError(f"{where}.nu: the table's Poisson's ratio {mine:g} differs from "
                             f"the grid's nu = {nu:g}; give one")
    try:
        return scene_table(spec, nu=nu)
    except InputError as exc:
        raise InputError(f"{where}: {exc}") from None


def _check_grid(where: str, grid, problems: list[str]) -> dict | None:
    if not isinstance(grid, dict):
        problems.append(f"{where}: must be a mapping of axes ({_fmt_choices(AXES)}) "
                        f"(got {type(grid).__name__})")
        return None
    n_before = len(problems)
    out = {}
    for key in grid:
        if key not in AXES:
            problems.append(f"{where}.{key}: unknown axis (allowed: {_fmt_choices(AXES)})")
    for axis in AXES:
        if SCENE_AXIS_INFO[axis].required and axis not in grid:
            problems.append(f"{where}.{axis}: required axis is missing")
    if "dwell" in grid:
        if "a0" in grid or "delta0" in grid:
            problems.append(f"{where}: a grid with a test protocol (approach_rate, preload, "
                            f"dwell) starts at first contact: give neither a0 nor delta0")
    elif ("a0" in grid) == ("delta0" in grid):
        problems.append(f"{where}: give exactly one of the axes a0 (initial contact radius) "
                        f"and delta0 (initial indentation)")
    for axis in AXES:
        if axis in grid:
            vals = _axis_values(f"{where}.{axis}", axis, grid[axis], problems)
            if vals is not None:
                out[axis] = vals
        elif axis in AXIS_DEFAULTS:
            out[axis] = (AXIS_DEFAULTS[axis],)
    return out if len(problems) == n_before else None


def _si_order(name: str) -> int:
    return SI_AXES[name].order if name in SI_AXES else SCENE_AXIS_INFO[name].order


def _check_si_grid(where: str, grid, problems: list[str]) -> dict | None:
    """Validate a ``units: si`` grid: SI fields (sweep.campaign.si.SI_AXES) and model/material/stop."""
    allowed = (*SI_SCENE_AXES, *SI_AXES)
    if not isinstance(grid, dict):
        problems.append(f"{where}: must be a mapping of SI fields ({_fmt_choices(allowed)}) "
                        f"(got {type(grid).__name__})")
        return None
    n_before = len(problems)
    for key in grid:
        if key not in allowed:
            problems.append(f"{where}.{key}: unknown SI field (allowed: "
                            f"{_fmt_choices(allowed)})")
    tables = any(not isinstance(m, str)
                 for m in (grid.get("material") if isinstance(grid.get("material"), list)
                           else [grid.get("material", "mpl")]))
    for name, info in SI_AXES.items():
        if tables and name in TABLE_FIELDS:   # a table gives them (sweep.campaign.si)
            continue
        if info.required and name not in grid:
            problems.append(f"{where}.{name}: required SI field is missing ({info.help}"
                            f"{', ' + info.unit if info.unit else ''})")
    if sum(a in grid for a in SI_INITIAL) != 1:
        problems.append(f"{where}: give exactly one of preload [N], a0 [m] and indentation [m]")
    out = {}
    # a single Poisson's ratio reads the shear tables of the material axis (a swept nu: a
    # shear table gives its own, and each point's nu must then be it)
    nu = grid.get("nu")
    nu = float(nu) if isinstance(nu, (int, float)) and not isinstance(nu, bool) else None
    for name in allowed:
        if name in grid:
            vals = _axis_values(f"{where}.{name}", name, grid[name], problems,
                                SI_AXES.get(name), nu=nu)
            if vals is not None:
                out[name] = vals
        elif name in SI_SCENE_AXES:
            out[name] = (AXIS_DEFAULTS[name],)
    return out if len(problems) == n_before else None


def _check_numerics(spec, problems: list[str]) -> Numerics | None:
    if spec is None:
        return Numerics.preset("balanced")
    if not isinstance(spec, dict):
        problems.append(f"numerics: must be a mapping such as {{preset: fast}} "
                        f"(got {spec!r})")
        return None
    n_before = len(problems)
    base = {"preset": spec["preset"]} if "preset" in spec else {}
    if "preset" in spec:
        try:
            Numerics.from_dict(base)
        except InputError as exc:
            problems.append(f"numerics.{exc}")
            base = {}
    # check each field on its own so that every problem is reported
    for key, value in spec.items():
        if key == "preset":
            continue
        try:
            Numerics.from_dict({**base, key: value})
        except InputError as exc:
            msg = str(exc)
            problems.append(msg if msg.startswith("numerics") else f"numerics.{msg}")
        except TypeError as exc:  # pragma: no cover - defensive
            problems.append(f"numerics.{key}: {exc}")
    if len(problems) != n_before:
        return None
    try:
        return Numerics.from_dict(spec)
    except InputError as exc:  # combination of individually valid fields
        problems.append(f"numerics: {exc}")
        return None


def config_from_dict(data, text: str | None = None, source: str = "<dict>") -> SweepConfig:
    """Validate a parsed config mapping; raise one InputError listing every problem."""
    problems: list[str] = []
    if data is None:
        raise InputError(f"{source}: config is empty (expected a mapping with keys "
                         f"{_fmt_choices(TOP_KEYS)})")
    if not isinstance(data, dict):
        raise InputError(f"{source}: config must be a mapping with keys "
                         f"{_fmt_choices(TOP_KEYS)} (got {type(data).__name__})")
    for key in data:
        if key not in TOP_KEYS:
            problems.append(f"{key}: unknown key (allowed: {_fmt_choices(TOP_KEYS)})")

    name = data.get("name")
    if name is None:
        problems.append("name: required key is missing (a short name such as 'smoke')")
        name = ""
    elif not isinstance(name, str):           # YAML read it as a number, a date, a list ...
        problems.append(f"name: must be a string, quoted in YAML where it reads as something "
                        f"else (name: \"{name}\") (got {name!r})")
    elif not _NAME_RE.match(name):
        problems.append(f"name: must be a string of letters, digits, '-', '_', '.' "
                        f"(got {name!r})")
    description = data.get("description", "") or ""
    if not isinstance(description, str):
        problems.append(f"description: must be a string (got {description!r})")

    units = data.get("units", "dimensionless")
    if units not in UNITS:
        problems.append(f"units: must be one of {_fmt_choices(UNITS)} (got {units!r})")
        units = "dimensionless"
    check_grid = _check_si_grid if units == "si" else _check_grid

    grids: list[dict] = []
    if "grid" not in data:
        problems.append("grid: required key is missing (a mapping of axes, or a list of them)")
    else:
        g = data["grid"]
        if isinstance(g, list):
            if not g:
                problems.append("grid: must not be an empty list")
            for i, sub in enumerate(g):
                checked = check_grid(f"grid[{i}]", sub, problems)
                if checked is not None:
                    grids.append(checked)
        else:
            checked = check_grid("grid", g, problems)
            if checked is not None:
                grids.append(checked)

    numerics = _check_numerics(data.get("numerics"), problems)

    trajectories = False
    store = data.get("store")
    if store is not None:
        if not isinstance(store, dict):
            problems.append(f"store: must be a mapping such as {{trajectories: true}} "
                            f"(got {store!r})")
        else:
            for key in store:
                if key not in STORE_KEYS:
                    problems.append(f"store.{key}: unknown key (allowed: "
                                    f"{_fmt_choices(STORE_KEYS)})")
            if "trajectories" in store:
                t = store["trajectories"]
                if not isinstance(t, bool):
                    problems.append(f"store.trajectories: must be true or false (got {t!r})")
                else:
                    trajectories = t

    output = data.get("output")
    if output is None:
        output = f"results/{name}.h5" if isinstance(name, str) and name else ""
    elif not isinstance(output, str) or not output.strip():
        problems.append(f"output: must be a file path string (got {output!r})")
        output = ""
    elif output.endswith(("/", os.sep)):
        problems.append(f"output: must name a file, not a directory (got {output!r})")

    total = 0
    for g in grids:
        size = 1
        for v in g.values():
            size *= len(v)
        total += size
    if not problems and total > MAX_SCENES:
        problems.append(f"grid: {total} scenes is more than the maximum {MAX_SCENES}; "
                        f"split the campaign into several configs")
    if problems and grids and total <= MAX_SCENES:
        # the grid points' own checks (a protocol's keys together, two initial states, an
        # SI grid's derived scenes), so that every problem is reported at once: they had
        # come only after the others were fixed
        try:
            SweepConfig(name="check", grids=tuple(grids),
                        numerics=numerics or Numerics.preset("balanced"), trajectories=False,
                        output="", description="", text="", source=source,
                        units=units).tasks()
        except InputError as exc:
            problems.append(str(exc))

    if problems:
        head = f"{source}: " if source else ""
        if len(problems) == 1:
            raise InputError(head + problems[0])
        raise InputError(f"{head}{len(problems)} problems: " + "; ".join(problems))

    cfg = SweepConfig(name=name, grids=tuple(grids), numerics=numerics,
                      trajectories=trajectories, output=output, description=description,
                      text=text or "", source=source, units=units)
    if text is None:
        cfg = dataclasses.replace(cfg, text=yaml.safe_dump(cfg.to_dict(), sort_keys=False))
    try:
        cfg.tasks()  # Scene-level checks (an SI grid's derived scenes are checked here)
    except InputError as exc:
        raise InputError(f"{source}: {exc}") from None
    return cfg


def as_config(config) -> SweepConfig:
    """A :class:`SweepConfig` from a config, a mapping, or a path to a YAML file."""
    if isinstance(config, SweepConfig):
        return config
    if isinstance(config, dict):
        return config_from_dict(config)
    if isinstance(config, (str, os.PathLike)):
        return load_config(config)
    raise InputError(f"config must be a SweepConfig, a mapping or a path "
                     f"(got {type(config).__name__})")


def scale_grid(config: SweepConfig, axis: str, values) -> SweepConfig:
    """A copy of ``config`` whose (first) grid has ``axis`` replaced by ``values``."""
    grids = list(config.grids)
    g = dict(grids[0])
    g[axis] = tuple(values)
    grids[0] = g
    return dataclasses.replace(config, grids=tuple(grids))

"""Crash-safe HDF5 store of a sweep: one results file per sweep, plus a journal while running.

Layout on disk for ``output = results/x.h5``::

    results/x.h5            consolidated HDF5 file (the "main file"); never opened for writing,
                            only ever replaced as a whole with os.replace
    results/x.h5.parts/     exists while a sweep writes (or after it was killed):
        meta.json           config hash, name and text, start time (written atomically)
        journal.jsonl       one JSON line per finished scene: its runs-table row
        traj/<id>.h5        trajectory of one scene (written to a temporary name, fsync-free,
                            then os.replace'd; always written *before* the scene's journal line)
        spool/<pid>.rows    rows local workers finished in dispatch chunks the writer has not
                            received yet (:mod:`sweep.campaign.spool`; scratch, read back
                            after an interrupt or on resume)
    results/x.h5.lock       advisory lock (flock) held by the single writer
    results/x.h5.tmp        a consolidation in progress (a stale one is deleted on next open)

Crash safety. The only writer is the parent process of :func:`sweep.run_sweep`. When a scene
finishes, its trajectory file (if any) is moved into place, then its row is appended to the
journal with a single ``write`` on an ``O_APPEND`` descriptor. Neither step can corrupt earlier
data: a kill (SIGKILL included) can at worst leave a torn *last* line, which readers ignore and
the next writer truncates away. Every few seconds and at the end the writer *consolidates*:
it writes the complete file (previous main file + journal) to ``x.h5.tmp``, fsyncs it and
``os.replace``-s it over ``x.h5``. A reader therefore always sees either the old or the new
complete file, never a half-written one; the main file is never modified in place, so no
crash can damage it. After the final consolidation the ``.parts`` directory is removed and the
sweep is a single self-contained HDF5 file.

Growing. A config whose grid changed but whose units, numerics and trajectory flag did not
(:meth:`ResultStore._grow_refusal` says why not otherwise) resumes onto the same file: scene
ids depend only on the scene and the numerics, so the finished rows stay valid and only the
new ids run. The first consolidation after such a start records the new config (hash, text),
the union's size in ``n_scenes`` and the earlier configs in ``config_history``; until then the
main file still carries the old config, which a resumed grow accepts in the same way, so a
kill at any moment keeps every finished scene.

Source of truth: the main file *plus* the journal. :func:`load` reads the journal first and
then the main file and returns their union (one row per scene id), so it returns every scene
that finished before a kill, even if the kill came before the next consolidation. Resuming a
sweep (running the same command again) reads the same union and skips those scenes.
The journal is not fsynced per scene (a process kill cannot lose page-cache data); it is
fsynced at each consolidation, so a power loss loses at most the last few seconds.

File contents (plain arrays and text only; no pickles):

* ``/runs/<column>``: one 1-D dataset per column of the runs table (float64 with NaN for
  missing values, int64, uint8 for booleans (attribute ``kind = "bool"``), or variable-length
  UTF-8 strings); ``/runs`` attribute ``columns`` gives the column order. One row per finished
  scene: ``scene_id``, the scene parameters, the numerics (``num_*``), every scalar result
  (:data:`sweep.scene.RESULT_SCALARS`, incl. ``status``, ``reason``, ``wall_s``) and the
  scheduler's ``task_wall_s`` and ``task_cpu_s`` (wall and CPU seconds of the task in its
  worker; CPU well below wall means a loaded machine), ``worker`` (host:pid),
  ``finished_at`` (unix time) and ``engine_revision`` (:data:`sweep.scene.ENGINE_REVISION`;
  absent, NaN, in rows written before it was recorded, which are revision 1).
* ``/trajectories/<scene_id>/{t, delta, P, a, a_inner}`` when the config asks for them.
* Numeric columns and trajectory arrays carry HDF5's Fletcher-32 checksum (``fletcher32``;
  files written before session 50 have none): a damaged one is an InputError on reading.
* File attributes: ``format``, ``format_version``, ``config_name``, ``config_hash``,
  ``config_text``, ``config_source``, ``package_version``, ``git_commit``, ``numba_version``,
  ``numpy_version``, ``h5py_version``, ``python_version``, ``started_at``, ``updated_at``,
  ``finished_at`` (ISO 8601 UTC; ``finished_at`` is empty until every scene is done),
  ``n_scenes`` (size of the grid), ``n_finished``, ``complete``, ``trajectories``,
  ``scene_id_version`` (:data:`sweep.scene.SCENE_ID_VERSION`; absent in files written before
  it was recorded, which are version 1), and in a grown file ``config_history`` (JSON list of
  the earlier configs' ``config_hash``, ``config_text``, ``until``). A file of a newer id
  version is refused for resuming (one-line error, file untouched); it still loads.
"""
from __future__ import annotations

import contextlib
import dataclasses
import errno
import json
import math
import os
import platform
import shutil
import subprocess
import time
from datetime import datetime, timezone
from importlib import metadata
from pathlib import Path
from typing import TYPE_CHECKING

import h5py
import numpy as np

from .._version import __version__
from ..errors import InputError
from ..scene import (ENGINE_REVISION, REVISION_CHANGES, SCENE_AXES, SCENE_ID_VERSION,
                     TABLE_MATERIAL, Numerics)
from .config import parse_config
from .si import si_row

try:
    import fcntl
except ImportError:  # pragma: no cover - not POSIX: no advisory lock
    fcntl = None

if TYPE_CHECKING:
    # pandas (about 0.3 s to import) is imported in the functions that build tables: every
    # sweep worker imports this module (through the scheduler) and never needs pandas.
    import pandas as pd

FORMAT = "visco-sweep-results"
FORMAT_VERSION = 1
JOURNAL = "journal.jsonl"
META = "meta.json"


class StoreBusyError(RuntimeError):
    """Another process is writing the same results file."""


# ----------------------------------------------------------------------------- paths
def real_path(path) -> Path:
    """``path``, or the file it names when it is a symbolic link: a results file reached
    through a link is the file itself, with its own journal, lock and consolidation (a link
    replaced by a private copy, and two writers through two names, are what this prevents)."""
    path = Path(path)
    return Path(os.path.realpath(path)) if path.is_symlink() else path


def parts_dir(path) -> Path:
    path = real_path(path)
    return path.with_name(path.name + ".parts")


def error_log_path(path) -> Path:
    """The log of internal errors beside the results file ``path``: ``<path>.errors.log``."""
    path = real_path(path)
    return path.with_name(path.name + ".errors.log")


def _lock_path(path: Path) -> Path:
    return path.with_name(path.name + ".lock")


def _tmp_path(path: Path) -> Path:
    return path.with_name(path.name + ".tmp")


def now_iso() -> str:
    return datetime.now(timezone.utc).isoformat(timespec="seconds")


def _fsync_path(p: Path, directory: bool = False) -> None:
    try:
        fd = os.open(p, os.O_RDONLY | (getattr(os, "O_DIRECTORY", 0) if directory else 0))
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


# ----------------------------------------------------------------------------- values
def plain(value):
    """A JSON/HDF5-friendly Python value (numpy scalars unwrapped, objects stringified)."""
    if value is None or isinstance(value, (bool, str)):
        return value
    if isinstance(value, np.bool_):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return float(value)
    return str(value)


def plain_row(row: dict) -> dict:
    return {str(k): plain(v) for k, v in row.items()}


def to_jsonable(obj):
    """``obj`` with numpy arrays and scalars made plain Python (lists, floats), dict keys made
    strings and non-finite floats made None, so that ``json.dumps`` accepts it."""
    if isinstance(obj, dict):
        return {str(k): to_jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [to_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return to_jsonable(obj.tolist())
    if isinstance(obj, np.generic):
        obj = obj.item()
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    return obj


def _column_kind(values) -> str:
    """Storage kind of a column: "str", "bool", "int" or "float" (None -> NaN)."""
    has_none = False
    kinds = set()
    for v in values:
        if v is None:
            has_none = True
        elif isinstance(v, str):
            return "str"
        elif isinstance(v, bool):
            kinds.add("bool")
        elif isinstance(v, int):
            kinds.add("int")
        else:
            kinds.add("float")
    if not has_none and kinds == {"bool"}:
        return "bool"
    if not has_none and kinds == {"int"}:
        return "int"
    return "float"


def _column_array(values, kind: str) -> np.ndarray:
    if kind == "str":
        return np.array(["" if v is None else str(v) for v in values], dtype=object)
    if kind == "bool":
        return np.array([1 if v else 0 for v in values], dtype=np.uint8)
    if kind == "int":
        return np.array(values, dtype=np.int64)
    return np.array([math.nan if v is None else float(v) for v in values], dtype=np.float64)


def _frame_from_rows(rows: list[dict], columns: list[str] | None = None) -> pd.DataFrame:
    import pandas as pd  # lazy: see TYPE_CHECKING above (workers never build a table)

    if columns is None:
        columns = _column_order(rows)
    data = {}
    for c in columns:
        vals = [r.get(c) for r in rows]
        kind = _column_kind(vals)
        arr = _column_array(vals, kind)
        data[c] = arr.astype(bool) if kind == "bool" else arr
    return pd.DataFrame(data, columns=columns)


def _column_order(rows) -> list[str]:
    order: dict[str, None] = {"scene_id": None}
    for r in rows:
        for k in r:
            order.setdefault(k, None)
    return list(order)


# ----------------------------------------------------------------------------- reading
def _read_journal(path: Path) -> list[dict]:
    """Complete rows of the journal of ``path`` (a torn or garbled line is skipped)."""
    jp = parts_dir(path) / JOURNAL
    try:
        data = jp.read_bytes()
    except (FileNotFoundError, NotADirectoryError):
        return []
    rows = []
    for line in data.split(b"\n")[:-1]:  # the piece after the last newline is incomplete
        if not line.strip():
            continue
        try:
            row = json.loads(line)
        except ValueError:
            continue
        if isinstance(row, dict) and isinstance(row.get("scene_id"), str):
            rows.append(row)
    return rows


def _open_main(path: Path):
    if path.is_dir():
        raise InputError(f"{path} is a directory, not a results file (give the .h5 file)")
    try:
        f = h5py.File(path, "r")
    except (OSError, ValueError) as exc:
        raise InputError(f"{path}: not a readable HDF5 results file "
                         f"({' '.join(str(exc).split())})") from None
    if f.attrs.get("format") != FORMAT:
        f.close()
        raise InputError(f"{path}: not a visco-sweep results file (no format attribute "
                         f"{FORMAT!r})")
    return f


def _read_runs_frame(f) -> pd.DataFrame:
    import pandas as pd  # lazy: see TYPE_CHECKING above

    if "runs" not in f:
        return pd.DataFrame({"scene_id": pd.Series([], dtype=object)})
    g = f["runs"]
    columns = [str(c) for c in g.attrs.get("columns", list(g.keys()))]
    data = {}
    for c in columns:
        ds = g[c]
        kind = ds.attrs.get("kind", "")
        if kind == "str" or h5py.check_string_dtype(ds.dtype) is not None:
            data[c] = np.array(ds.asstr()[()], dtype=object)
        else:
            data[c] = _checked(ds, f"the column {c}")
            if kind == "bool":
                data[c] = data[c].astype(bool)
    return pd.DataFrame(data, columns=columns)


def _checked(ds, what: str) -> np.ndarray:
    """The values of the dataset ``ds``; a checksum that fails (a numeric column or a
    trajectory array written since session 50 carries one, ``fletcher32``) is an
    InputError naming the file and ``what``."""
    try:
        return ds[()]
    except OSError as exc:
        raise InputError(f"{ds.file.filename}: {what} does not read "
                         f"({' '.join(str(exc).split())}): the file is damaged (by the disk "
                         f"or by hand); it is left as it is") from None


def _read_runs_rows(f) -> list[dict]:
    df = _read_runs_frame(f)
    rows = []
    cols = list(df.columns)
    for rec in df.itertuples(index=False, name=None):
        rows.append({c: plain(v) for c, v in zip(cols, rec)})
    return rows


def read_attrs(path) -> dict:
    """File attributes of a results file (the journal's meta if no main file exists yet)."""
    path = Path(path)
    if path.exists():
        with _open_main(path) as f:
            return {k: plain(v) if not isinstance(v, np.ndarray) else v.tolist()
                    for k, v in f.attrs.items()}
    meta = parts_dir(path) / META
    if meta.exists():
        return json.loads(meta.read_text())
    raise FileNotFoundError(f"no results at {path}")


def load(path) -> pd.DataFrame:
    """The runs table of a sweep as a DataFrame: one row per finished scene.

    Includes scenes that finished after the last consolidation of a running or killed sweep
    (read from its journal). Columns: ``scene_id``, scene parameters, ``num_*`` numerics,
    scalar results, ``status``, ``reason``, ``wall_s``, ``task_wall_s``, ``worker``,
    ``finished_at``. Missing numbers are NaN (e.g. ``delta0`` of an ``a0`` scene).
    """
    import pandas as pd  # lazy: see TYPE_CHECKING above

    path = Path(path)
    # journal first, then main: a consolidation that removes the journal in between has
    # already put its rows into the main file.
    jrows = _read_journal(path)
    if path.exists():
        with _open_main(path) as f:
            main = _read_runs_frame(f)
    elif jrows or parts_dir(path).exists():
        main = None
    else:
        raise FileNotFoundError(f"no results at {path}")
    # the journal is newer than the main file: its row of a scene replaces the main file's
    # (a scene run again on resume, an internal error's, appends its new row there), and of
    # two journal rows of one scene the later one counts
    newer = list({r["scene_id"]: r for r in jrows}.values())
    if main is None:
        return _frame_from_rows(newer) if newer else \
            pd.DataFrame({"scene_id": pd.Series([], dtype=object)})
    if not newer:
        return main
    cols = list(main.columns) + [c for c in _column_order(newer) if c not in main.columns]
    jf = _frame_from_rows(newer, cols)
    kept = main[~main["scene_id"].isin({r["scene_id"] for r in newer})]
    if len(kept) == 0:
        return jf                   # one row per scene already (newer)
    return _dedupe(pd.concat([kept, jf], ignore_index=True))


def load_results(path) -> pd.DataFrame:
    """:func:`load` of a path a user gave (``results``): an InputError naming it if it is not
    a file or not a sweep results file."""
    if not Path(path).is_file():
        raise InputError(f"results: no such file {str(path)!r}")
    try:
        return load(path)
    except (OSError, KeyError, ValueError) as exc:
        raise InputError(f"results: {str(path)!r} is not a sweep results file ({exc})") from None


#: a stored scene is a config's scene whose floats differ from it in the last bits (a grid
#: whose powers of ten another machine's numpy rounded otherwise, before
#: :func:`sweep.campaign.config.powers_of_ten`) where every float agrees to this relative
#: difference (a few units in the last place) and every other field is equal
TWIN_RTOL = 1e-14
#: the significant digits of the floats by which candidate twins are looked up (two floats
#: TWIN_RTOL apart round apart here once in about 1e4: that scene then runs again)
TWIN_DIGITS = 10
#: a Prony-table scene of an SI grid written before the table's moduli were read at its
#: hash's 10 digits (:func:`sweep.materials.prony_files.hash_rounded`): its floats derived
#: from the relaxed modulus (mu, a0, preload, ...) differ from today's by up to ~1e-10
#: relative, and are looked up at 6 digits (two such floats round apart there once in 1e4)
TABLE_TWIN_RTOL, TABLE_TWIN_DIGITS = 1e-9, 6


def _twin_fields(scene, numerics) -> dict | None:
    """A task's fields as a stored row holds them (the scene's, the numerics' as ``num_``),
    numbers as floats, None for none; None where a field is not a scalar."""
    out = {}
    for key, value in [*scene.to_dict().items(),
                       *((f"num_{k}", v) for k, v in numerics.to_dict().items())]:
        v = _twin_scalar(value)
        if v is NotImplemented:
            return None
        out[key] = v
    return out


def _twin_scalar(value):
    if value is None or isinstance(value, (bool, np.bool_, str)):
        return value
    if isinstance(value, bytes):
        return value.decode()
    if isinstance(value, (int, float, np.integer, np.floating)):
        x = float(value)
        return None if math.isnan(x) else x
    return NotImplemented


def _twin_key(fields: dict, digits: int = TWIN_DIGITS) -> tuple:
    return tuple(sorted((k, float(f"{v:.{digits}g}") if isinstance(v, float) else v)
                        for k, v in fields.items() if k != "scene_id"))


def _is_table(fields: dict) -> bool:
    return str(fields.get("material", "")).startswith(f"{TABLE_MATERIAL}:")


def rounding_twins(tasks, rows, numerics) -> dict[str, str]:
    """The ids of ``tasks`` ((scene id, Scene) with the config's ``numerics``) whose scene a
    stored row (``rows``) holds with other last bits (TWIN_RTOL): a file written on a
    machine whose numpy rounded a ``log10`` grid otherwise, before the grids' powers of ten
    were correctly rounded (:func:`sweep.campaign.config.powers_of_ten`); or, for a Prony
    table's scene (TABLE_TWIN_RTOL), a file of an SI grid written before the table's moduli
    were read at its hash's digits. Such a scene is finished, not run again (its row keeps
    the floats it ran with). Rows of an internal error do not count. Returns {task's id:
    the stored row's id}."""
    wanted = [(sid, f) for sid, f in ((sid, _twin_fields(scene, numerics))
                                      for sid, scene in tasks) if f is not None]
    if not wanted:
        return {}
    keys = sorted(wanted[0][1])
    keys_with_id = [*keys, "scene_id"]
    index: dict = {}
    for row in rows:
        if row.get("status") == "error":
            continue
        fields = {k: _twin_scalar(row.get(k)) for k in keys_with_id}
        if NotImplemented not in fields.values():
            digits = TABLE_TWIN_DIGITS if _is_table(fields) else TWIN_DIGITS
            index.setdefault(_twin_key(fields, digits), []).append(fields)
    found = {}
    for sid, want in wanted:
        table = _is_table(want)
        rtol = TABLE_TWIN_RTOL if table else TWIN_RTOL
        key = _twin_key(want, TABLE_TWIN_DIGITS if table else TWIN_DIGITS)
        for fields in index.get(key, []):
            if all(v == fields.get(k) or (
                    isinstance(v, float) and isinstance(fields.get(k), float)
                    and abs(v - fields[k]) <= rtol * abs(v)) for k, v in want.items()):
                found[sid] = fields["scene_id"]
                break
    return found


def recorded_numerics(path) -> Numerics | None:
    """The numerics the rows of the results at ``path`` ran with (their ``num_*`` columns;
    fields added since take their defaults), or None when the file has no rows or its rows
    ran with more than one set.

    A file written before a preset or default changed resumes under these values when a
    config gives them explicitly (:meth:`ResultStore.prepare`).
    """
    try:
        df = load(path)
    except (OSError, KeyError, ValueError):
        return None
    cols = [c for c in df.columns if c.startswith("num_")]
    if len(df) == 0 or not cols:
        return None
    distinct = df[cols].astype(str).drop_duplicates()
    if len(distinct) != 1:
        return None
    values = {}
    for c in cols:
        v = plain(df[c].iloc[0])
        values[c[len("num_"):]] = None if isinstance(v, float) and math.isnan(v) else v
    try:
        return Numerics(**values)
    except (InputError, TypeError):
        return None


def _numerics_diff(a, b) -> str:
    """The fields in which two Numerics differ, as "name a -> b", comma-separated."""
    da, db = a.to_dict(), b.to_dict()
    return ", ".join(f"{k} {da.get(k)!r} -> {db.get(k)!r}" for k in sorted(set(da) | set(db))
                     if da.get(k) != db.get(k))


#: what a refusal for changed numerics advises (one line, with the fields named before it)
PIN_ADVICE = "give the file's values in this config's numerics to resume it"


def _history(value) -> list[dict]:
    """The ``config_history`` attribute of a grown file: a list of {config_hash, config_text,
    until} of the earlier configs whose scenes it holds (empty for a file that never grew)."""
    if not value:
        return []
    try:
        items = json.loads(str(value))
    except ValueError:
        return []
    return [e for e in items if isinstance(e, dict) and "config_hash" in e]


def _dedupe(df: pd.DataFrame) -> pd.DataFrame:
    return df.drop_duplicates("scene_id", keep="first").reset_index(drop=True)


def load_trajectory(path, scene_id: str) -> dict:
    """Trajectory arrays of one scene: ``t`` (tau0), ``delta`` (d_ref), ``P`` (pi dg R),
    ``a``, ``a_inner`` (a_ref), and with a test protocol ``phase`` (0 approach, 1 dwell, 2
    retraction; :attr:`sweep.Result.trajectory`). KeyError if the file keeps none or not
    this scene's; FileNotFoundError if there is no file; TypeError if ``scene_id`` is not a
    string (the ``scene_id`` column of :func:`load`)."""
    if not isinstance(scene_id, str):
        raise TypeError(f"scene_id must be a string, the scene_id column of sweep.load "
                        f"(got {scene_id!r})")
    path = Path(path)
    part = parts_dir(path) / "traj" / f"{scene_id}.h5"
    if part.exists():
        with contextlib.suppress(OSError), h5py.File(part, "r") as f:
            return {k: f[k][()] for k in f.keys()}
    if path.exists():
        with _open_main(path) as f:
            g = f.get("trajectories")
            if g is not None and scene_id in g:
                return {k: _checked(g[scene_id][k], f"the trajectory {scene_id}/{k}")
                        for k in g[scene_id].keys()}
            trajectories = bool(f.attrs.get("trajectories", 0))
    elif parts_dir(path).exists():
        trajectories = bool(read_attrs(path).get("trajectories", False))
    else:
        raise FileNotFoundError(f"no results at {path}")
    if not trajectories:
        raise KeyError(f"{path} holds no trajectories (set store: {{trajectories: true}} in "
                       f"the config to keep them)")
    raise KeyError(f"no trajectory for scene {scene_id!r} in {path}")


def si_table(results) -> pd.DataFrame:
    """The rows of a results file written by a ``units: si`` config, in both systems.

    The SI inputs of each scene come from the config the file records (``config_text``),
    expanded again: columns ``scene_id``, ``model`` (requested), ``model_used``, ``status``,
    the SI inputs
    (``si_R``, ``si_speed``, ...), ``mu``, ``k``, ``rate``, ``l0_m``, ``a_ref_m``,
    ``d_ref_m``, ``load_ref_N``, ``jkr_pull_off_N``, ``pull_off_N``, ``a_pulloff_m``,
    ``crack_speed_m_s``, ... and the dimensionless ``pull_off``. InputError if the file was
    not written by an SI config.
    """
    import pandas as pd  # lazy: see TYPE_CHECKING above

    text = str(read_attrs(results).get("config_text", ""))
    cfg = parse_config(text, source=str(results)) if text else None
    if cfg is None or cfg.units != "si":
        raise InputError(f"results: {results} was not written by a `units: si` config")
    by_id = dict(cfg.si_tasks())
    for entry in _history(read_attrs(results).get("config_history", "")):
        with contextlib.suppress(InputError):   # a grown file: the earlier grids' points too
            for sid, si in parse_config(entry["config_text"]).si_tasks():
                by_id.setdefault(sid, si)
    rows = []
    for row in load(results).to_dict("records"):
        si = by_id.get(row["scene_id"])
        if si is None:
            continue
        rows.append({"scene_id": row["scene_id"], "model": row.get("model"),
                     "model_used": row.get("model_used"),
                     "status": row.get("status"), "pull_off": row.get("pull_off"),
                     **si_row(si, row)})
    return pd.DataFrame(rows)


# ----------------------------------------------------------------------------- provenance
def provenance() -> dict:
    """Versions and git commit of the code that writes a results file."""
    commit = "unknown"
    here = Path(__file__).resolve().parent
    try:
        out = subprocess.run(["git", "-C", str(here), "rev-parse", "HEAD"], capture_output=True,
                             text=True, timeout=5)
        if out.returncode == 0:
            commit = out.stdout.strip()
            dirty = subprocess.run(["git", "-C", str(here), "status", "--porcelain",
                                    "--untracked-files=no"], capture_output=True, text=True,
                                   timeout=5)
            if dirty.returncode == 0 and dirty.stdout.strip():
                commit += "-dirty"
    except (OSError, subprocess.SubprocessError):
        pass
    return {
        "package_version": __version__,
        "git_commit": commit,
        "numba_version": _distribution_version("numba"),
        "numpy_version": np.__version__,
        "h5py_version": h5py.__version__,
        "python_version": platform.python_version(),
    }


def _distribution_version(name: str) -> str:
    """The installed version of the distribution ``name`` (read from its metadata, without
    importing it), or "unknown"."""
    try:
        return metadata.version(name)
    except metadata.PackageNotFoundError:  # pragma: no cover - a dependency of this package
        return "unknown"


# ----------------------------------------------------------------------------- writing
def _write_traj_file(target: Path, traj: dict) -> None:
    tmp = target.with_name(target.name + f".tmp{os.getpid()}")
    with h5py.File(tmp, "w") as f:
        for k, v in traj.items():
            f.create_dataset(str(k), data=np.asarray(v, dtype=np.float64), fletcher32=True)
    os.replace(tmp, target)


def _backup_name(path: Path) -> Path:
    cand = path.with_name(path.name + ".bak")
    i = 1
    while cand.exists() or parts_dir(cand).exists() or error_log_path(cand).exists():
        cand = path.with_name(f"{path.name}.bak{i}")
        i += 1
    return cand


class ResultStore:
    """The single writer of one results file (see the module docstring for the layout).

    Use: ``prepare(resume)`` (lock + compatibility checks, no changes on disk),
    ``begin(fresh)`` (returns the ids already finished), ``append(row, traj)`` per scene,
    ``maybe_consolidate()`` now and then, ``finish(complete)`` at the end (also on errors).
    """

    def __init__(self, path, *, config_hash: str, config_name: str = "", config_text: str = "",
                 config_source: str = "", n_scenes: int = 0, trajectories: bool = False,
                 template_row: dict | None = None, interval: float = 5.0, config=None):
        self.path = real_path(path)
        #: the SweepConfig being run (optional): lets a results file of the same numerics and
        #: trajectory flag *grow* to this config's grid (see :meth:`prepare`)
        self.config = config
        #: (config hash, config text) of the earlier configs whose results this file holds
        #: when it grew; empty when it did not
        self.grown_from: list[tuple[str, str]] = []
        self._grow_ids: set[str] = set()
        self.parts = parts_dir(self.path)
        #: the journal's meta.json did not read, and the main file named the sweep
        self._meta_unreadable = False
        self.config_hash = config_hash
        self.meta = {
            "format": FORMAT, "format_version": FORMAT_VERSION,
            "config_name": config_name, "config_hash": config_hash,
            "config_text": config_text, "config_source": config_source,
            "n_scenes": int(n_scenes), "trajectories": bool(trajectories),
            "scene_id_version": SCENE_ID_VERSION, "started_at": now_iso(),
        }
        self.trajectories = bool(trajectories)
        self.template = plain_row(template_row or {"scene_id": ""})
        self.interval = float(interval)
        self.rows: list[dict] = []
        self._ids: dict[str, int] = {}
        self._lock_fd = None
        self._jfd = None
        self._dirty = False
        self._main_complete = False
        self._last = time.monotonic()
        self._last_cost = 0.0
        self.backup: Path | None = None
        self._prov = None

    # -- locking ----------------------------------------------------------------
    def _acquire(self) -> None:
        lp = _lock_path(self.path)
        if fcntl is None:  # pragma: no cover
            return
        for _ in range(5):
            fd = os.open(lp, os.O_RDWR | os.O_CREAT, 0o644)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError as exc:
                os.close(fd)
                if exc.errno in (errno.EAGAIN, errno.EACCES):
                    raise StoreBusyError(f"another sweep is writing {self.path} (lock "
                                         f"{lp} is held); wait for it or use --out") from None
                raise
            try:
                same = os.fstat(fd).st_ino == os.stat(lp).st_ino
            except FileNotFoundError:
                same = False
            if same:
                self._lock_fd = fd
                return
            os.close(fd)  # the lock file was replaced under us; retry
        raise StoreBusyError(f"cannot lock {lp}")

    def _release(self) -> None:
        if self._lock_fd is not None:
            with contextlib.suppress(OSError):
                os.unlink(_lock_path(self.path))
            os.close(self._lock_fd)
            self._lock_fd = None

    # -- checks -----------------------------------------------------------------
    def _existing_hashes(self) -> list[tuple[str, str, int, str]]:
        """(where, config hash, scene id version, config text) of the main file and the
        journal's meta.

        Files written before the id version was recorded are version 1.
        """
        found = []
        if self.path.exists():
            if self.path.is_dir():
                raise InputError(f"output {self.path} is a directory; give a file path "
                                 f"such as {self.path}/results.h5")
            try:
                with _open_main(self.path) as f:
                    found.append((str(self.path), str(f.attrs.get("config_hash", "")),
                                  int(f.attrs.get("scene_id_version", 1)),
                                  str(f.attrs.get("config_text", ""))))
            except InputError as exc:
                raise InputError(f"{exc}; refusing to overwrite it: use --out to write "
                                 f"elsewhere, or --fresh to move it aside to a .bak file") \
                    from None
        meta = self.parts / META
        if meta.exists():
            try:
                m = json.loads(meta.read_text())
                found.append((str(self.parts), m["config_hash"],
                              int(m.get("scene_id_version", 1)), str(m.get("config_text", ""))))
            except (ValueError, KeyError, OSError, TypeError) as exc:
                if not found:
                    raise InputError(
                        f"{meta} does not read ({type(exc).__name__}), so which config wrote "
                        f"the finished scenes in {self.parts} is unknown; use --fresh to move "
                        f"them aside (kept as a .bak) or --out to write elsewhere") from None
                # the main file's own config identifies the sweep: begin writes it again
                self._meta_unreadable = True
        return found

    def prepare(self, resume: bool = True) -> None:
        """Take the lock and check that the existing results (if any) are compatible.

        With ``resume`` an existing file written by a different config is an
        :class:`InputError`; nothing on disk is changed here either way.
        """
        self._acquire()
        try:
            hashes = self._existing_hashes() if resume else []
            if not resume and self.path.is_dir():
                raise InputError(f"output {self.path} is a directory; give a file path")
            for where, h, version, text in hashes:
                if version > SCENE_ID_VERSION:
                    raise InputError(
                        f"{where} was written with scene id version {version}, newer than this "
                        f"visco-sweep's {SCENE_ID_VERSION}: resume it with the version that "
                        f"wrote it, or use --out to write elsewhere")
                if h != self.config_hash and text and text == self.meta.get("config_text"):
                    ran = recorded_numerics(self.path)
                    if (ran is not None and self.config is not None
                            and ran == self.config.numerics):
                        # the same numerics: the grid's floats came out otherwise where the
                        # file was written (sweep.campaign.config.powers_of_ten); its
                        # scenes count as the config's (scheduler.rounding_twins)
                        continue
                    diff = (_numerics_diff(ran, self.config.numerics)
                            if ran is not None and self.config is not None else "")
                    what = f" (its rows ran with other values: {diff})" if diff else ""
                    raise InputError(
                        f"{where} was written by this same config when its numerics meant "
                        f"other values{what}; a preset or default changed since, the file's "
                        f"scenes are kept and still load: {PIN_ADVICE}, use --fresh to "
                        f"recompute (the old file is kept as a .bak) or --out to write "
                        f"elsewhere")
                if h != self.config_hash:
                    reason = self._grow_refusal(h, text)
                    if reason is None:
                        continue          # the same numerics: the grid grows onto this file
                    raise InputError(
                        f"{where} holds results of a different config (config hash {h}, this "
                        f"config {self.config_hash}) that cannot grow into this one: {reason}; "
                        f"use --fresh to start over (the old file is kept as a .bak) or --out "
                        f"to write elsewhere")
        except BaseException:
            self._release()
            raise

    def _grow_refusal(self, old_hash: str, old_text: str) -> str | None:
        """Why results of the config ``old_text`` (hash ``old_hash``) cannot grow into this
        config's file, or None when they can: the same units, numerics and trajectory flag
        (the grid alone changed; scene ids depend on the scene and the numerics only, so the
        finished scenes are kept and only the new ones run). Records what it accepts."""
        if not old_text:
            return "the file records no config text to compare numerics with"
        try:
            old = parse_config(old_text, source="the file's config")
        except InputError as exc:
            return f"its recorded config no longer reads ({exc})"
        if old.config_hash != old_hash:
            # a preset or default changed since: the file's scenes ran with the numerics
            # its rows record, and grow into a config that gives those explicitly
            meant = ("its config's numerics meant other values when it was written (a "
                     "preset or default changed since)")
            ran = recorded_numerics(self.path)
            if ran is None:
                return meant
            old = dataclasses.replace(old, numerics=ran)
            changed = f"{meant} and its rows ran with other values than this config's ("
        else:
            changed = "numerics differ ("
        new = self.config
        if new is None:
            try:
                new = parse_config(str(self.meta.get("config_text", "")), source="config")
            except InputError as exc:
                return f"this config's text does not read ({exc})"
        if old.units != new.units:
            return f"units differ (file {old.units}, this config {new.units})"
        if old.numerics != new.numerics:
            return (f"{changed}{_numerics_diff(old.numerics, new.numerics) or 'preset'}); "
                    f"{PIN_ADVICE}")
        if old.trajectories != new.trajectories:
            return (f"store.trajectories differs (file {str(old.trajectories).lower()}, this "
                    f"config {str(new.trajectories).lower()})")
        if (old_hash, old_text) not in self.grown_from:
            self.grown_from.append((old_hash, old_text))
            self._grow_ids.update(sid for sid, _ in old.tasks())
        return None

    # -- opening ----------------------------------------------------------------
    def begin(self, fresh: bool = False) -> set[str]:
        """Move old results aside (``fresh``) or load them (resume); return finished ids."""
        with contextlib.suppress(FileNotFoundError):
            _tmp_path(self.path).unlink()
        if fresh and (self.path.exists() or self.parts.exists()):
            self.backup = _backup_name(self.path)
            if self.path.exists():
                os.replace(self.path, self.backup)
            if self.parts.exists():
                os.replace(self.parts, parts_dir(self.backup))
            # the old file's internal errors go with it
            if error_log_path(self.path).exists():
                os.replace(error_log_path(self.path), error_log_path(self.backup))
        started = None
        history = []
        if self.path.exists():
            with _open_main(self.path) as f:
                started = f.attrs.get("started_at")
                history = _history(f.attrs.get("config_history", ""))
                self._main_complete = bool(f.attrs.get("complete", 0))
                for row in _read_runs_rows(f):
                    self._add(row)
        meta = self.parts / META
        if meta.exists() and started is None:
            with contextlib.suppress(ValueError, OSError, KeyError):
                m = json.loads(meta.read_text())
                history = history or _history(m.get("config_history", ""))
                started = m["started_at"]
        if started:
            self.meta["started_at"] = str(started)
        for row in _read_journal(self.path):
            # newer than the main file's row of the scene, if it has one (load's rule)
            if row["scene_id"] in self._ids:
                self.rows[self._ids[row["scene_id"]]] = row
            else:
                self._add(row)
            self._dirty = True
        if self.grown_from:
            # growing: the file's grid is the union of this config's and the earlier ones'
            # (the attribute config_history keeps the earlier configs' hashes and texts)
            for h, text in self.grown_from:
                if not any(e["config_hash"] == h for e in history):
                    history.append({"config_hash": h, "config_text": text,
                                    "until": now_iso()})
            self._dirty = True   # consolidate now: the main file records the grown grid
        # this config is the file's own now, not an earlier one (an earlier, smaller config
        # run again on a grown file had listed itself among them)
        history = [e for e in history if e["config_hash"] != self.config_hash]
        if history:
            self.meta["config_history"] = json.dumps(history)
        # the config's scenes that a row holds with other last bits count as finished
        twins = {}
        if self.config is not None and self.rows:
            tasks = self.config.tasks()
            missing = [(sid, scene) for sid, scene in tasks if sid not in self._ids]
            twins = rounding_twins(missing, self.rows, self.config.numerics) if missing else {}
        if self.config is not None and (self.grown_from or history):
            ids = ({sid for sid, _ in self.config.tasks()}
                   | ((set(self._ids) | self._grow_ids) - set(twins.values())))
            self.meta["n_scenes"] = len(ids)
        # the main file exists before the journal does, so a reader always finds a schema
        if not self.path.exists() or self._dirty:
            self.consolidate()
        # journal: create or repair (truncate a torn last line), then open for appending
        (self.parts / "traj").mkdir(parents=True, exist_ok=True)
        if not meta.exists() or self.grown_from or self._meta_unreadable:
            tmp = meta.with_name(META + ".tmp")
            tmp.write_text(json.dumps(self.meta))
            os.replace(tmp, meta)
        jp = self.parts / JOURNAL
        if jp.exists():
            data = jp.read_bytes()
            if data and not data.endswith(b"\n"):
                with open(jp, "r+b") as fh:
                    fh.truncate(data.rfind(b"\n") + 1)
        self._jfd = os.open(jp, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o644)
        return set(self._ids) | set(twins)

    def holds(self, scene_id: str) -> bool:
        """Whether a row of ``scene_id`` is stored (read or appended)."""
        return scene_id in self._ids

    def status(self, scene_id: str) -> str | None:
        """The stored row's ``status`` of ``scene_id``, or None when none is stored."""
        i = self._ids.get(scene_id)
        return None if i is None else self.rows[i].get("status")

    def _add(self, row: dict) -> None:
        self._ids[row["scene_id"]] = len(self.rows)
        self.rows.append(row)

    # -- appending --------------------------------------------------------------
    def append(self, row: dict, trajectory: dict | None = None) -> None:
        """Record one finished scene (trajectory file first, then its journal line)."""
        row = plain_row(row)
        sid = row["scene_id"]
        if self.trajectories and trajectory:
            _write_traj_file(self.parts / "traj" / f"{sid}.h5", trajectory)
        line = (json.dumps(row, separators=(",", ":"), allow_nan=True) + "\n").encode()
        view = memoryview(line)
        while view:
            n = os.write(self._jfd, view)
            view = view[n:]
        if sid in self._ids:
            self.rows[self._ids[sid]] = row
        else:
            self._add(row)
        self._dirty = True

    def maybe_consolidate(self) -> bool:
        """Consolidate if ``interval`` seconds have passed since the last consolidation.

        The wait is also at least 20x the cost of the last consolidation (at most ~5% of the
        time goes to consolidating a large file), except with ``interval == 0``, which
        consolidates after every scene (for tests).
        """
        wait = self.interval if self.interval == 0 else max(self.interval, 20 * self._last_cost)
        if self._dirty and time.monotonic() - self._last >= wait:
            self.consolidate()
            return True
        return False

    # -- consolidation ----------------------------------------------------------
    def _write_runs(self, f) -> None:
        g = f.create_group("runs")
        rows = self.rows
        columns = _column_order([self.template] + rows)
        for c in columns:
            vals = [r.get(c) for r in rows] if rows else [self.template.get(c)]
            kind = _column_kind(vals)
            arr = _column_array(vals, kind)[: len(rows)]
            if kind == "str":           # HDF5 takes no filter on strings
                ds = g.create_dataset(c, data=arr, dtype=h5py.string_dtype("utf-8"))
            else:                       # a checksum: damage fails the read (_checked)
                ds = g.create_dataset(c, data=arr, fletcher32=True)
            ds.attrs["kind"] = kind
        g.attrs["columns"] = np.array(columns, dtype=h5py.string_dtype("utf-8"))

    def consolidate(self, complete: bool | None = None) -> None:
        """Write main file + journal to ``<output>.tmp``, fsync, and os.replace it in place."""
        t0 = time.monotonic()
        if self._jfd is not None:
            with contextlib.suppress(OSError):
                os.fsync(self._jfd)
        if self._prov is None:
            self._prov = provenance()
        n_done = len(self.rows)
        if complete is None:
            complete = self.meta["n_scenes"] > 0 and n_done >= self.meta["n_scenes"]
        tmp = _tmp_path(self.path)
        old = None
        try:
            if self.trajectories and self.path.exists():
                old = h5py.File(self.path, "r")
            with h5py.File(tmp, "w") as f:
                for k, v in {**self.meta, **self._prov}.items():
                    f.attrs[k] = v
                f.attrs["updated_at"] = now_iso()
                f.attrs["finished_at"] = now_iso() if complete else ""
                f.attrs["n_finished"] = n_done
                f.attrs["complete"] = bool(complete)
                self._write_runs(f)
                if self.trajectories:
                    tg = f.create_group("trajectories")
                    old_tg = old.get("trajectories") if old is not None else None
                    for row in self.rows:
                        sid = row["scene_id"]
                        part = self.parts / "traj" / f"{sid}.h5"
                        if part.exists():
                            sub = tg.create_group(sid)
                            with h5py.File(part, "r") as p:
                                for k in p.keys():
                                    sub.create_dataset(k, data=p[k][()], fletcher32=True)
                        elif old_tg is not None and sid in old_tg:
                            old.copy(old_tg[sid], tg, name=sid)
        finally:
            if old is not None:
                old.close()
        _fsync_path(tmp)
        os.replace(tmp, self.path)
        _fsync_path(self.path.parent, directory=True)
        self._dirty = False
        self._main_complete = bool(complete)
        self._last = time.monotonic()
        self._last_cost = self._last - t0

    def finish(self, complete: bool | None = None) -> None:
        """Final consolidation, then remove the journal (only if that succeeded) and unlock."""
        try:
            if self._jfd is not None:
                if complete is None:
                    n = self.meta["n_scenes"]
                    complete = n > 0 and len(self.rows) >= n
                if self._dirty or complete != self._main_complete or not self.path.exists():
                    self.consolidate(complete=complete)
                os.close(self._jfd)
                self._jfd = None
                shutil.rmtree(self.parts, ignore_errors=True)
        finally:
            self._release()

    def abort(self) -> None:
        """Release without consolidating (the journal keeps everything for a resume)."""
        if self._jfd is not None:
            with contextlib.suppress(OSError):
                os.close(self._jfd)
            self._jfd = None
        self._release()


# ----------------------------------------------------------------------------- summary
#: Scene columns of the runs table that ``sweep info`` summarizes (the Scene fields).
SCENE_PARAMS = SCENE_AXES


def older_revision_rows(rows, ids) -> dict[int, int]:
    """Rows among ``ids`` computed by an earlier engine revision than this one
    (:data:`sweep.scene.ENGINE_REVISION`), counted by revision; a row without the column was
    written by revision 1."""
    older: dict[int, int] = {}
    for row in rows:
        if row.get("scene_id") not in ids:
            continue
        rev = row.get("engine_revision")
        try:
            rev = int(rev) if rev is not None and math.isfinite(float(rev)) else 1
        except (TypeError, ValueError):
            rev = 1
        if rev != ENGINE_REVISION:
            older[rev] = older.get(rev, 0) + 1
    return older


def revision_counts(older: dict[int, int]) -> str:
    """``3 of revision 1 (what it computed otherwise)``, for each count of
    :func:`older_revision_rows`."""
    return ", ".join(f"{count} of revision {rev} ({REVISION_CHANGES.get(rev, 'other numbers')})"
                     for rev, count in sorted(older.items()))


def _g(x) -> str:
    return f"{x:.4g}" if isinstance(x, (float, np.floating)) else str(x)


def summary(path, slowest: int = 5) -> str:
    """A human-readable summary of a results file (what ``sweep info`` prints)."""
    path = Path(path)
    df = load(path)
    attrs = read_attrs(path)
    lines = [f"{path}"]
    name = attrs.get("config_name", "?")
    total = int(attrs.get("n_scenes", 0) or 0)
    lines.append(f"  sweep {name!r}  config hash {attrs.get('config_hash', '?')}  "
                 f"package {attrs.get('package_version', '?')}  commit "
                 f"{str(attrs.get('git_commit', '?'))[:12]}")
    lines.append(f"  started {attrs.get('started_at', '?')}  updated "
                 f"{attrs.get('updated_at', '?')}  finished "
                 f"{attrs.get('finished_at') or '(not finished)'}")
    pending = parts_dir(path).exists()
    grown = _history(attrs.get("config_history", ""))
    if grown:
        lines.append(f"  grown: the grid is the union of this config and {len(grown)} earlier "
                     f"one{'s' if len(grown) > 1 else ''} (config hash "
                     f"{', '.join(e['config_hash'] for e in grown)})")
    lines.append(f"  scenes: {len(df)} finished of {total}"
                 + ("  (journal present: running, or killed; rerun to resume)" if pending
                    else ""))
    if len(df) and "status" in df:
        counts = df["status"].value_counts()
        lines.append("  status: " + ", ".join(f"{k} {v}" for k, v in counts.items()))
    older = older_revision_rows(df.to_dict("records"), set(df["scene_id"])) if len(df) else {}
    if older:
        lines.append(f"  engine: rows of an earlier engine than this one (revision "
                     f"{ENGINE_REVISION}): {revision_counts(older)}")
    varying, fixed = [], []
    # n is unused where every material is a Prony table (its value is bookkeeping)
    tables = (len(df) and "material" in df
              and df["material"].astype(str).str.startswith(f"{TABLE_MATERIAL}:").all())
    for c in list(SCENE_PARAMS) + [c for c in df.columns if c.startswith("num_")]:
        if c not in df or not len(df) or (c == "n" and tables):
            continue
        col = df[c]
        if col.dtype.kind in "fiu":
            col = col.dropna()
            if not len(col):
                continue
            # values that differ only in their last bits (a table's k read from two
            # formats) are one value
            uniq = np.unique([float(f"{v:.12g}") for v in col] if col.dtype.kind == "f"
                             else col)
            if len(uniq) > 1:
                lo, hi = _g(uniq.min()), _g(uniq.max())
                if lo == hi:
                    lo, hi = f"{uniq.min():.12g}", f"{uniq.max():.12g}"
                varying.append(f"{c}: {len(uniq)} values in [{lo}, {hi}]")
            else:
                fixed.append(f"{c}={_g(uniq[0])}")
        else:
            uniq = sorted(set(map(str, col)))
            if len(uniq) > 1:
                varying.append(f"{c}: {', '.join(uniq)}")
            else:
                fixed.append(f"{c}={uniq[0]}")
    if varying:
        lines.append("  varying:")
        lines.extend(f"    {v}" for v in varying)
    if fixed:
        lines.append("  fixed: " + ", ".join(fixed))
    if len(df) and "wall_s" in df:
        wall = df["wall_s"].astype(float)
        lines.append(f"  wall time per scene: median {np.nanmedian(wall):.3g} s, "
                     f"total {np.nansum(wall):.4g} s")
        params = [c for c in SCENE_PARAMS if c in df and len(set(map(str, df[c]))) > 1]
        top = df.assign(_w=wall).sort_values("_w", ascending=False).head(slowest)
        lines.append(f"  slowest {len(top)}:")
        for _, r in top.iterrows():
            desc = " ".join(f"{c}={_g(r[c])}" for c in params)
            lines.append(f"    {r['scene_id']}  {r['_w']:.3g} s  {r.get('status', '')}  {desc}")
    if len(df) and "status" in df:
        failed = df[df["status"] != "ok"]
        if len(failed):
            lines.append(f"  failures ({len(failed)}):")
            params = [c for c in SCENE_PARAMS if c in df and len(set(map(str, df[c]))) > 1]
            for _, r in failed.head(20).iterrows():
                desc = " ".join(f"{c}={_g(r[c])}" for c in params)
                lines.append(f"    {r['scene_id']}  {desc}  reason: {r.get('reason', '')}")
            if len(failed) > 20:
                lines.append(f"    ... and {len(failed) - 20} more")
    return "\n".join(lines)

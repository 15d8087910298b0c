"""An on-disk cache of what a sweep derives again and again from a few numbers: the
unit-spacing influence matrix (:func:`sweep.engine.mesh.unit_influence`), the Prony series of a
material on a time window (:func:`sweep.engine.problem.prony_series`) and the relaxed starts
(:func:`sweep.engine.initial.cached_state`).

Both are pure functions of their key and of the source code that computes them, so each entry's
file name carries a hash of that source (an edit there makes the old entries unused; they are
never read again). Files are written atomically (a temporary file, then ``os.replace``), so a
concurrent reader (another worker of the same sweep) sees a whole file or none; an unreadable
file is ignored and computed again. The cache only saves time: switched off, or on a read-only
disk, everything is computed as before.

Location: ``$SWEEP_CACHE_DIR``, or ``$XDG_CACHE_HOME/viscoadhesion-sweep`` (default
``~/.cache/viscoadhesion-sweep``); ``SWEEP_CACHE_DIR=off`` keeps everything in memory.
"""
from __future__ import annotations

import hashlib
import json
import os
import tempfile
from functools import lru_cache
from pathlib import Path

import numpy as np

#: environment variable naming the cache directory ("off": no disk cache)
CACHE_ENV = "SWEEP_CACHE_DIR"


def cache_dir() -> Path | None:
    """The cache directory, or None when switched off (``SWEEP_CACHE_DIR=off``)."""
    env = os.environ.get(CACHE_ENV, "").strip()
    if env.lower() == "off":
        return None
    if env:
        return Path(env)
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "viscoadhesion-sweep"


@lru_cache(maxsize=None)
def source_tag(*files: str) -> str:
    """12 hex digits of a hash of the given source files (paths of imported modules)."""
    h = hashlib.sha1()
    for f in files:
        h.update(Path(f).read_bytes())
    return h.hexdigest()[:12]


def key_digest(key) -> str:
    """16 hex digits naming a hashable key of numbers and strings (its repr)."""
    return hashlib.sha1(repr(key).encode()).hexdigest()[:16]


#: the suffix of a record file (:func:`save`, :func:`load`), and its first line
RECORD_SUFFIX = ".rec"
RECORD_MAGIC = b"visco-sweep record 1\n"


def record_path(kind: str, tag, key) -> Path | None:
    """Where the record of ``key`` is kept: ``<kind>_<tag>_<key digest>.rec`` in the cache
    directory, ``tag`` (a callable, called only with the cache on) naming the code that
    computes it; None when the cache is off."""
    d = cache_dir()
    return None if d is None else d / f"{kind}_{tag()}_{key_digest(key)}{RECORD_SUFFIX}"


def _record_bytes(arrays: dict) -> bytes:
    """A record: RECORD_MAGIC, one line of JSON listing each array's name, dtype, shape and
    byte count, then the arrays' bytes in that order. Read back by one ``read`` and one JSON
    parse (:func:`_read_record`): an .npz of the same arrays parses a zip directory and one
    header per array (0.5-0.8 ms a file against about 0.1 ms; a warm campaign reads three
    files a scene). Numbers and strings only: no object arrays (no pickle)."""
    parts, layout = [], []
    for name, value in arrays.items():
        a = np.asarray(value)              # tobytes() is C order (ascontiguousarray: ndim >= 1)
        if a.dtype.hasobject:
            raise ValueError(f"disk cache record {name!r}: object arrays are not stored")
        data = a.tobytes()
        layout.append([name, a.dtype.str, list(a.shape), len(data)])
        parts.append(data)
    header = json.dumps(layout, separators=(",", ":")).encode() + b"\n"
    return RECORD_MAGIC + header + b"".join(parts)


def _read_record(path: Path) -> dict:
    """The arrays of a record file (:func:`_record_bytes`), each a writable copy; ValueError
    when it is not one, or is cut short."""
    raw = path.read_bytes()
    if not raw.startswith(RECORD_MAGIC):
        raise ValueError("not a record")
    end = raw.index(b"\n", len(RECORD_MAGIC))
    layout = json.loads(raw[len(RECORD_MAGIC):end])
    out, at = {}, end + 1
    for name, dtype, shape, nbytes in layout:
        if at + nbytes > len(raw):
            raise ValueError("record cut short")
        out[name] = np.frombuffer(raw, dtype=np.dtype(dtype), count=int(np.prod(shape)),
                                  offset=at).reshape(shape).copy()
        at += nbytes
    if at != len(raw):
        raise ValueError("record of another length")
    return out


def save(path: Path, arrays: dict) -> bool:
    """Write ``arrays`` (name -> array) to ``path`` atomically: .npy for one array named "a"
    (the influence matrix, memory-mapped by its readers), a record (:func:`_record_bytes`)
    for a ``.rec`` path, else .npz; False (nothing written) when the disk refuses."""
    tmp = None
    try:
        payload = _record_bytes(arrays) if path.suffix == RECORD_SUFFIX else None
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=path.parent, suffix=".tmp")
        with os.fdopen(fd, "wb") as fh:
            if payload is not None:
                fh.write(payload)
            elif path.suffix == ".npy":
                np.save(fh, arrays["a"])
            else:
                np.savez(fh, **arrays)
        os.replace(tmp, path)
        return True
    except OSError:
        if tmp is not None:
            try:
                os.unlink(tmp)
            except OSError:
                pass
        return False


def load(path: Path, mmap: bool = False):
    """The array (.npy, memory-mapped read-only with ``mmap``) or dict of arrays (.rec or
    .npz) at ``path``; None when missing or unreadable."""
    try:
        if path.suffix == RECORD_SUFFIX:
            return _read_record(path)
        if path.suffix == ".npy":
            return np.load(path, mmap_mode="r" if mmap else None)
        with np.load(path) as z:
            return {k: z[k] for k in z.files}
    except (OSError, ValueError, EOFError, KeyError, TypeError):
        return None

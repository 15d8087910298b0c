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


def save(path: Path, arrays: dict) -> bool:
    """Write ``arrays`` (name -> array) to ``path`` (.npy for one array named "a", else
    .npz) atomically; False (nothing written) when the disk refuses."""
    tmp = None
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=path.parent, suffix=".tmp")
        with os.fdopen(fd, "wb") as fh:
            if path.suffix == ".npy":
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
    """The array (.npy, memory-mapped read-only with ``mmap``) or dict of arrays (.npz) at
    ``path``; None when missing or unreadable."""
    try:
        if path.suffix == ".npy":
            return np.load(path, mmap_mode="r" if mmap else None)
        with np.load(path) as z:
            return {k: z[k] for k in z.files}
    except (OSError, ValueError, EOFError, KeyError):
        return None

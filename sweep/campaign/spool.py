"""Rows a worker process has finished, on disk as each scene ends: what an interrupted sweep
keeps of the dispatch chunks it did not see end.

A local sweep's workers (forked or loky) run dispatch chunks of up to
:data:`sweep.campaign.scheduler.CHUNK_SCENES` scenes and hand their rows back when the whole
chunk ends. A Ctrl-C, SIGTERM or SIGKILL in between would lose the scenes a chunk had already
finished ("0 of 100 scenes are kept" after 25 s of two workers' work). So each worker also
appends every row, as its scene ends, to its own file in ``<out>.parts/spool/``
(:func:`write`); the sweep's process reads them back (:func:`read`) where it did not get
the chunk's rows: after an interrupt or a worker's crash, and on resume after it was killed
itself. Forked workers' rows are read as they are written (:class:`Reader`), so that a sweep
stores and reports each scene as it ends, not each chunk. The results file is written by the sweep's process alone, as always
(:mod:`sweep.campaign.store`); the spool is scratch, removed when the sweep ends.

Format: one file per worker process, ``<pid>.rows``, a sequence of records, each an 8-byte
little-endian length and a pickle of ``(row, trajectory or None)`` (plain dicts, floats,
strings and float arrays, as :func:`sweep.campaign.scheduler.run_scene` returns them). A
worker killed while writing leaves a torn last record, which :func:`read` drops (that scene
runs again). One write and one flush per scene: tens of microseconds.
"""
from __future__ import annotations

import os
import pickle
import struct
from pathlib import Path

__all__ = ["write", "read", "clear", "Reader"]

_LENGTH = struct.Struct("<Q")
#: this process's open spool file: (directory, file object, the pid that opened it)
_OPEN: tuple | None = None


def write(directory, row: dict, trajectory) -> None:
    """Append ``(row, trajectory)`` to this process's spool file in ``directory``."""
    global _OPEN
    directory = Path(directory)
    # a forked worker inherits its parent's handle, and a loky worker outlives a sweep whose
    # end removed its file (the same output resumed in one session): open this process's own
    if (_OPEN is None or _OPEN[0] != directory or _OPEN[2] != os.getpid()
            or os.fstat(_OPEN[1].fileno()).st_nlink == 0):
        directory.mkdir(parents=True, exist_ok=True)
        _OPEN = (directory, open(directory / f"{os.getpid()}.rows", "ab"), os.getpid())
    data = pickle.dumps((row, trajectory), protocol=pickle.HIGHEST_PROTOCOL)
    fh = _OPEN[1]
    fh.write(_LENGTH.pack(len(data)) + data)
    fh.flush()


class Reader:
    """The records of the spool files in ``directory`` as they are written: each call of
    :meth:`new` returns the whole records written since the last (a record still being
    written waits for the next call)."""

    def __init__(self, directory):
        self.directory = Path(directory)
        self._offsets: dict[Path, int] = {}

    def new(self) -> list[tuple[dict, dict | None]]:
        out = []
        if not self.directory.is_dir():
            return out
        for path in sorted(self.directory.glob("*.rows")):
            at = self._offsets.get(path, 0)
            try:
                with open(path, "rb") as fh:
                    fh.seek(at)
                    data = fh.read()
            except FileNotFoundError:       # pragma: no cover - cleared meanwhile
                continue
            pos = 0
            while pos + _LENGTH.size <= len(data):
                (n,) = _LENGTH.unpack_from(data, pos)
                if pos + _LENGTH.size + n > len(data):
                    break                   # still being written, or torn by a kill
                try:
                    out.append(pickle.loads(data[pos + _LENGTH.size: pos + _LENGTH.size + n]))
                except Exception:           # pragma: no cover - a torn pickle
                    break
                pos += _LENGTH.size + n
            self._offsets[path] = at + pos
        return out


def read(directory) -> list[tuple[dict, dict | None]]:
    """Every whole record of the spool files in ``directory`` (none if it is absent), in
    file order; a torn last record is dropped."""
    return Reader(directory).new()


def clear(directory) -> None:
    """Remove the spool files and ``directory`` (what the results file now holds)."""
    directory = Path(directory)
    if not directory.is_dir():
        return
    for path in directory.glob("*.rows"):
        path.unlink(missing_ok=True)
    try:
        directory.rmdir()
    except OSError:
        pass

"""The compiled core (installed as ``sweep.kernels``): Numba ``@njit(cache=True)`` functions on
plain arrays, no I/O and no Python objects.

=============  =================================================================================
module         owns
=============  =================================================================================
interface      the Lennard-Jones traction law, its stiffness, the contact-radius crossing
influence      the overlapping-triangle influence matrix of the axisymmetric half-space
history        the Prony recursion of the hereditary integral (O(N M) per step)
blas           BLAS/LAPACK (scipy's) called from compiled code
clock          a monotonic clock compiled code reads: the time budget's deadline in the kernels
jacobian       Newton's linear algebra: a kept factorization, the crack-tip zone exact
solve          the per-step Newton solve and the unloading loop with its stop rule
protocol       the march of a test protocol: steps held at a load, the settle at the crack tip
=============  =================================================================================

The folder sits at the top of the repository (``kernels/``); the wheel installs it inside the
``sweep`` distribution, never as a top-level package of its own.

The modules do no I/O. This package's import does one thing besides: it drops compiled
machine code older than the kernel sources (:func:`drop_stale_cache`). Numba keys a
function's cache on its own file only, so a kernel compiled with another file's function
inlined (``solve.newton`` with ``jacobian.factorize``) was loaded stale after only that other
file changed: measured on 2026-11-26, an edited ``jacobian.py`` changed no result until the
cache was cleared by hand, as after a ``git pull`` into an editable install.
"""
import hashlib
import os
from pathlib import Path

#: the file, beside the compiled kernels, naming the hash of the sources they came from
CACHE_STAMP = "sweep-kernels.sha256"


def sources_hash(src_dir) -> str:
    """SHA-256 of every ``*.py`` file of ``src_dir`` (names and contents, in name order)."""
    h = hashlib.sha256()
    for p in sorted(Path(src_dir).glob("*.py")):
        h.update(p.name.encode() + b"\0" + p.read_bytes() + b"\0")
    return h.hexdigest()


def cache_folder(src_dir) -> Path:
    """Where Numba keeps the compiled kernels of ``src_dir``: ``$NUMBA_CACHE_DIR/<folder>_<sha1
    of its path>`` (Numba's own naming) when that variable is set, else its ``__pycache__``."""
    src_dir = Path(src_dir).resolve()
    env = os.environ.get("NUMBA_CACHE_DIR", "").strip()
    if not env:
        return src_dir / "__pycache__"
    return Path(env) / f"{src_dir.name}_{hashlib.sha1(str(src_dir).encode()).hexdigest()}"


def drop_stale_cache(src_dir=None, folder=None) -> int:
    """Delete the compiled kernels of ``src_dir`` (default: this package) in ``folder``
    (default :func:`cache_folder`) unless the folder's :data:`CACHE_STAMP` names the sources'
    present hash, then write that hash; they compile again on first use (about 40 s). Returns
    the number of files deleted. A folder that cannot be written is left as it is."""
    src_dir = Path(__file__).resolve().parent if src_dir is None else Path(src_dir)
    folder = cache_folder(src_dir) if folder is None else Path(folder)
    digest = sources_hash(src_dir)
    stamp = folder / CACHE_STAMP
    try:
        if stamp.read_text(encoding="utf-8").strip() == digest:
            return 0
    except OSError:
        pass
    modules = {p.stem for p in src_dir.glob("*.py")}
    dropped = 0
    if folder.is_dir():
        for f in folder.iterdir():
            if f.suffix in (".nbi", ".nbc") and f.name.split(".", 1)[0] in modules:
                try:
                    f.unlink()
                    dropped += 1
                except OSError:
                    pass
    try:
        folder.mkdir(parents=True, exist_ok=True)
        tmp = folder / f"{CACHE_STAMP}.{os.getpid()}.tmp"
        tmp.write_text(digest + "\n", encoding="utf-8")
        os.replace(tmp, stamp)
    except OSError:
        pass
    return dropped


drop_stale_cache()

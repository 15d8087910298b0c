"""Compiled kernels older than the kernel sources are dropped (kernels/__init__.py).

Numba keys a function's cached machine code on its own file only: a kernel that inlined a
function of another kernel file was loaded stale after only that file changed. The package's
import keeps, beside the cache, the hash of the sources it was compiled from, and drops the
cache where the hash differs. Checked here on a copy of the sources and a fake cache folder.
"""
import shutil
from pathlib import Path

from sweep import kernels
from sweep.kernels import CACHE_STAMP, cache_folder, drop_stale_cache, sources_hash

SOURCES = Path(kernels.__file__).resolve().parent


def _fake_cache(folder: Path) -> list[Path]:
    folder.mkdir(parents=True, exist_ok=True)
    files = [folder / name for name in ("solve.newton-373.py311.nbi",
                                        "solve.newton-373.py311.1.nbc",
                                        "jacobian.factorize-150.py311.nbi")]
    for f in files:
        f.write_bytes(b"machine code")
    (folder / "other.thing-1.py311.nbi").write_bytes(b"not ours")   # another module's
    return files


def test_a_changed_source_drops_every_compiled_kernel_and_a_known_one_keeps_them(tmp_path):
    src = tmp_path / "kernels"
    shutil.copytree(SOURCES, src, ignore=shutil.ignore_patterns("__pycache__"))
    folder = tmp_path / "cache"
    files = _fake_cache(folder)
    # no stamp yet: nothing says what the cache was compiled from
    assert drop_stale_cache(src, folder) == len(files)
    assert not any(f.exists() for f in files)
    assert (folder / "other.thing-1.py311.nbi").exists()
    assert (folder / CACHE_STAMP).read_text().strip() == sources_hash(src)
    # the same sources: kept
    files = _fake_cache(folder)
    assert drop_stale_cache(src, folder) == 0 and all(f.exists() for f in files)
    # one callee's file edited (the caller's untouched): every kernel of the package dropped
    jac = src / "jacobian.py"
    jac.write_text(jac.read_text() + "\n# edited\n")
    assert drop_stale_cache(src, folder) == len(files)
    assert not any(f.exists() for f in files)


def test_the_folder_is_numbas_own(tmp_path, monkeypatch):
    import hashlib

    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    assert cache_folder(SOURCES) == SOURCES / "__pycache__"
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    from numba.core.caching import _CacheLocator

    sub = _CacheLocator.get_suitable_cache_subpath(str(SOURCES / "solve.py"))
    assert cache_folder(SOURCES) == tmp_path / sub
    assert sub.endswith(hashlib.sha1(str(SOURCES).encode()).hexdigest())


def test_the_installed_cache_names_the_present_sources():
    stamp = cache_folder(SOURCES) / CACHE_STAMP
    assert stamp.read_text().strip() == sources_hash(SOURCES)

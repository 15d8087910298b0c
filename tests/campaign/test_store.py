"""The crash-safe HDF5 store: round trip, journal, consolidation, refusal to damage files."""
from __future__ import annotations

import json
import math
import os

import h5py
import numpy as np
import pytest

import sweep
from sweep.errors import InputError
from sweep.campaign.store import (JOURNAL, ResultStore, StoreBusyError, load, load_trajectory,
                         parts_dir, read_attrs, summary)

TEMPLATE = {"scene_id": "", "n": 0.0, "a0": None, "material": "mpl", "num_nodes": 0,
            "num_exact": False, "status": "", "reason": "", "pull_off": math.nan, "steps": 0}


def row(i, **over):
    r = {"scene_id": f"id{i:04d}", "n": 0.4 + 0.1 * i, "a0": None if i % 2 else 2.0 + i,
         "material": "mpl", "num_nodes": 60, "num_exact": bool(i % 3 == 0),
         "status": "ok" if i % 4 else "failed", "reason": "" if i % 4 else "Newton failed: ü",
         "pull_off": 1.0 + i if i % 4 else math.nan, "steps": 10 * i}
    r.update(over)
    return r


def traj(i, n=7):
    t = np.linspace(0.0, 1.0, n)
    return {"t": t, "delta": -t * i, "P": t ** 2, "a": 2 - t, "a_inner": 1.5 - t}


def make(path, n_scenes=6, trajectories=False, config_hash="h1", **kw):
    return ResultStore(path, config_hash=config_hash, config_name="t", config_text="name: t\n",
                       n_scenes=n_scenes, trajectories=trajectories, template_row=TEMPLATE, **kw)


def written(path, scenes=3, trajectories=False, rows=None):
    """A finished results file of ``scenes`` rows (and their trajectories), or of ``rows``."""
    grid = {} if rows is None else {"n_scenes": len(rows)}
    rows = [row(i) for i in range(scenes)] if rows is None else rows
    st = make(path, trajectories=trajectories, **grid)
    st.prepare()
    st.begin()
    for i, r in enumerate(rows):
        st.append(r, traj(i) if trajectories else None)
    st.finish()
    return path


def test_round_trip_plain_types(tmp_path):
    path = tmp_path / "r.h5"
    st = make(path)
    st.prepare()
    assert st.begin() == set()
    for i in range(6):
        st.append(row(i))
    st.finish()
    df = load(path)
    assert list(df.scene_id) == [f"id{i:04d}" for i in range(6)]
    assert df["n"].dtype == np.float64 and df["steps"].dtype == np.int64
    assert df["num_exact"].dtype == bool and list(df["num_exact"]) == [i % 3 == 0
                                                                        for i in range(6)]
    assert np.isnan(df["a0"][1]) and df["a0"][2] == 4.0        # None -> NaN
    assert np.isnan(df["pull_off"][0]) and df["pull_off"][5] == 6.0
    assert df["reason"][0] == "Newton failed: ü" and df["reason"][1] == ""
    assert not parts_dir(path).exists()                          # single self-contained file
    attrs = read_attrs(path)
    assert attrs["complete"] and attrs["n_finished"] == 6 and attrs["finished_at"]
    assert attrs["config_text"] == "name: t\n" and attrs["config_hash"] == "h1"
    for key in ("package_version", "git_commit", "numba_version", "numpy_version",
                "started_at", "updated_at"):
        assert attrs[key], key


def test_sweep_reexports():
    assert sweep.load is load and sweep.load_trajectory is load_trajectory


def test_file_holds_plain_arrays_and_text_only(tmp_path):
    path = written(tmp_path / "r.h5", trajectories=True)
    seen = []

    def visit(name, obj):
        if isinstance(obj, h5py.Dataset):
            dt = obj.dtype
            ok = dt.kind in "fiu" or h5py.check_string_dtype(dt) is not None
            assert ok, (name, dt)                     # no opaque/compound/object/pickle bytes
            seen.append(name)
    with h5py.File(path, "r") as f:
        f.visititems(visit)
        for k, v in f.attrs.items():
            assert isinstance(v, (str, bytes, np.integer, np.floating, np.bool_, int, float,
                                  bool)), (k, type(v))
    assert "runs/scene_id" in seen and "trajectories/id0001/P" in seen


def test_journal_is_read_before_consolidation(tmp_path):
    path = tmp_path / "r.h5"
    st = make(path, interval=1e9)
    st.prepare()
    st.begin()                                # writes an empty consolidated file at once
    assert len(load(path)) == 0 and "pull_off" in load(path).columns
    for i in range(4):
        st.append(row(i))
        assert st.maybe_consolidate() is False
    with h5py.File(path, "r") as f:
        assert len(f["runs/scene_id"]) == 0   # main file not yet rewritten ...
    df = load(path)                            # ... but load() sees every finished scene
    assert list(df.scene_id) == [f"id{i:04d}" for i in range(4)]
    assert np.isnan(df["a0"][1])
    st.abort()                                 # like a kill: no final consolidation
    st2 = make(path)
    st2.prepare()
    assert st2.begin() == {f"id{i:04d}" for i in range(4)}
    st2.finish()
    assert len(load(path)) == 4 and not parts_dir(path).exists()


def test_a_journal_row_replaces_the_main_files_row_of_its_scene(tmp_path):
    # an internal error's row is consolidated; the resume runs the scene again and its new
    # row reaches the journal, then the process dies before the next consolidation: load,
    # a resume and sweep info see the new row, not the stale error
    path = tmp_path / "r.h5"
    st = make(path, n_scenes=2)
    st.prepare()
    st.begin()
    st.append(row(1, status="error", reason="internal error: TypeError", pull_off=math.nan))
    st.append(row(2))
    st.finish()
    st = make(path, n_scenes=2, interval=1e9)
    st.prepare()
    st.begin()
    st.append(row(1, pull_off=7.5))
    st.abort()                                 # like a kill: no consolidation
    df = load(path)
    assert list(df.status) == ["ok", "ok"] and set(df.pull_off) == {3.0, 7.5}
    assert "error" not in summary(path)
    st = make(path, n_scenes=2)
    st.prepare()
    assert st.begin() == {"id0001", "id0002"} and st.status("id0001") == "ok"
    st.finish()
    df = load(path)
    assert len(df) == 2 and df.set_index("scene_id").pull_off["id0001"] == 7.5


def test_torn_journal_line_ignored_then_repaired(tmp_path):
    path = tmp_path / "r.h5"
    st = make(path, interval=1e9)
    st.prepare()
    st.begin()
    st.append(row(1))
    st.abort()
    jp = parts_dir(path) / JOURNAL
    with open(jp, "ab") as fh:                 # a write cut short by SIGKILL
        fh.write(json.dumps(row(2)).encode()[:25])
    assert list(load(path).scene_id) == ["id0001"]
    st = make(path)
    st.prepare()
    assert st.begin() == {"id0001"}
    st.append(row(3))
    text = jp.read_bytes()
    assert text.endswith(b"\n") and text.count(b"\n") == 2   # torn tail truncated
    st.finish()
    assert list(load(path).scene_id) == ["id0001", "id0003"]


def test_consolidation_replaces_file_atomically(tmp_path):
    path = tmp_path / "r.h5"
    st = make(path, interval=0.0)
    st.prepare()
    st.begin()
    reader = h5py.File(path, "r")              # a reader holding the old version open
    ino = os.stat(path).st_ino
    st.append(row(1))
    st.consolidate()
    assert os.stat(path).st_ino != ino         # replaced, never written in place
    assert len(reader["runs/scene_id"]) == 0   # the old reader still sees a valid file
    reader.close()
    assert not (tmp_path / "r.h5.tmp").exists()
    st.finish()


def test_trajectories(tmp_path):
    path = tmp_path / "r.h5"
    st = make(path, trajectories=True, interval=1e9)
    st.prepare()
    st.begin()
    st.append(row(1), traj(1))
    got = load_trajectory(path, "id0001")      # from the journal's part file
    np.testing.assert_array_equal(got["delta"], traj(1)["delta"])
    st.consolidate()
    st.append(row(2), traj(2, n=9))
    st.finish()
    for i, n in ((1, 7), (2, 9)):              # both now from the consolidated file
        got = load_trajectory(path, f"id{i:04d}")
        assert set(got) == {"t", "delta", "P", "a", "a_inner"} and len(got["t"]) == n
    with pytest.raises(KeyError, match="no trajectory"):
        load_trajectory(path, "nope")
    # resume into the consolidated file keeps old trajectories when rewriting it
    st = make(path, n_scenes=7, trajectories=True)
    st.prepare()
    st.begin()
    st.append(row(3), traj(3))
    st.finish()
    assert len(load_trajectory(path, "id0001")["t"]) == 7


def test_no_trajectories_message(tmp_path):
    path = tmp_path / "r.h5"
    st = make(path)
    st.prepare()
    st.begin()
    st.append(row(1), traj(1))                 # ignored: store.trajectories is false
    st.finish()
    with pytest.raises(KeyError, match="trajectories: true"):
        load_trajectory(path, "id0001")


def test_different_config_refused_and_file_untouched(tmp_path):
    path = tmp_path / "r.h5"
    st = make(path)
    st.prepare()
    st.begin()
    st.append(row(1))
    st.finish()
    before = path.read_bytes()
    other = make(path, config_hash="h2")
    # the same config text whose scenes hash differently: a preset's meaning changed
    with pytest.raises(InputError, match="same config when its numerics meant other values"):
        other.prepare(resume=True)
    other.meta["config_text"] = "name: t2\n"
    with pytest.raises(InputError, match="different config.*--fresh.*--out"):
        other.prepare(resume=True)
    assert path.read_bytes() == before
    assert not (tmp_path / "r.h5.lock").exists()  # lock released on refusal


def test_fresh_moves_old_results_aside(tmp_path):
    path = tmp_path / "r.h5"
    for round_ in range(2):
        st = make(path)
        st.prepare()
        st.begin()
        st.append(row(round_))
        if round_ == 0:
            st.finish()
        else:
            st.abort()                          # second file left with a journal
    new = make(path, config_hash="h2")
    new.prepare(resume=False)
    assert new.begin(fresh=True) == set()
    new.append(row(9))
    new.finish()
    assert list(load(path).scene_id) == ["id0009"]
    assert new.backup == tmp_path / "r.h5.bak"
    assert sorted(load(new.backup).scene_id) == ["id0000", "id0001"]   # journal moved too
    # a second --fresh never overwrites the first backup
    again = make(path, config_hash="h3")
    again.prepare(resume=False)
    again.begin(fresh=True)
    again.finish()
    assert again.backup == tmp_path / "r.h5.bak1"
    assert list(load(again.backup).scene_id) == ["id0009"]


def test_foreign_file_refused(tmp_path):
    path = tmp_path / "r.h5"
    path.write_bytes(b"precious data, not HDF5")
    st = make(path)
    with pytest.raises(InputError, match="not a readable HDF5.*refusing to overwrite"):
        st.prepare(resume=True)
    with h5py.File(tmp_path / "o.h5", "w") as f:
        f["x"] = [1, 2]
    with pytest.raises(InputError, match="not a visco-sweep results file"):
        make(tmp_path / "o.h5").prepare(resume=True)
    assert path.read_bytes() == b"precious data, not HDF5"
    with pytest.raises(InputError):
        load(path)


def test_single_writer_lock(tmp_path):
    path = tmp_path / "r.h5"
    a = make(path)
    a.prepare()
    a.begin()
    with pytest.raises(StoreBusyError, match="another sweep is writing"):
        make(path).prepare()
    a.finish()
    b = make(path)
    b.prepare()                                # free again after finish
    b.abort()


def test_load_missing(tmp_path):
    with pytest.raises(FileNotFoundError):
        load(tmp_path / "none.h5")


def test_summary_text(tmp_path):
    path = tmp_path / "r.h5"
    st = make(path, n_scenes=8)
    st.prepare()
    st.begin()
    for i in range(6):
        st.append({**row(i), "rate": 10.0 ** i, "wall_s": 0.1 * i})
    st.finish()
    text = summary(path, slowest=3)
    assert "6 finished of 8" in text and "status: ok 4, failed 2" in text
    assert "rate: 6 values in [1, 1e+05]" in text
    assert "slowest 3:" in text and text.index("id0005") < text.index("id0004")
    assert "failures (2):" in text and "Newton failed" in text


def test_summary_names_values_that_differ_in_the_last_bits_once(tmp_path):
    """A table's k read from two formats differs in its last bits: one value, not "2 values
    in [0.05, 0.05]"; two values that print alike at 4 digits print with more."""
    ks = (0.05, 0.05 * (1 + 2 ** -50), 0.3, 0.30001)
    mixed = written(tmp_path / "r.h5", rows=[{**row(i), "k": k, "rate": 1.0 if i < 2 else 10.0}
                                             for i, k in enumerate(ks)])
    assert "k: 3 values in [0.05, 0.3]" in summary(mixed)
    alike = written(tmp_path / "s.h5", rows=[{**row(i), "k": k} for i, k in enumerate(ks[:2])])
    assert "k=0.05" in summary(alike)
    close = written(tmp_path / "t.h5", rows=[{**row(i), "k": k}
                                             for i, k in enumerate((0.123451, 0.123452))])
    assert "k: 2 values in [0.123451, 0.123452]" in summary(close)


def test_kill_during_consolidation_leaves_old_file(tmp_path):
    """A consolidation cut short leaves only a stray .tmp: readers ignore it, writers drop it."""
    path = tmp_path / "r.h5"
    st = make(path, interval=1e9)
    st.prepare()
    st.begin()
    st.append(row(1))
    st.abort()
    tmp = tmp_path / "r.h5.tmp"
    tmp.write_bytes(b"\x89HDF\r\n\x1a\n half a file")        # torn consolidation
    assert list(load(path).scene_id) == ["id0001"]
    st = make(path)
    st.prepare()
    assert st.begin() == {"id0001"}
    assert not tmp.exists()
    st.finish()
    assert list(load(path).scene_id) == ["id0001"]


def test_load_trajectory_names_a_scene_id_that_is_not_a_string(tmp_path):
    """``load_trajectory(path, 3)`` had raised h5py's "A name should be string or bytes"."""
    with pytest.raises(TypeError, match="scene_id must be a string"):
        load_trajectory(tmp_path / "x.h5", 3)


def test_a_results_file_reached_through_a_link_is_the_file_itself(tmp_path):
    """Writing through a symbolic link keeps the link and writes the file it names (its
    journal, its lock): the link is not replaced by a private copy, and a second writer
    through the other name is refused."""
    real = tmp_path / "shared" / "r.h5"
    real.parent.mkdir()
    link = tmp_path / "r.h5"
    st = make(real, n_scenes=4)
    st.prepare()
    st.begin()
    st.append(row(1))
    st.finish()
    link.symlink_to(real)
    st = make(link, n_scenes=4, interval=1e9)
    st.prepare()
    other = make(real, n_scenes=4)
    with pytest.raises(StoreBusyError):
        other.prepare()
    st.begin()
    st.append(row(2))
    assert list(load(link).scene_id) == list(load(real).scene_id) == ["id0001", "id0002"]
    st.finish()
    assert link.is_symlink() and len(load(real)) == 2
    assert not parts_dir(link).exists() and not (tmp_path / "r.h5.parts").exists()


def test_an_unreadable_journal_meta_is_named_and_the_main_file_still_resumes(tmp_path):
    path = tmp_path / "r.h5"
    st = make(path, interval=1e9)
    st.prepare()
    st.begin()
    st.append(row(1))
    st.abort()                                 # killed: the journal and its meta.json stay
    meta = parts_dir(path) / "meta.json"
    meta.write_text('{"broken')
    st = make(path)                            # the main file names the sweep: resume
    st.prepare()
    assert st.begin() == {"id0001"}
    assert json.loads(meta.read_text())["config_hash"] == "h1"     # written again
    st.finish()
    assert list(load(path).scene_id) == ["id0001"]
    # without a main file nothing tells which config wrote the journal: refused, untouched
    st = make(path, interval=1e9)
    st.prepare()
    st.begin()
    st.append(row(2))
    st.abort()
    os.remove(path)
    meta.write_text('{"broken')
    with pytest.raises(InputError, match=r"meta.json does not read .*use --fresh"):
        make(path).prepare()
    assert meta.read_text() == '{"broken' and (parts_dir(path) / JOURNAL).exists()


def _flip_a_byte(path, dataset):
    with h5py.File(path, "r") as f:
        info = f[dataset].id.get_chunk_info(0)
    data = bytearray(path.read_bytes())
    data[info.byte_offset + 3] ^= 0xFF
    path.write_bytes(bytes(data))


def test_damaged_bytes_in_a_column_or_a_trajectory_fail_their_checksum(tmp_path):
    """A byte changed on disk inside a numeric column or a trajectory array is found by its
    Fletcher-32 checksum: load, load_trajectory and a resume say so in one line (an
    InputError naming the file and the dataset) and leave the file as it is."""
    path = written(tmp_path / "r.h5", trajectories=True)
    _flip_a_byte(path, "trajectories/id0001/P")
    assert list(load(path).scene_id) == ["id0000", "id0001", "id0002"]
    with pytest.raises(InputError, match=r"r\.h5: the trajectory id0001/P does not read .*"
                                         r"damaged"):
        load_trajectory(path, "id0001")
    _flip_a_byte(path, "runs/pull_off")
    before = path.read_bytes()
    with pytest.raises(InputError, match=r"r\.h5: the column pull_off does not read"):
        load(path)
    st = make(path, trajectories=True)
    st.prepare()
    with pytest.raises(InputError, match="the column pull_off does not read"):
        st.begin()
    st.abort()
    assert path.read_bytes() == before

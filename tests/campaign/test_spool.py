"""sweep.campaign.spool: a worker's rows on disk as its scenes end (what an interrupt keeps)."""
from __future__ import annotations

import os

import numpy as np

from sweep.campaign import spool


def _row(i):
    return {"scene_id": f"{i:016x}", "status": "ok", "pull_off": 1.5 + i}, (
        {"P": np.linspace(0.0, -1.5, 5) * i} if i % 2 else None)


def test_rows_read_back_in_order_and_a_torn_record_is_dropped(tmp_path):
    d = tmp_path / "spool"
    for i in range(3):
        spool.write(d, *_row(i))
    got = spool.read(d)
    assert [r["scene_id"] for r, _ in got] == [_row(i)[0]["scene_id"] for i in range(3)]
    np.testing.assert_array_equal(got[1][1]["P"], _row(1)[1]["P"])
    assert got[0][1] is None
    # a worker killed while writing: the last record cut short
    path = d / f"{os.getpid()}.rows"
    data = path.read_bytes()
    path.write_bytes(data[:-7])
    assert [r["scene_id"] for r, _ in spool.read(d)] == [_row(i)[0]["scene_id"] for i in range(2)]


def test_a_reader_returns_what_was_written_since_its_last_call(tmp_path):
    d = tmp_path / "spool"
    reader = spool.Reader(d)
    assert reader.new() == []                            # no spool yet
    spool.write(d, *_row(0))
    spool.write(d, *_row(1))
    assert [r["pull_off"] for r, _ in reader.new()] == [1.5, 2.5]
    assert reader.new() == []
    spool.write(d, *_row(2))
    assert [r["pull_off"] for r, _ in reader.new()] == [3.5]


def test_clear_removes_the_spool_and_a_later_write_starts_a_new_file(tmp_path):
    """The same output resumed in one session: a worker that outlived the first sweep
    (loky's reusable workers) writes to a new file, not to the one the first removed."""
    d = tmp_path / "spool"
    spool.write(d, *_row(0))
    spool.clear(d)
    assert not d.exists()
    spool.write(d, *_row(1))
    assert [r["scene_id"] for r, _ in spool.read(d)] == [_row(1)[0]["scene_id"]]
    spool.clear(d)
    spool.clear(d)                                         # nothing left: a no-op


def test_a_spooled_row_replaces_a_stored_internal_error_of_its_scene(tmp_path):
    """A resume runs an `error` scene again; its worker spools the new row and the sweep is
    killed before storing it: the next resume stores the spooled row in place of the error
    (and keeps a stored ok row against a spooled one)."""
    import math

    from sweep.campaign.scheduler import _unspool
    from sweep.campaign.store import ResultStore, load

    path = tmp_path / "r.h5"
    template = {"scene_id": "", "status": "", "pull_off": math.nan}
    store = ResultStore(path, config_hash="h", config_name="t", config_text="name: t\n",
                        n_scenes=2, template_row=template)
    store.prepare()
    store.begin()
    store.append({"scene_id": "a", "status": "error", "pull_off": math.nan})
    store.append({"scene_id": "b", "status": "ok", "pull_off": 2.0})
    d = tmp_path / "spool"
    spool.write(d, {"scene_id": "a", "status": "ok", "pull_off": 1.0}, None)
    spool.write(d, {"scene_id": "b", "status": "ok", "pull_off": 9.0}, None)
    assert _unspool(store, d, {"a", "b"}, tmp_path / "errors.log") == {"a"}
    store.finish()
    assert load(path).set_index("scene_id").pull_off.to_dict() == {"a": 1.0, "b": 2.0}

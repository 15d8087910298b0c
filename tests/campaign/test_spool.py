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

"""sweep.scene.Result prints as a one-line summary, never its trajectory arrays."""
from __future__ import annotations

import numpy as np

from sweep.scene import Numerics, Result, Scene

SCENE = Scene(n=0.8, k=0.1, mu=3.24, rate=10.0, a0=3.0, model="crack")


def _result(points: int, **kw) -> Result:
    rng = np.random.default_rng(0)
    traj = {name: rng.random(points) for name in ("t", "delta", "P", "a", "a_inner")}
    return Result(scene=SCENE, numerics=Numerics.preset("fast"), trajectory=traj, **kw)


def test_a_result_prints_its_summary_not_its_arrays():
    res = _result(5000, status="ok", pull_off=4.08732, crack_speed=0.705092, steps=4999,
                  model_used="crack")
    text = repr(res)
    assert str(res) == text and "\n" not in text
    assert len(text) < 200                       # the 5 arrays of 5000 floats: ~100 kB
    for part in ("Result(ok:", "pull_off=4.08732", "crack_speed=0.705092", "model=crack",
                 "steps=4999", "trajectory=5000 points", "n=0.8", "rate=10", "a0=3"):
        assert part in text, part
    assert "array" not in text and "0." + "0" * 5 not in text


def test_a_failed_result_prints_its_reason_shortened():
    res = _result(0, status="failed", reason="Newton failure " + "x" * 300)
    text = repr(res)
    assert text.startswith("Result(failed (Newton failure x") and "...)" in text
    assert "pull_off=nan" in text and "trajectory=0 points" in text
    assert "model=crack" in text                 # the model asked for, none recorded
    assert len(text) < 260


def test_a_result_in_a_list_prints_short():
    res = _result(2000, status="ok", pull_off=2.0)
    assert len(repr([res, res])) < 2 * 200


def test_results_compare_by_identity_and_presets_are_read_only():
    """A Result's copy had compared unequal after pickling (NaN fields, ``wall_s``) and
    raised after deepcopy (the trajectory's arrays): results compare by identity, their
    numbers through ``scalars``. ``sweep.PRESETS["fast"]["step"] = 5`` had changed
    ``Numerics.preset("fast")`` for the session."""
    import copy
    import pickle

    import pytest

    from sweep.scene import PRESETS

    res = Result(scene=Scene(n=0.5, k=0.1, mu=3.0, a0=2.0, rate=1.0),
                 numerics=Numerics.preset("fast"), status="ok", pull_off=2.0,
                 trajectory={"t": np.arange(3.0), "P": np.ones(3)})
    twin = copy.deepcopy(res)
    assert res == res and res != twin                      # no ValueError from the arrays
    back = pickle.loads(pickle.dumps(res))
    np.testing.assert_equal(back.scalars(), res.scalars())  # NaN-aware, field by field
    with pytest.raises(TypeError):
        PRESETS["fast"]["step"] = 5.0
    with pytest.raises(TypeError):
        PRESETS["mine"] = {}
    assert Numerics.preset("fast").step == 0.25
    assert Numerics.preset("fast", step=0.5).step == 0.5


def test_a_material_string_is_a_name_and_a_path_object_a_file(tmp_path):
    """``Scene(material="df_prony.csv")`` had been refused with "must be one of mpl, sls"
    only, though the docstring promised any input read_prony reads: a plain string names a
    material, and the refusal says how a file is given; a pathlib.Path is read as a file."""
    from pathlib import Path

    import pytest

    from sweep.errors import InputError

    table = Path(__file__).parent / "data" / "prony" / "pdms_prony.csv"
    kw = dict(n=0.5, k=0.1, mu=3.0, a0=2.0, rate=1.0)
    with pytest.raises(InputError, match=r"material must be mpl, sls or a Prony table: a file "
                                         r"as \{'prony': path\} or a pathlib.Path"):
        Scene(material=str(table), **kw)
    by_path = Scene(material=table, **kw)
    by_dict = Scene(material={"prony": str(table)}, **kw)
    assert by_path == by_dict and by_path.material.label == by_dict.material.label

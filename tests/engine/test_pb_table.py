"""The Persson-Brener law's table and its fast evaluation against the values the crack-front
model gave before they were made faster (issue 33 item 5).

``tests/data/crack_front_pull_offs.yaml`` holds pull-offs and law values computed by the code
of commit 65153f0 (the table built by the full-window Newton of ``sweep.theory`` and evaluated
through scipy's ``PPoly``), written by::

    PYTHONPATH=$PWD python tests/engine/test_pb_table.py --write   # at commit 65153f0

The scenes span the calibration demo's kind (k = 1/3000, mu ~ 165, a0 ~ 1.7, n in [0.1, 1.5],
rates over eleven decades) and beyond it (k 0.1 and 0.01, other mu and a0, the SLS, a process
zone). Tolerances: pull-offs within 1e-6 relative (the integrator's rtol is 1e-8; a table
value moved by 1e-12 moves a pull-off far less), law speeds within 1e-10 relative.
"""
from __future__ import annotations

import math
import sys

import numpy as np
import pytest

from sweep import Numerics, Scene
from sweep.engine.crack_front import pb_law_for_scene, simulate_crack

K_DEMO = 1.0e6 / 3.0e9
MU_DEMO, A0_DEMO = 164.6253482568674, 1.7045680136832084

#: (n, k, mu, a0, rate, material, pz) of the fixture's scenes
SCENES = (
    [(n, K_DEMO, MU_DEMO, A0_DEMO, r, "mpl", None)
     for n in (0.1, 0.22, 0.6, 1.5) for r in (3.2e-3, 0.65, 6.5e3, 3.2e6, 3.2e8)]
    + [(0.8, 0.1, 3.24, 3.61, 316.227766, "mpl", None),
       (0.3, 0.01, 50.0, 5.0, 1.0e4, "mpl", None),
       (2.5, 0.01, 20.0, 2.0, 1.0e-1, "mpl", None),
       (0.5, 0.05, 100.0, 1.2, 1.0e2, "sls", None),
       (0.4, 0.02, 80.0, 3.0, 1.0e3, "mpl", (1.0e2, 0.3))]
)
#: (n, k, material, g) at which the law's speed V(g) and dV/dg are recorded (the law of mu = 1)
SPEEDS = [(n, k, m, g) for n, k, m in ((0.22, K_DEMO, "mpl"), (1.5, K_DEMO, "mpl"),
                                        (0.8, 0.1, "mpl"), (0.5, 0.05, "sls"))
          for g in (1.0 + 1e-9, 1.001, 1.3, 2.0, 5.0, 0.3 / k, 0.9 / k, 0.999 / k)]


def _scene(n, k, mu, a0, rate, material, pz):
    extra = {} if pz is None else {"pz_law": "gent-schultz", "pz_v0": pz[0], "pz_xi": pz[1]}
    return Scene(n=n, k=k, mu=mu, a0=a0, rate=rate, material=material, model="crack", **extra)


def _pull_off(spec):
    res = simulate_crack(_scene(*spec), Numerics.preset("fast"))
    assert res.status == "ok", res.reason
    return res.pull_off


def _speed(n, k, material, g):
    v, dv = pb_law_for_scene(n, k, 1.0, material).speed(g)
    return float(v), float(dv)


def _fixture():
    from tests.reference import load
    return load("crack_front_pull_offs")


@pytest.mark.parametrize("i", range(len(SCENES)))
def test_pull_off_as_before(i):
    ref = _fixture()["pull_offs"][i]
    assert list(ref["scene"]) == [x if not isinstance(x, tuple) else list(x) for x in SCENES[i]]
    po = _pull_off(SCENES[i])
    assert abs(po - ref["pull_off"]) <= 1e-6 * ref["pull_off"], (po, ref["pull_off"])


def test_law_speed_as_before():
    ref = _fixture()["speeds"]
    assert len(ref) == len(SPEEDS)
    for spec, row in zip(SPEEDS, ref):
        v, dv = _speed(*spec)
        assert v == pytest.approx(row["v"], rel=1e-10, abs=0.0), spec
        assert dv == pytest.approx(row["dv"], rel=1e-10, abs=0.0), spec


def test_scalar_speed_is_the_array_speed():
    """The scalar path (the integrator's) and the array path evaluate the same spline."""
    law = pb_law_for_scene(0.22, K_DEMO, MU_DEMO)
    g = np.concatenate([[0.5, 1.0, 1.0 + 1e-12], np.geomspace(1.0 + 1e-9, 1.0 / K_DEMO, 400),
                        [1.0 / K_DEMO + 1.0]])
    v_arr, dv_arr = law.speed(g)
    for gi, va, dva in zip(g, v_arr, dv_arr):
        v, dv = law.speed(float(gi))
        assert v == pytest.approx(va, rel=1e-13, abs=0.0)
        assert dv == pytest.approx(dva, rel=1e-13, abs=0.0)


def _write():
    import yaml
    from pathlib import Path
    out = {"source": "tests/engine/test_pb_table.py --write at commit 65153f0 (module docstring)",
           "pull_offs": [{"scene": [list(x) if isinstance(x, tuple) else x for x in s],
                          "pull_off": _pull_off(s)}
                         for s in SCENES],
           "speeds": [dict(zip(("v", "dv"), _speed(*s))) for s in SPEEDS]}
    path = Path(__file__).resolve().parents[1] / "data" / "crack_front_pull_offs.yaml"
    header = ("# Crack-front pull-offs (pi dg R) of the scenes of tests/engine/test_pb_table.py and\n"
              "# its law's V(g), dV/dg (l0 of mu = 1), computed before the table was made faster:\n"
              "#   PYTHONPATH=$PWD python tests/engine/test_pb_table.py --write   # at 65153f0\n")
    path.write_text(header + yaml.safe_dump(out, sort_keys=False))
    print(f"wrote {path}")


if __name__ == "__main__":
    if sys.argv[1:] == ["--write"]:
        _write()

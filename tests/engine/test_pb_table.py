"""The Persson-Brener law's table and its fast evaluation against the values the crack-front
model gave before they were made faster (issue 33 item 5).

``tests/data/crack_front_pull_offs.yaml`` holds pull-offs and law values computed by the code
of commit 65153f0 (the table built by the full-window Newton of ``sweep.theory`` and evaluated
through scipy's ``PPoly``), written by::

    PYTHONPATH=$PWD python tests/engine/test_pb_table.py --write   # at commit 65153f0

The scenes span the calibration demo's kind (k = 1/3000, mu ~ 165, a0 ~ 1.7, n in [0.1, 1.5],
rates over eleven decades) and beyond it (k 0.1 and 0.01, other mu and a0, the SLS, a process
zone). Tolerances: pull-offs within 1e-6 relative (the integrator's rtol is 1e-8; a table
value moved by 1e-12 moves a pull-off far less), law speeds within 1e-10 relative, or within
the rounding of the table's Gamma amplified by the law's condition number where that is larger
(only at g = 1 + 1e-9: :data:`SPEED_RTOL`, :func:`_speed_rtol`).
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

#: Tolerance of a law speed V(g) and slope dV/dg against the fixture, relative:
#: max(SPEED_RTOL, c * kappa * eps) with kappa = g V'(g) / V(g) (the fixture's own v, dv: the
#: law's condition number) and eps = 2.2e-16, c = SPEED_C_V for V and SPEED_C_DV for dV/dg.
#: Why: V(g) = exp(spline(ln(g - 1))) through the nodes (ln(Gamma_i - 1), ln vhat_i); Gamma_i ~ 1
#: is a double computed through exp, log, hypot, gammainc and sums, whose last bits differ
#: between processors and libraries. An ulp of Gamma_i moves ln(Gamma_i - 1) by
#: eps Gamma_i / (Gamma_i - 1), and so V by about kappa * eps, as an ulp of g itself does (at
#: g = 1 + 1e-9, kappa = 1e9: 2.2e-7), and dV/dg, the spline's slope, by ~10-40 times that.
#: Measured (every exp, log, hypot, gammainc, gammaincc and sum of the table's Gamma moved by a
#: random -1/0/+1 ulp, 4 x 12 draws, the 4 laws): V moved by at most 2.3 kappa eps at
#: g = 1 + 1e-9 (5.0e-7) and at most 13 kappa eps elsewhere (2.1e-14 at g = 900, < 7e-13 at any
#: kappa ~ 1e3 row); dV/dg by at most 26 kappa eps at g = 1 + 1e-9 (5.8e-6) and 109 kappa eps
#: elsewhere (< 6e-12 at any row). The fixture, written on another processor, is exactly this: its
#: (0.8, 0.1, "mpl", 1 + 1e-9) row is reproduced to the bit here by moving the table's node 11
#: (Gamma - 1 = 8.0e-10) by -1 ulp; V differs by 1.0e-9 (0.005 kappa eps), dV/dg by 1.85e-7
#: (0.83 kappa eps). c is four times the measured worst at the threshold: 8 and 100, i.e.
#: 1.8e-6 and 2.2e-5 at g = 1 + 1e-9; every other row (kappa <= 1.3e3: <= 2.8e-11) keeps
#: SPEED_RTOL. A law changed by 1e-6 fails every other row.
SPEED_RTOL = 1e-10
SPEED_C_V, SPEED_C_DV = 8.0, 100.0


def _speed_rtol(g, v_ref, dv_ref):
    """(rtol of V, rtol of dV/dg) of the fixture's row at ``g`` (the comment above
    :data:`SPEED_RTOL`); kappa = 0 at the speed cap, where dV/dg = 0."""
    kappa = g * dv_ref / v_ref
    eps = np.finfo(float).eps
    return max(SPEED_RTOL, SPEED_C_V * kappa * eps), max(SPEED_RTOL, SPEED_C_DV * kappa * eps)


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
        rtol_v, rtol_dv = _speed_rtol(spec[3], row["v"], row["dv"])
        assert v == pytest.approx(row["v"], rel=rtol_v, abs=0.0), spec
        assert dv == pytest.approx(row["dv"], rel=rtol_dv, abs=0.0), spec


def test_speed_tolerance_only_at_the_threshold():
    """The condition-number tolerance loosens only the rows at g = 1 + 1e-9 (kappa ~ 1e9);
    every other row is held to SPEED_RTOL."""
    ref = _fixture()["speeds"]
    for spec, row in zip(SPEEDS, ref):
        rtols = _speed_rtol(spec[3], row["v"], row["dv"])
        if spec[3] == 1.0 + 1e-9:
            assert 1e-6 < rtols[0] < 2e-6 and 2e-5 < rtols[1] < 3e-5, (spec, rtols)
        else:
            assert rtols == (SPEED_RTOL, SPEED_RTOL), (spec, rtols)


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

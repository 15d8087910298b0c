"""The PDMS report's numbers: limits, monotonicity and closed forms (the target itself is
`make pdms`)."""
import math

import numpy as np
import pytest

from sweep.crack_front import pb_law_for_scene, unload
from sweep.pdms import PDMS_CASE, compute, pdms_scene
from sweep.theory import pb_gamma_eff
from tests.reference import paper_values

PV = paper_values()["pdms_experiment"]


@pytest.fixture(scope="module")
def res():
    return compute()


def test_keys_and_scales(res):
    for key in ("speeds_um_s", "pull_off_mN", "mu", "l0_nm", "a0t_mm",
                "speed_full_amplification_m_s"):
        assert key in res
    assert set(res["pull_off_mN"]) == {"crack_pb", "crack_gs", "pb_estimate", "pb_estimate_l0"}
    assert res["mu"] == pytest.approx(103, abs=0.5)
    assert res["l0_nm"] == pytest.approx(PV["l0_nm"], abs=0.05)
    assert res["speeds_um_s"][0] == 1.0 and res["speeds_um_s"][-1] == pytest.approx(1e4)
    assert res["jkr_pull_off_mN"] == pytest.approx(3.725, abs=5e-4)


def test_pull_off_grows_with_speed_for_every_model(res):
    for name, p in res["pull_off_mN"].items():
        assert np.all(np.diff(p) > 0), name
        assert p[0] > res["jkr_pull_off_mN"] * (1 - 1e-9), name
    # the closed-form chain at 1 um/s (rhat_PB = r tau0/d_ref ~ 3e-3) is the relaxed JKR
    assert res["pull_off_mN"]["pb_estimate"][0] == pytest.approx(res["jkr_pull_off_mN"],
                                                                  rel=5e-3)


def test_crack_front_pb_reaches_jkr_only_far_below_1_um_s():
    si = pdms_scene(1e-11)            # 1e-5 um/s: crack speed ~ 2e-4 um/s, vhat ~ 0.1
    d = si.dimensionless()
    law = pb_law_for_scene(d["n"], d["k"], d["mu"])
    s = unload(law, rate=d["rate"], mu=d["mu"], a0=d["a0"])
    assert s.pull_off == pytest.approx(1.5, rel=0.05)


def test_discussion_estimates(res):
    k = res["k"]
    col = PDMS_CASE["threshold_collapse"]
    assert col["prefactor"] * res["a0t_hat"] ** col["exponent"] == pytest.approx(1.5 / k)
    assert res["a0t_mm"] == pytest.approx(res["a0t_hat"] * res["a_ref_mm"])
    assert res["a0t_mm"] == pytest.approx(PV["threshold_radius_estimate"]["a0t_mm"], abs=0.05)
    f = res["full_amplification_fraction"]
    assert float(pb_gamma_eff(PDMS_CASE["n"], k, res["vhat_full_amplification"])) * k \
        == pytest.approx(f, rel=1e-6)
    # the v-r fit inverted with rhat = r tau0 / l0
    rhat = res["speed_full_amplification_m_s"] * PDMS_CASE["tau0"] / (res["l0_nm"] * 1e-9)
    assert 2.887 * rhat ** 1.171 == pytest.approx(res["vhat_full_amplification"], rel=1e-9)
    assert math.isfinite(res["speed_full_amplification_crack_front_m_s"])


def test_gs_over_linear_ratio(res):
    g = res["gs_over_linear"]
    np.testing.assert_allclose(np.array(g["gamma_gs"]) / np.array(g["gamma_lin"]), g["ratio"])
    v = np.array(g["crack_speed_um_s"])
    np.testing.assert_allclose(g["paper_fit"], 1 + np.sqrt(v / 1e4))

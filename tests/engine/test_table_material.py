"""A Prony table as the material in every model (issue 36 item 1): the BEM marches the table's
own Kelvin series, the crack-front model and the pb estimate use its discrete spectrum.

Checks with independent values:

(a) an SLS as a one-term table equals ``material: sls`` (BEM, crack-front, pb) to 1e-9 in
    the pull-off (measured at most 4e-13): the same Chat by two routes (the SLS closed form and its exact one-term series; the table read from
    its Wiechert form, relaxation time k tau0, and converted to Kelvin by partial fractions).
(b) the MPL's own Prony series (:func:`sweep.engine.problem.prepare`'s, on the scene's window,
    ``prony_rtol`` 1e-4 of the balanced preset) given as a Kelvin table reproduces the MPL
    scene: the BEM marches the same series (measured 5e-12 and 4e-11 relative at rates 1 and
    100), the crack-front model compares the table's discrete Persson-Brener spectrum against
    the MPL's closed form (measured 2.0e-6 and 5.9e-6 relative): both within the series'
    rtol 1e-4.
"""
import numpy as np
import pytest

from sweep import simulate
from sweep.engine.crack_front import PerssonBrenerLaw
from sweep.engine.models import pb_estimate
from sweep.engine.problem import material_of, prepare
from sweep.errors import InputError
from sweep.scene import Numerics, Scene

NUM = Numerics.preset("balanced")
SMALL = {"mu": 5.0, "a0": 1.5}        # ~0.1-1 s a BEM scene
K = 0.1


def sls_table(k=K):
    """The SLS (retardation time 1) as a one-arm Wiechert table: relaxation time k,
    arm modulus Einf - E0 (E0 = 1)."""
    return {"tau": [k], "E": [1.0 / k - 1.0], "E0": 1.0}


@pytest.mark.parametrize("model", ["bem", "crack"])     # pb refuses a table (TABLE_REFUSALS)
@pytest.mark.parametrize("rate", [1.0, 100.0])
def test_sls_as_a_one_term_table_is_the_sls(model, rate):
    """(a): pull-off to 1e-9 relative (the two Chats differ by the partial-fraction
    round-off, ~1e-16; measured at most 4e-13, the BEM at rate 1), the crack speed to 1e-7:
    the BEM takes it from a local fit of a(t), which amplifies that round-off (measured
    2.1e-9 at rate 1; 0 to 2e-15 elsewhere)."""
    a = simulate(Scene(material="sls", n=0.8, k=K, rate=rate, model=model, **SMALL), NUM)
    b = simulate(Scene(material=sls_table(), n=0.8, rate=rate, model=model, **SMALL), NUM)
    assert a.ok and b.ok, (a.reason, b.reason)
    assert b.pull_off == pytest.approx(a.pull_off, rel=1e-9)
    assert b.crack_speed == pytest.approx(a.crack_speed, rel=1e-7)
    if model == "bem":
        assert b.prony_terms == 1 and b.prony_error == 0.0


def test_sls_table_with_a_process_zone_is_the_sls_with_it():
    pz = {"pz_law": "gent-schultz", "pz_v0": 1.0, "pz_xi": 0.5}
    a = simulate(Scene(material="sls", n=0.8, k=K, rate=10.0, model="crack", **pz, **SMALL))
    b = simulate(Scene(material=sls_table(), n=0.8, rate=10.0, model="crack", **pz, **SMALL))
    assert a.ok and b.ok
    assert b.pull_off == pytest.approx(a.pull_off, rel=1e-9)


def mpl_series_table(rate):
    """The MPL scene's own Prony series (n 0.8, k 0.1) as a Kelvin table; its lumped glassy
    term (time inf) becomes a mode 1e6 times slower than the window's slowest (a table's
    times are finite): over the window it changes Chat by at most c_inf 1e-6."""
    pb = prepare(Scene(material="mpl", n=0.8, k=K, rate=rate, **SMALL), NUM)
    w, t = pb.prony_weights.copy(), pb.prony_times.copy()
    t[~np.isfinite(t)] = 1e6 * t[np.isfinite(t)].max()
    assert pb.prony_error <= NUM.prony_rtol
    return {"tau": t.tolist(), "c": w.tolist(), "E0": 1.0, "form": "kelvin"}


@pytest.mark.parametrize("model", ["bem", "crack"])
@pytest.mark.parametrize("rate", [1.0, 100.0])
def test_the_mpl_series_as_a_table_reproduces_the_mpl(model, rate):
    """(b): within the series' rtol (prony_rtol 1e-4; measured in the module docstring)."""
    tab = mpl_series_table(rate)
    a = simulate(Scene(material="mpl", n=0.8, k=K, rate=rate, model=model, **SMALL), NUM)
    b = simulate(Scene(material=tab, n=0.8, rate=rate, model=model, **SMALL), NUM)
    assert a.ok and b.ok, (a.reason, b.reason)
    assert b.pull_off == pytest.approx(a.pull_off, rel=NUM.prony_rtol)
    if model == "bem":
        assert b.prony_terms == len(tab["tau"]) and b.prony_error == 0.0


def test_material_of_a_table_scene_is_its_kelvin_table():
    """The exact-convolution reference and the tip-following mesh read material_of: for a
    table, Chat and its integral from the table (SLS closed forms, 1e-12)."""
    s = Scene(material=sls_table(), n=0.8, rate=1.0, **SMALL)
    sls = material_of(Scene(material="sls", n=0.8, k=K, rate=1.0, **SMALL))
    t = np.logspace(-3, 2, 11)
    m = material_of(s)
    assert m.normalized_creep_compliance(t) == pytest.approx(
        sls.normalized_creep_compliance(t), rel=1e-12)
    assert m.integrated_compliance(t) == pytest.approx(sls.integrated_compliance(t), rel=1e-12)


def test_pb_estimate_of_a_table_is_its_spectrum():
    """The pb estimate needs only Gamma_PB(vhat), which a table's discrete spectrum has: the
    SLS table gives the SLS's; the law refuses a k other than the table's."""
    tab = Scene(material=sls_table(), n=0.8, rate=1.0, **SMALL).material
    a = pb_estimate(0.8, K, 5.0, 30.0, "sls")
    b = pb_estimate(0.8, tab.k, 5.0, 30.0, tab)
    assert b["pull_off"] == pytest.approx(a["pull_off"], rel=1e-12)
    with pytest.raises(InputError, match="k must be the table's"):
        PerssonBrenerLaw(0.8, 0.3, 1.0, tab)


def test_sls_table_in_the_exact_reference():
    """The exact-convolution reference (numerics.exact, material_of's integrated compliance)
    of the SLS table equals the SLS's: measured 1.4e-14 relative, asserted 1e-9."""
    num = Numerics(nodes=80, exact=True, domain=4.0)
    a = simulate(Scene(material="sls", n=0.8, k=K, mu=3.0, a0=1.5, rate=10.0), num)
    b = simulate(Scene(material=sls_table(), n=0.8, mu=3.0, a0=1.5, rate=10.0), num)
    assert a.ok and b.ok and b.prony_terms == 0
    assert b.pull_off == pytest.approx(a.pull_off, rel=1e-9)

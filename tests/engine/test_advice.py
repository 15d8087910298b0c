"""Failure messages give advice that fits the model and mesh that ran (issue 21 item 3)."""
from __future__ import annotations

from sweep.engine.bem import no_contact_reason
from sweep.engine.resolution import estimate_error, refine_advice
from sweep.scene import Numerics, Result, Scene

SCENE = Scene(n=0.8, k=0.1, mu=3.24, a0=2.0, rate=10.0)


def test_refine_advice_names_the_knob_of_the_mesh_that_ran():
    assert refine_advice(Numerics.preset("balanced")).startswith("raise band_resolution")
    assert "nodes" not in refine_advice(Numerics.preset("fast"))
    assert refine_advice(Numerics()).startswith("raise nodes (the uniform")
    assert refine_advice(Numerics(nodes=300)).startswith("raise nodes (the uniform")
    assert refine_advice(Numerics.preset("balanced", nodes=300)).startswith(
        "raise nodes (the graded mesh's fine spacing follows)")


def test_unresolved_message_fits_the_mesh():
    for numerics, knob in ((Numerics.preset("balanced"), "raise band_resolution"),
                           (Numerics(nodes=300), "raise nodes")):
        res = Result(scene=SCENE, numerics=numerics, status="ok", pull_off=4.0)
        coarse = Result(scene=SCENE, numerics=numerics, status="ok", pull_off=3.0)
        estimate_error(res, 0.1, lambda num: coarse)
        assert res.status == "failed" and res.reason.endswith(refine_advice(numerics))
        assert knob in res.reason
        if knob == "raise nodes":
            assert "band_resolution" not in res.reason


def test_no_contact_reason_fits_the_initial_state_given():
    by_a0 = no_contact_reason(SCENE, 0.0)
    assert "a0 = 2" in by_a0 and "delta0" not in by_a0
    by_delta0 = no_contact_reason(Scene(n=0.8, k=0.1, mu=3.24, delta0=-0.5, rate=10.0), 0.0)
    assert "delta0 = -0.5 is below the jump-in" in by_delta0

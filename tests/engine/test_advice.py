"""Failure messages give advice that fits the model and mesh that ran (issue 21 item 3)."""
from __future__ import annotations

from sweep.engine.bem import no_contact_reason
from sweep.engine.crack_front import answers
from sweep.engine.models import simulate_model
from sweep.engine.resolution import estimate_error, refine_advice
from sweep.engine.tip_following import fold_advice
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


def _crack_refuses(scene) -> bool:
    """Whether the crack-front model, run through the models' front door, refuses ``scene``
    (a failed row without a pull-off)."""
    res = simulate_model(scene, "crack", Numerics.preset("fast"))
    return not res.ok


def test_advice_names_the_crack_front_model_only_where_it_runs_the_scene():
    relaxed = dict(n=0.8, k=0.1, mu=18.0, rate=10.0)
    scenes = {
        "relaxed start": Scene(a0=2.0, **relaxed),
        "from an indentation": Scene(delta0=1.0, **relaxed),
        "a contact below fixed grip's stability": Scene(a0=0.4, **relaxed),
        "a test protocol": Scene(approach_rate=10.0, preload=2.0, dwell=1.0, **relaxed),
        "a compliant machine": Scene(a0=2.0, machine_stiffness=10.0, **relaxed),
    }
    runs = {name: not _crack_refuses(scene) for name, scene in scenes.items()}
    assert runs == {"relaxed start": True, "from an indentation": True,
                    "a contact below fixed grip's stability": False, "a test protocol": False,
                    "a compliant machine": False}
    for name, scene in scenes.items():
        assert answers(scene) == runs[name], name
        assert ("model crack" in fold_advice(scene)) == runs[name], name
        assert fold_advice(scene).startswith("raise band_resolution")


def test_a_protocol_beyond_the_bem_range_is_not_sent_to_the_crack_front_model():
    scene = Scene(n=0.8, k=0.1, mu=150.0, rate=10.0, approach_rate=10.0, preload=2.0,
                  dwell=1.0, model="auto")
    res = simulate_model(scene, "auto", Numerics.preset("fast"))
    assert not res.ok and "outside the hereditary BEM's range" in res.reason
    assert "crack" not in res.reason


def test_beyond_the_bem_range_the_advice_names_a_model_that_runs_there():
    """Above mu = 100 the BEM's refusal had advised the elastic branch, which refuses there
    too (user test J, session 50): it names the crack-front model, which answers it."""
    from sweep.engine.models import simulate_model as run

    scene = Scene(n=0.8, k=0.1, mu=1e6, a0=2.0, rate=10.0)
    res = run(scene, "bem", Numerics.preset("fast"))
    assert "model elastic" not in res.reason and "model crack or auto" in res.reason
    assert run(scene, "crack").ok


def test_an_unresolved_row_quotes_the_estimate_it_compared():
    """The reason quotes the pair's change and the estimate compared with pull_off_rtol (the
    change over 2^ESTIMATE_ORDER - 1): a change below the tolerance whose estimate is above
    it read as a contradiction ("moves by 0.0061 ..., above pull_off_rtol = 0.01")."""
    numerics = Numerics.preset("balanced")
    res = Result(scene=SCENE, numerics=numerics, status="ok", pull_off=1.0, spacing=0.01)
    coarse = Result(scene=SCENE, numerics=numerics, status="ok", pull_off=1.0061)
    estimate_error(res, 0.1, lambda num: coarse)
    assert res.status == "failed" and 0.0061 < numerics.pull_off_rtol < res.error_estimate
    assert "the pull-off moves by 0.0061 on a mesh of 1/2" in res.reason
    assert f": estimate {res.error_estimate:.2g} (change / (2^0.65 - 1))" in res.reason

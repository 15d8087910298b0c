"""Pull-off refinement (sweep.engine.postprocess.refine_minimum) against closed forms."""
import numpy as np
import pytest

from sweep.engine.postprocess import refine_minimum


@pytest.mark.parametrize("vertex_t", [0.3, 0.5, 0.7, 1.2])
def test_parabola_minimum_is_recovered_exactly(vertex_t):
    t = np.linspace(0.0, 2.0, 21)
    P = 0.8 * (t - vertex_t) ** 2 - 3.0
    _, ts, Ps = refine_minimum(t, P)
    assert ts == pytest.approx(vertex_t, abs=1e-12)
    assert Ps == pytest.approx(-3.0, abs=1e-12)


def test_a_jump_of_the_load_gives_the_sampled_minimum_not_a_wild_vertex():
    """The samples around a load jump (-3.888, -3.889, -2.770, as at a broken re-meshing)
    are no parabola; their vertex lies at -73 and must not be reported."""
    t = np.array([0.0, 1.0, 2.0, 3.0, 4.0])
    P = np.array([-3.8870, -3.8880, -3.8890, -2.7700, -2.7690])
    i, ts, Ps = refine_minimum(t, P)
    assert (i, ts, Ps) == (2, 2.0, -3.8890)

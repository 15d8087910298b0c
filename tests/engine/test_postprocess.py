"""Pull-off refinement (sweep.engine.postprocess.refine_minimum) and the cycle's work
(cycle_work, work_quadrature_error) against closed forms."""
import numpy as np
import pytest

from sweep.engine.postprocess import cycle_work, refine_minimum, work_quadrature_error


@pytest.mark.parametrize("vertex_t", [0.3, 0.5, 0.7, 1.2])
def test_parabola_minimum_is_recovered_exactly(vertex_t):
    t = np.linspace(0.0, 2.0, 21)
    P = 0.8 * (t - vertex_t) ** 2 - 3.0
    _, ts, Ps = refine_minimum(t, P)
    assert ts == pytest.approx(vertex_t, abs=1e-12)
    assert Ps == pytest.approx(-3.0, abs=1e-12)


def test_the_minimum_is_recovered_late_in_a_long_run():
    """Steps of 1e-4 tau0 at t ~ 3600 tau0 (a retraction after a test protocol's dwell): in
    absolute time the parabola's terms cancelled to a relative precision of ~2e-7."""
    t = 3598.159 + 1e-4 * np.arange(21)
    vertex_t = t[10] + 0.3e-4
    P = 0.5e8 * (t - vertex_t) ** 2 - 4.689463
    _, ts, Ps = refine_minimum(t, P)
    assert Ps == pytest.approx(-4.689463, rel=1e-12)
    assert ts == pytest.approx(vertex_t, abs=1e-10)


def test_a_jump_of_the_load_gives_the_sampled_minimum_not_a_wild_vertex():
    """The samples around a load jump (-3.888, -3.889, -2.770, as at a broken re-meshing)
    are no parabola; their vertex lies at -73 and must not be reported."""
    t = np.array([0.0, 1.0, 2.0, 3.0, 4.0])
    P = np.array([-3.8870, -3.8880, -3.8890, -2.7700, -2.7690])
    i, ts, Ps = refine_minimum(t, P)
    assert (i, ts, Ps) == (2, 2.0, -3.8890)


# -- quantities at the pull-off never straddle a re-meshing (issue 21) ----------------------
from types import SimpleNamespace  # noqa: E402

from sweep.engine.postprocess import finish, one_mesh_span  # noqa: E402
from sweep.kernels.solve import STATUS_DONE  # noqa: E402
from sweep.scene import Numerics, Result, Scene  # noqa: E402

SPACING = 3e-4
SCALES = SimpleNamespace(process_zone=0.01, loading_speed=1.0)


def remeshed_trajectory(m=40, n=80, dP=-0.11, da=0.0029, speed=3.0e4, dt=4.8e-9):
    """A trajectory like the issue's scene (n=1.916, mu=18.98, sls, balanced): the crack tip
    recedes at ``speed``; the load falls until record ``m``, where the tip-following mesh
    changes, the load steps by ``dP`` (-0.11: 0.11 % |P|) and the tip radius by ``da``
    (+2.9e-3, 10 node spacings) and then rises: the load minimum is the first record of the
    new mesh."""
    k = np.arange(n)
    t = k * dt
    a = 2.62 - speed * t + np.where(k < m, 0.0, da)
    P = np.where(k < m, -95.2712 + 3e-6 * (m - 1 - k) ** 2,
                 -95.2712 + dP + 3e-4 * (k - m) + 1e-6 * (k - m) ** 2)
    return {"t": t, "delta": -t, "P": P, "a": a, "a_inner": a - 0.1}


def run_finish(traj, remeshed=(), **scene):
    res = Result(scene=Scene(**{**dict(n=0.8, k=0.1, mu=3.24, a0=2.0, rate=10.0), **scene}),
                 numerics=Numerics.preset("balanced"))
    finish(res, STATUS_DONE, traj, SPACING, 0.0, SCALES, advice="refine", remeshed=remeshed)
    return res


def test_one_mesh_span():
    assert one_mesh_span(5, 20) == (0, 20)
    assert one_mesh_span(5, 20, [3, 9, 15]) == (3, 9)
    assert one_mesh_span(9, 20, [3, 9, 15]) == (9, 15)
    assert one_mesh_span(8, 20, [3, 9, 15]) == (3, 9)
    assert one_mesh_span(16, 20, [3, 9, 15]) == (15, 20)


def test_load_minimum_on_a_remeshing_is_read_on_one_mesh():
    traj = remeshed_trajectory()
    m = 40
    assert int(np.argmin(traj["P"])) == m
    # read across the re-meshing (as before the fix): the crack-speed fit takes the step of
    # the state transfer for motion, the contact "advances"; the guard makes that a failure
    across = run_finish(traj)
    assert across.status == "failed" and across.reason.startswith("negative crack speed")
    # read on the new mesh only: the sampled minimum, the speed of the receding tip
    res = run_finish(traj, remeshed=[10, m, 70])
    assert res.ok and res.pull_off == pytest.approx(95.3812, abs=1e-12)
    assert res.t_pulloff == traj["t"][m] and res.a_pulloff == traj["a"][m]
    assert res.crack_speed == pytest.approx(3.0e4, rel=1e-6)
    assert "load minimum at a re-meshing" in res.reason and "new mesh only" in res.reason
    assert "stepped by 0.0012 |P|" in res.reason


def test_remeshing_away_from_the_minimum_changes_nothing():
    """A re-meshing far from the minimum (outside the parabola's and the fit's samples)
    leaves every quantity bitwise as on one mesh."""
    traj = remeshed_trajectory(m=40, da=0.0, dP=0.0)
    P = traj["P"]
    P[:] = (np.arange(80) - 50.3) ** 2 * 1e-3 - 95.0        # a smooth minimum at record 50
    one, split = run_finish(traj), run_finish(traj, remeshed=[20, 70])
    assert one.ok and split.ok and one.reason == split.reason == ""
    for name in ("pull_off", "t_pulloff", "a_pulloff", "delta_pulloff", "crack_speed"):
        assert getattr(one, name) == getattr(split, name)


def test_ok_result_never_has_a_negative_crack_speed():
    traj = remeshed_trajectory(da=0.0)
    traj["a"] = 2.0 + 3.0e4 * traj["t"]                    # the contact advancing
    res = run_finish(traj)
    assert res.status == "failed" and np.isnan(res.pull_off)
    assert res.reason.startswith("negative crack speed at the pull-off (-3e+04 a_ref/tau0")


def test_a_contact_that_vanished_before_the_load_minimum_says_so():
    """A process zone strong enough to hold the surfaces after the contact's end: the tip
    reaches the axis (a = 0) while the load still falls (a strong zone at a fast unloading:
    n 0.5902, k 0.02331, mu 1.076, a0 1.31, rate 380400, pz_v0 1.201, xi 0.785 had
    "negative crack speed at the pull-off ... a = 0"). The fit's speed there is 0 (a flat a
    = 0), or negative where a node closes again: neither is a crack speed, and the reason
    names the vanished contact."""
    t = np.linspace(0.0, 1.0, 41)
    a = np.maximum(1.0 - 1.25 * t, 0.0)                    # a = 0 from t = 0.8
    P = -10.0 - 5.0 * t
    P[-1] = P[-2] + 1e-9                                   # a flat minimum one record back
    traj = {"t": t, "delta": -t, "P": P, "a": a, "a_inner": 0.0 * a}
    res = run_finish(traj)
    assert res.status == "failed" and np.isnan(res.pull_off)
    assert res.reason.startswith("the contact vanished (a = 0 from t = 0.8 tau0) before the "
                                 "load minimum P = -14.875")


ZONE = dict(pz_law="gent-schultz", pz_v0=1.0, pz_xi=0.5)


def test_a_process_zone_that_held_the_surfaces_gives_the_pull_off_without_a_crack_speed():
    """With a process zone the stop rule follows the load past a contact that vanished
    before its minimum (stop mode 2) until it recovers; the row is then ok: the pull-off is
    the load minimum, read as every pull-off is (the parabola through the records around
    it, here exactly the synthetic parabola's vertex), and the crack speed is NaN, for there
    is no crack tip at the pull-off, the reason says why. Without a process zone, or with
    a load that has not recovered, the row fails as before."""
    from sweep.engine.postprocess import stop_mode
    from sweep.kernels.solve import stop_reached

    t = np.linspace(0.0, 1.0, 81)
    a = np.maximum(1.0 - 2.5 * t, 0.0)                     # a = 0 from t = 0.4
    P = 40.0 * (t - 0.6) ** 2 - 20.0                       # the minimum -20 at t = 0.6
    traj = {"t": t, "delta": -t, "P": P, "a": a, "a_inner": 0.0 * a}
    assert stop_mode(Scene(n=0.8, k=0.1, mu=3.24, a0=2.0, rate=10.0, **ZONE)) == 2
    res = run_finish(traj, **ZONE)
    assert res.ok, res.reason
    assert res.pull_off == pytest.approx(20.0, rel=1e-12)
    assert res.t_pulloff == pytest.approx(0.6, rel=1e-9)
    assert np.isnan(res.crack_speed) and res.a_pulloff == 0.0
    assert res.reason.startswith("the contact vanished (a = 0 from t = 0.4 tau0) before the "
                                 "load minimum P = -20")
    assert res.reason.endswith("no crack speed at the pull-off")
    plain = run_finish(traj)                               # no process zone: stop mode 0
    assert plain.status == "failed" and plain.reason.startswith("the contact vanished")
    # the stop rule itself: at the first rise after the minimum mode 0 stops (contact lost),
    # mode 2 goes on until the load has recovered by RECOVERY over RECOVERY_STEPS steps
    i_min, first_rise = 48, 50
    assert stop_reached(P, a, first_rise, i_min, 0, 0.01)
    assert not stop_reached(P, a, first_rise, i_min, 2, 0.01)
    assert stop_reached(P, a, 81, i_min, 2, 0.01)
    # where the contact was there at the minimum, mode 2 stops as mode 0 does
    b = (np.arange(t.size) <= i_min).astype(float)
    assert stop_reached(P, b, first_rise, i_min, 2, 0.01)


def test_a_pull_off_at_the_initial_state_reads_the_first_steps_speed():
    """A contact that starts at or beyond its pull-off (past the JKR fold at low mu): the load
    only rises from record 0. The crack speed is the first step's radius change over its
    time (a one-sided fit centred there read 0.0035 to -0.0007 where the first steps give
    0.0082-0.0084 on the low-mu scene below). Closed form: a tip receding at a constant
    speed, then faster; the first step gives that speed exactly."""
    t = np.array([0.0, 2.0, 3.0, 4.0, 5.0])
    a = np.array([0.5, 0.48, 0.4, 0.2, 0.0])                 # 0.01 per unit time, then faster
    traj = {"t": t, "delta": -t, "P": -1.7 + 0.01 * t, "a": a, "a_inner": 0.0 * a}
    res = run_finish(traj)
    assert res.ok and res.pull_off == pytest.approx(1.7) and res.t_pulloff == 0.0
    assert res.crack_speed == pytest.approx(0.01, rel=1e-12)
    assert res.reason.startswith("load minimum at the initial state")


def test_the_initial_state_speed_converges_with_the_step():
    """The low-mu JKR-fold scene (n 0.19, k 0.0027, mu 0.033, rate 3.4e-4, a0 0.51), whose
    pull-off is its initial state: the crack speed at da_max 0.3 and 0.6 spacings (balanced's
    step otherwise) lies within 3 % of that at 0.1 (second method: the same first-step
    speed at a third of the step), where the previous centred fit read 0.0023 / 0.0035
    against 0.0011."""
    from sweep import simulate

    scene = Scene(n=0.1913, k=0.002652, mu=0.03253, rate=0.0003383, a0=0.51)
    speeds = {da: simulate(scene, Numerics.preset("balanced", da_max=da, pull_off_rtol=0.0))
              for da in (0.1, 0.3, 0.6)}
    assert all(r.ok and r.reason.startswith("load minimum at the initial state")
               for r in speeds.values())
    fine = speeds[0.1].crack_speed
    for da in (0.3, 0.6):
        assert speeds[da].crack_speed == pytest.approx(fine, rel=0.03)


def test_capture_fits_gives_the_inputs_of_the_reported_crack_speed():
    """The fit's inputs collected by ``capture_fits`` reproduce the result's crack speed
    bitwise (the crack-speed study reads them again under other windows); nothing is
    collected outside the block."""
    from sweep.engine.postprocess import capture_fits, crack_speed_on_mesh

    traj = remeshed_trajectory(m=40, da=0.0, dP=0.0)
    traj["P"] = (np.arange(80) - 50.3) ** 2 * 1e-3 - 95.0
    traj["a"] = 2.62 - 3.0e4 * traj["t"] - 1e12 * traj["t"] ** 2     # an accelerating tip
    with capture_fits() as fits:
        res = run_finish(traj, remeshed=[20, 70])
    run_finish(traj)
    assert res.ok and len(fits) == 1
    f = fits[0]
    assert (f["lo"], f["hi"], f["spacing"]) == (20, 70, SPACING) and f["t_star"] == res.t_pulloff
    assert crack_speed_on_mesh(f["t"], f["a"], f["t_star"], f["spacing"], f["lo"], f["hi"]) \
        == res.crack_speed
    # closed form: -da/dt = 3e4 + 2e12 t at the pull-off instant
    assert res.crack_speed == pytest.approx(3.0e4 + 2e12 * res.t_pulloff, rel=1e-9)


def test_the_cycle_work_and_its_quadrature_error_on_a_parabola():
    """P = delta^2 recorded at spacing h on [0, 1]: the trapezoid gives 1/3 + h^2/6, on
    every other record 1/3 + 4 h^2/6; their difference, h^2/2, is what the quadrature error
    reports (relative to the work); ``until`` ends the path between records."""
    h = 1.0 / 16
    d = np.arange(17) * h
    traj = {"t": d.copy(), "delta": d, "P": d**2, "phase": np.zeros(d.size)}
    assert cycle_work(traj) == pytest.approx(1 / 3 + h**2 / 6, rel=1e-13)
    assert cycle_work(traj, halved=True) == pytest.approx(1 / 3 + 4 * h**2 / 6, rel=1e-13)
    assert work_quadrature_error(traj) == pytest.approx((h**2 / 2) / (1 / 3 + h**2 / 6),
                                                        rel=1e-12)
    # the path ends at t = 0.5 + h / 2 (delta there, P its square): [0, 0.5] then one half step
    end = 0.5 + h / 2
    assert cycle_work(traj, until=(end, end, end**2)) == pytest.approx(
        cycle_work({"delta": d[:9], "P": d[:9] ** 2}) + 0.5 * (0.25 + end**2) * h / 2, rel=1e-13)


def test_halving_keeps_each_phase_and_its_ends():
    """An approach up P = delta^2 and a retraction down the same records: the two cancel on
    the halved records as on all of them (each phase's first and last kept), whatever the
    phases' parities; on another retraction curve the halved path is that of the records
    kept."""
    up = np.arange(10) / 9.0                      # 10 records: its last, odd, is kept
    down = up[::-1][1:]
    traj = {"delta": np.concatenate([up, down]), "P": np.concatenate([up, down]) ** 2,
            "phase": np.concatenate([np.zeros(10), np.full(9, 2.0)])}
    assert cycle_work(traj) == pytest.approx(0.0, abs=1e-15)
    assert cycle_work(traj, halved=True) == pytest.approx(0.0, abs=1e-15)
    traj["P"] = np.concatenate([up**2, down**2 - 1.0])
    kept = [0, 2, 4, 6, 8, 9, 10, 12, 14, 16, 18]
    assert cycle_work(traj, halved=True) == pytest.approx(
        cycle_work({key: traj[key][kept] for key in ("delta", "P")}), rel=1e-14)


# -- a path that folds past its load minimum ------------------------------------------------
from sweep.engine.postprocess import FOLD_REASON  # noqa: E402
from sweep.kernels.solve import STATUS_NEWTON_FAILED  # noqa: E402


def folded_trajectory(n_after: int, rise: float, n=120, i_min=80, dt=1e-3):
    """A retraction whose load reaches its minimum P = -10 at record ``i_min`` (a parabola in
    time), its crack tip receding one fine spacing a record throughout, and whose solve
    failed (the discrete path folds) ``n_after`` records past the minimum, where the load
    has risen by ``rise`` of |P_min|."""
    k = np.arange(i_min + n_after + 1)
    t = k * dt
    curvature = rise * 10.0 / max(n_after, 1) ** 2
    P = -10.0 + curvature * (k - i_min) ** 2
    a = 2.0 - SPACING * k
    return {"t": t, "delta": -t, "P": P, "a": a, "a_inner": a - 0.1}


def run_folded(traj):
    res = Result(scene=Scene(n=0.8, k=0.1, mu=3.24, a0=2.0, rate=1.0), numerics=Numerics())
    finish(res, STATUS_NEWTON_FAILED, traj, SPACING, 3.0 * SPACING, SCALES, advice="refine")
    return res


def test_a_fold_past_the_load_minimum_gives_the_minimum_as_the_pull_off():
    """The fold 10 records (10 spacings of crack travel) past the minimum, the load risen by
    1e-3 of it, short of the stop rule's 5 % recovery: the minimum is the pull-off (the
    parabola's vertex exactly), the reason says where the path folded."""
    res = run_folded(folded_trajectory(n_after=10, rise=1e-3))
    assert res.ok, res.reason
    assert res.pull_off == pytest.approx(10.0, rel=1e-12)
    assert res.a_pulloff == pytest.approx(2.0 - 80 * SPACING, rel=1e-12)
    assert res.crack_speed == pytest.approx(SPACING / 1e-3, rel=1e-6)
    assert "folds past the load minimum (10 records later" in res.reason
    assert "receded 10 spacings" in res.reason


@pytest.mark.parametrize("n_after, rise", [(0, 0.0), (2, 1e-3)])
def test_a_fold_at_or_near_the_minimum_is_no_pull_off(n_after, rise):
    """A fold at the minimum (the load still falling), or within the stop rule's crack travel
    past it (3 spacings: a dip of the load as the tip crosses a node), stays a failure with
    the fold's advice."""
    traj = folded_trajectory(n_after=n_after, rise=rise)
    if n_after == 0:
        traj["P"] = traj["P"] - 1e-3 * np.arange(traj["P"].size)   # still falling at the end
    res = run_folded(traj)
    assert res.status == "failed" and res.reason.startswith(FOLD_REASON), res.reason
    assert res.reason.endswith("refine")


def test_a_load_that_overflowed_is_no_pull_off():
    """A run whose load is NaN from some record on (time steps past the arithmetic's range)
    is a failure saying so, never an ok row with a NaN pull-off (np.argmin takes a NaN for
    the minimum)."""
    traj = folded_trajectory(n_after=30, rise=0.06)
    traj["P"][90:] = np.nan
    res = Result(scene=Scene(n=0.8, k=0.1, mu=3.24, a0=2.0, rate=1.0), numerics=Numerics())
    finish(res, STATUS_DONE, traj, SPACING, 3.0 * SPACING, SCALES, advice="refine")
    assert res.status == "failed" and "not finite from record 90 on" in res.reason


def test_an_unloading_too_slow_for_the_arithmetic_fails_with_the_reason():
    """Independent value: the relaxed limit. At rate 1e-120 the time steps (1e116 tau0 and
    more) overflow Newton's start, and the row fails saying so; at 1e-90 and 1e-100 the
    pull-offs agree to 1e-10 (measured 1e-12), the material relaxed long before."""
    from sweep import simulate

    scene = dict(n=0.8, k=0.1, mu=3.24, a0=2.0)
    num = Numerics.preset("fast", pull_off_rtol=0.0)
    slow, slower = (simulate(Scene(rate=rate, **scene), num) for rate in (1e-90, 1e-100))
    assert slow.ok and slower.ok
    assert slower.pull_off == pytest.approx(slow.pull_off, rel=1e-10)
    res = simulate(Scene(rate=1e-120, **scene), num)
    assert res.status == "failed" and "the solve overflowed" in res.reason, res.reason


def test_the_retraction_clock_is_its_indentation_where_the_absolute_one_is_too_coarse():
    """After 1e15 tau0 the float spacing of the records' absolute time (0.125) exceeds the
    retraction's steps (1e-3): the local clock is (delta[first] - delta) / speed, exact for a
    rigid machine; after 1e3 tau0 the records' own times are kept."""
    from sweep.engine.postprocess import retraction_clock

    first, speed, dt = 5, 2.0, 1e-3
    local = np.concatenate([np.linspace(-1.0, 0.0, first + 1)[:-1], dt * np.arange(50)])
    delta = np.where(np.arange(local.size) < first, 0.0, -speed * local) + 1.0
    for start, kept in ((1e3, True), (1e15, False)):
        t = start + local
        clock, offset = retraction_clock(t, delta, first, speed)
        if kept:
            assert clock is t and offset == 0.0
        else:
            assert offset == t[first]
            np.testing.assert_allclose(clock[first:], local[first:], rtol=0, atol=1e-15)

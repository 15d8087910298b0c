"""The crack-speed study (sweep.bench.crack_speed): its re-reading of a fit under another
window, and its summary, against closed forms. A pure quadratic a(t) is read exactly by
every window; with a cubic term (a crack accelerating through the pull-off) a wider window
reads it with a bias of the size the closed form gives, which the summary must report."""
from __future__ import annotations

import math

import numpy as np
import pytest

from sweep.bench import crack_speed
from sweep.engine.postprocess import crack_speed_on_mesh

SPACING, ZONE = 0.01, 0.16            # balanced: 16 spacings per tip zone


def _row(name, label, v0, acc, jerk, dt, t_star=0.5, spacing=SPACING):
    """A record of a(t) = 1 - v0 t - acc t^2/2 - jerk t^3/6 around ``t_star`` every ``dt``;
    its true crack speed at t_star is v0 + acc t* + jerk t*^2/2."""
    t = np.arange(0.0, 1.0 + dt / 2, dt)
    a = 1.0 - v0 * t - acc * t ** 2 / 2 - jerk * t ** 3 / 6
    return dict(name=name, label=label, scene={}, status="ok", crack_speed=math.nan,
                tip_zone=ZONE, fit=dict(t=t, a=a, t_star=t_star, spacing=spacing, lo=0, hi=t.size))


def test_speed_under_the_engines_rule_is_the_engines_fit():
    row = _row("s", "balanced", 0.1, 0.05, 0.3, 0.01)
    f = row["fit"]
    assert crack_speed.speed_under(row, "3 spacings") == crack_speed_on_mesh(
        f["t"], f["a"], f["t_star"], f["spacing"], f["lo"], f["hi"])


def test_a_quadratic_is_read_exactly_by_every_window():
    row = _row("s", "balanced", 0.1, 0.05, 0.0, 0.01)
    for rule in crack_speed.WINDOW_RULES:
        assert crack_speed.speed_under(row, rule) == pytest.approx(0.1 + 0.05 * 0.5, rel=1e-10)


def test_the_summary_reports_the_bias_of_a_wide_window():
    """a(t) with a cubic term and no acceleration at t*, so that the window in radius is
    symmetric in time, [-w, w] with v w + jerk w^3/6 = W: the quadratic least-squares fit
    over evenly spaced samples reads the speed high by jerk w^2/10 in the continuum limit
    (the projection of -jerk tau^3/6 on tau is -jerk (3 w^2/5) tau/6). The reference, on a
    mesh three times finer (48 spacings per tip zone) and sampled finely, read with the
    engine's window of three of its spacings, has that bias at its own small w."""
    ts, jerk = 0.5, 0.3
    v0, acc = 0.2, -jerk * ts
    true = v0 + acc * ts + jerk * ts ** 2 / 2
    rows = [_row("threshold x", "reference", v0, acc, jerk, 0.0005, spacing=ZONE / 48),
            _row("threshold x", "balanced", v0, acc, jerk, 0.005)]
    s = crack_speed.summarize(rows)["threshold_mu3.24"]
    assert s["reference_spread_over_rules"]["scenes"] == 1
    narrow = s["balanced"]["rules"]["3 spacings"]
    wide = s["balanced"]["rules"]["max(3 spacings, 0.4 z)"]

    def bias(width):                                # jerk w^2/10, w the window in time
        w = np.roots([jerk / 6, 0.0, true, -width])
        return jerk * float(w[np.isreal(w)].real[0]) ** 2 / 10

    ref_v = crack_speed.speed_under(rows[0], crack_speed.REFERENCE_RULE)
    assert ref_v == pytest.approx(true + bias(3 * ZONE / 48), rel=1e-3)
    assert wide["max"] == pytest.approx((bias(0.4 * ZONE) - bias(3 * ZONE / 48)) / ref_v, rel=0.1)
    assert narrow["max"] == pytest.approx((bias(3 * SPACING) - bias(3 * ZONE / 48)) / ref_v,
                                          rel=0.15)
    assert narrow["max"] < wide["max"] / 3
    assert wide["above_target"] == int(wide["max"] > crack_speed.CRACK_SPEED_TARGETS["balanced"])
    assert crack_speed.summarize(rows)["coverage_sample"]["balanced"]["rules"]["3 spacings"]["scenes"] == 0

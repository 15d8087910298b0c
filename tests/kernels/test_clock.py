"""The clock compiled code reads (kernels.clock): it runs with Python's, and a deadline of
inf is never passed."""
import math
import time

from sweep.kernels.clock import deadline_after, now


def test_the_kernels_clock_runs_with_pythons():
    now()                                   # compiled (or loaded) before the reads
    t0 = time.perf_counter()
    k0 = now()
    time.sleep(0.2)
    k1 = now()
    t1 = time.perf_counter()
    # the kernels' interval lies inside Python's and spans the sleep (whatever the machine's
    # speed: no tolerance but the clocks' resolution)
    assert 0.2 <= k1 - k0 <= t1 - t0 + 1e-6


def test_a_deadline_is_seconds_from_now_on_the_kernels_clock():
    assert deadline_after(math.inf) == math.inf
    before = now()
    d = deadline_after(5.0)
    assert before + 5.0 <= d <= now() + 5.0

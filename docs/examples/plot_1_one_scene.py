"""
One scene and its load curve
============================

A rigid sphere pressed into an MPL half-space to the contact radius ``a0``, relaxed, then
pulled off at the dimensionless rate ``rate``: :func:`sweep.simulate` returns the pull-off
force, the contact radius and crack speed at the pull-off, an estimate of its own error and
the whole unloading trajectory. Units are the paper's (:doc:`/units`): loads in
``pi dg R``, radii in ``a_ref``, gaps in ``d_ref``.

The same scene on the command line::

    sweep scene --n 0.8 --k 0.1 --mu 3.24 --a0 3.61 --rate 316.2 --preset fast
"""
import matplotlib.pyplot as plt

from sweep import Numerics, Scene, simulate
from sweep.theory import jkr_load

res = simulate(Scene(n=0.8, k=0.1, mu=3.24, a0=3.61, rate=10**2.5), Numerics.preset("fast"))
print(res.status, f"pull-off {res.pull_off:.4f} at a = {res.a_pulloff:.3f}, "
      f"error estimate {res.error_estimate:.1e}")

# %%
# The trajectory holds the unloading curve: time ``t``, indentation ``delta``, load ``P``
# and the contact radius ``a``. Against the radius, the unloading curve leaves the relaxed
# JKR curve: the material stiffens as the crack runs faster, so the contact holds to a far
# larger tension.

tr = res.trajectory
fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(9, 3.6), layout="constrained")
ax1.plot(tr["delta"], tr["P"], color="C0")
ax1.axhline(-res.pull_off, color="C3", ls="--", lw=1, label=f"pull-off {res.pull_off:.3f}")
ax1.set(xlabel="indentation delta [d_ref]", ylabel="load P [pi dg R]",
        title="load against indentation")
ax1.legend(loc="lower right")
ax2.plot(tr["a"], tr["P"], color="C0", label="BEM, unloading")
a = tr["a"][tr["a"] > 0.3]
ax2.plot(a, jkr_load(a), color="0.4", ls=":", lw=1.5, label="JKR (relaxed, elastic)")
ax2.set(xlabel="contact radius a [a_ref]", ylabel="load P [pi dg R]",
        title="load against contact radius")
ax2.legend(loc="upper left")
plt.show()

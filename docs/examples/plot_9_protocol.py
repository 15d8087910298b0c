"""
The test as run: approach, dwell, retract
=========================================

A scene with a protocol (``approach_rate``, ``preload``, ``dwell``) starts at first contact,
approaches to the preload, dwells, and retracts (:mod:`sweep.engine.protocol`, the BEM).
Loaded and unloaded at one rate without a dwell, the pull-off of a standard linear solid
rises and falls again with the rate: at high rates the whole contact is glassy, loaded and
unloaded elastically (the bell of Afferrante and Violano, JMPS 2022). After a long dwell the
contact has relaxed and a fast retraction meets its full viscoelastic resistance: the
pull-off rises monotonically.
"""
import matplotlib.pyplot as plt
import numpy as np

from sweep import Numerics, Scene, simulate

rates = np.logspace(-2, 4, 7)
numerics = Numerics.preset("fast")
runs = {dwell: [simulate(Scene(material="sls", n=0.5, k=0.1, mu=5, rate=r, approach_rate=r,
                               preload=1.0, dwell=dwell, model="bem"), numerics)
                for r in rates]
        for dwell in (0.0, 1e4)}
for dwell, results in runs.items():
    print(f"dwell {dwell:g}: pull-off", " ".join(f"{res.pull_off:.2f}" for res in results))

# %%
# The pull-off against the rate, and three load cycles P(delta) without a dwell: the
# approach dotted, the retraction solid.

fig, (left, right) = plt.subplots(1, 2, figsize=(9, 3.8), layout="constrained")
for dwell, style in ((0.0, "o-"), (1e4, "s--")):
    left.plot(rates, [res.pull_off for res in runs[dwell]], style,
              label=f"dwell {dwell:g} tau0")
left.axhline(1.5, color="0.3", ls=":", lw=1, label="JKR, 1.5")
left.set(xscale="log", xlabel=r"rate $\hat r$ (approach and retraction)",
         ylabel=r"pull-off ($\pi\Delta\gamma R$)", title="SLS, k = 0.1, mu = 5, preload 1")
left.legend(fontsize=8)
for res, colour in zip(runs[0.0][::3], ("C0", "C1", "C2")):
    tr = res.trajectory
    back = tr["phase"] == 2
    right.plot(tr["delta"][~back], tr["P"][~back], ":", color=colour)
    right.plot(tr["delta"][back], tr["P"][back], "-", color=colour,
               label=f"rate {res.scene.rate:g}")
right.set(xlabel=r"indentation $\hat\delta$", ylabel=r"load $\hat P$", title="load cycles")
right.legend(fontsize=8)
plt.show()

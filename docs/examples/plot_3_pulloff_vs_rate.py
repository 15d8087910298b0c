"""
Pull-off against rate, with the Persson-Brener curve
====================================================

The crack-front model (``model="crack"``: a JKR contact whose edge opens with the
Persson-Brener effective surface energy of the material's spectrum) against the paper's
closed-form estimate ``model="pb"`` (1.5 Gamma_PB(vhat), vhat from the paper's v-r fit), for
three MPL exponents. Neither runs the boundary elements, so this takes seconds; the BEM
(``model="bem"``, the default) answers the same scenes with the process zone resolved.
"""
import matplotlib.pyplot as plt
import numpy as np

from sweep import Numerics, Scene, simulate

rates = np.logspace(-1, 6, 15)
numerics = Numerics.preset("fast")
pull_off = {}
for n in [0.4, 0.8, 1.6]:
    for model in ("crack", "pb"):
        pull_off[n, model] = [simulate(Scene(n=n, k=0.1, mu=3.24, a0=3.61, rate=r, model=model),
                                       numerics).pull_off for r in rates]
    print(f"n = {n}: crack {pull_off[n, 'crack'][-1]:.3f}, pb {pull_off[n, 'pb'][-1]:.3f} "
          "at rate 1e6")

# %%
# Both saturate at 1.5/k = 15, the frozen (glassy) limit, and fall to the elastic JKR value
# 1.5 at slow rates; the broader the spectrum (smaller n), the more decades of rate the rise
# takes.

fig, ax = plt.subplots(figsize=(6, 4), layout="constrained")
for i, n in enumerate([0.4, 0.8, 1.6]):
    ax.plot(rates, pull_off[n, "crack"], "o", color=f"C{i}",
            label=f"n = {n:g}, crack-front model")
    ax.plot(rates, pull_off[n, "pb"], "-", color=f"C{i}",
            label=f"n = {n:g}, Persson-Brener 1.5 Gamma(vhat)")
ax.axhline(1.5, color="0.4", ls=":", lw=1.5, label="elastic JKR, 1.5")
ax.set(xscale="log", yscale="log", xlabel="unloading rate r-hat",
       ylabel="pull-off [pi dg R]", title="k = 0.1, mu = 3.24, a0 = 3.61")
ax.legend(fontsize=7, loc="upper left")
plt.show()

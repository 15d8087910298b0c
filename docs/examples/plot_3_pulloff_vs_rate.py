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
fig, ax = plt.subplots(figsize=(6, 4), layout="constrained")
for i, n in enumerate([0.4, 0.8, 1.6]):
    crack = [simulate(Scene(n=n, k=0.1, mu=3.24, a0=3.61, rate=r, model="crack"), numerics)
             for r in rates]
    pb = [simulate(Scene(n=n, k=0.1, mu=3.24, a0=3.61, rate=r, model="pb"), numerics)
          for r in rates]
    ax.plot(rates, [r.pull_off for r in crack], "o", color=f"C{i}",
            label=f"n = {n:g}, crack-front model")
    ax.plot(rates, [r.pull_off for r in pb], "-", color=f"C{i}",
            label=f"n = {n:g}, Persson-Brener 1.5 Gamma(vhat)")
    print(f"n = {n}: crack {crack[-1].pull_off:.3f}, pb {pb[-1].pull_off:.3f} at rate 1e6")
ax.axhline(1.5, color="0.4", ls=":", lw=1.5, label="elastic JKR, 1.5")
ax.set(xscale="log", yscale="log", xlabel="unloading rate r-hat",
       ylabel="pull-off [pi dg R]", title="k = 0.1, mu = 3.24, a0 = 3.61")
ax.legend(fontsize=7, loc="upper left")
plt.show()

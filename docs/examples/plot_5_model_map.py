"""
Which model ``auto`` picks
==========================

``model: auto`` answers every scene with the cheapest model whose measured error against
the BEM meets the numerics' ``pull_off_rtol`` (:doc:`/models`). The choice runs nothing and
costs a fraction of a millisecond: :func:`sweep.engine.models.model_choice` returns the
model and the reason a results file records as ``model_reason``. Left, the choice over the
Tabor parameter and the initial contact radius at the balanced preset (the BEM on its graded
mesh, or on the tip-following mesh for large contacts, or beyond mu = 100 the crack-front
model); right, over the Tabor parameter and the tolerance asked for: a looser tolerance lets the
crack-front model answer from mu of about 2 (the closed-form Persson-Brener estimate's
measured error is above every tolerance shown, so it is never picked here).
"""
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.colors import ListedColormap

from sweep import Numerics, Scene
from sweep.engine.models import model_choice

LABELS = ["PB estimate", "crack-front", "BEM, graded mesh", "BEM, tip-following"]


def code(choice) -> int:
    if choice.model == "bem":
        return 3 if "tip-following" in choice.reason else 2
    return {"pb": 0, "crack": 1}[choice.model]


mus = np.logspace(-1, 2.5, 36)
a0s = np.linspace(0.6, 12, 39)
tols = np.logspace(-3, -0.5, 26)
balanced = Numerics.preset("balanced")
by_a0 = np.array([[code(model_choice(Scene(n=0.8, k=0.1, mu=mu, a0=a0, rate=1e3), balanced))
                   for mu in mus] for a0 in a0s])
by_tol = np.array([[code(model_choice(Scene(n=0.8, k=0.1, mu=mu, a0=3.0, rate=1e3),
                                      Numerics.preset("balanced", pull_off_rtol=tol)))
                    for mu in mus] for tol in tols])

# %%
# Draw both maps with one colour per choice.

cmap = ListedColormap(["C1", "C0", "C3", "C4"])
fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 3.8), layout="constrained")
ax1.pcolormesh(mus, a0s, by_a0, cmap=cmap, vmin=-0.5, vmax=3.5, shading="nearest")
ax1.set(xscale="log", xlabel="Tabor parameter mu", ylabel="initial contact radius a0 [a_ref]",
        title="balanced preset (pull_off_rtol 0.01)")
mesh = ax2.pcolormesh(mus, tols, by_tol, cmap=cmap, vmin=-0.5, vmax=3.5, shading="nearest")
ax2.set(xscale="log", yscale="log", xlabel="Tabor parameter mu",
        ylabel="pull_off_rtol asked for", title="a0 = 3, by tolerance")
bar = fig.colorbar(mesh, ax=[ax1, ax2], ticks=range(len(LABELS)))
bar.ax.set_yticklabels(LABELS)
for i, label in enumerate(LABELS):
    print(f"{label:20s} {(by_a0 == i).sum():4d} of {by_a0.size} (left), "
          f"{(by_tol == i).sum():4d} of {by_tol.size} (right)")
print(model_choice(Scene(n=0.8, k=0.1, mu=50, a0=3.0, rate=1e3)).reason)
plt.show()

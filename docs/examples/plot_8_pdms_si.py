"""
The PDMS case in SI units
=========================

The paper's experiment: a glass lens (R = 5.19 mm) preloaded to 1.5 mN on Sylgard 184 (the
paper's MPL constants) and pulled off at 1 um/s to 1 cm/s. :class:`sweep.campaign.si.SIScene`
takes the SI quantities and :func:`sweep.campaign.si.run_si` returns the result in both
systems. At mu = 103 the case lies beyond the BEM's Tabor range (mu <= 100), so the
crack-front model and the Persson-Brener estimate answer it; ``configs/pdms.yaml`` is the
same as a ``units: si`` sweep (``sweep run configs/pdms.yaml``, then
``sweep info results/pdms.h5 --si``).
"""
import matplotlib.pyplot as plt
import numpy as np

from sweep.campaign.si import SIScene, run_si

pdms = dict(R=5.19e-3, E0=1.458e6, Einf=3.089e9, nu=0.5, n=0.2207, tau0=0.01876,
            dg=0.1523, h0=30.8e-9, preload=1.5e-3)
speeds = np.logspace(-6, -2, 9)                       # 1 um/s .. 1 cm/s
rows = {model: [run_si(SIScene(speed=v, **pdms), model=model) for v in speeds]
        for model in ("crack", "pb")}
first = rows["crack"][0]
print(f"mu = {first['mu']:.0f}, l0 = {1e9 * first['l0_m']:.0f} nm")
for model, results in rows.items():
    print(f"{model:5s} pull-off [mN]:", " ".join(f"{1e3 * r['pull_off_N']:.1f}" for r in results))

# %%
# The relaxed elastic (JKR) pull-off of the same lens, 1.5 pi dg R in SI, is the slow limit.

jkr = 1e3 * first["jkr_pull_off_N"]
fig, ax = plt.subplots(figsize=(6, 4), layout="constrained")
for model, style, label in [("crack", "o-", "crack-front model"),
                            ("pb", "s--", "Persson-Brener estimate")]:
    ax.plot(1e6 * speeds, [1e3 * r["pull_off_N"] for r in rows[model]], style, label=label)
ax.axhline(jkr, color="0.3", ls=":", lw=1.5, label=f"JKR, relaxed: {jkr:.2f} mN")
ax.set(xscale="log", yscale="log", xlabel="unloading speed [um/s]", ylabel="pull-off [mN]",
       title="glass lens on PDMS, 1.5 mN preload")
ax.legend(fontsize=8)
plt.show()

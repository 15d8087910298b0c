"""
Fitting the MPL constants to a DMA master curve
===============================================

``configs/dma/pdms-master.csv`` is a sample master curve shipped with the repository: the
paper's PDMS as an MPL material (E0 = 1.458 MPa, Einf = 3.089 GPa, n = 0.2207,
tau0 = 18.76 ms) with 2 % log-normal noise on both moduli, written by
``python configs/dma/make_sample.py`` (its header says how). The fit should give those
constants back within its standard errors; the same on the command line::

    sweep fit-dma configs/dma/pdms-master.csv --noise 0.02 --plot fig.png
"""
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import sweep
from sweep.analysis.dma import fit_mpl, kramers_kronig_check, read_dma_csv
from sweep.materials import MPLRetardation

root = Path(sweep.__file__).resolve().parents[1]
data = read_dma_csv(root / "configs" / "dma" / "pdms-master.csv")
fit = fit_mpl(data)
truth = {"E0": 1.458e6, "Einf": 3.089e9, "n": 0.2207, "tau0": 0.01876}
for name, true in truth.items():
    value, err = getattr(fit, name), fit.stderr[name]
    print(f"{name:5s} {value:.5g} +- {err:.2g} (truth {true:g}, "
          f"{abs(value - true) / err:.1f} sigma)")
kk = kramers_kronig_check(data, noise=0.02)
print(f"Kramers-Kronig: rms {kk.rms_modulus:.3f} of |E*| against the tolerance "
      f"{kk.threshold:.3f}: {'consistent' if kk.consistent else 'INCONSISTENT'}")

# %%
# The fitted model against the data over the whole range.

w = np.logspace(np.log10(data.omega.min()), np.log10(data.omega.max()), 300)
E = MPLRetardation(E0=fit.E0, Einf=fit.Einf, n=fit.n, tau0=fit.tau0).complex_modulus(w)
fig, ax = plt.subplots(figsize=(6, 4), layout="constrained")
ax.plot(data.omega, data.E_storage, "o", ms=3, color="C0", label="E' (sample data)")
ax.plot(data.omega, data.E_loss, "s", ms=3, color="C1", label="E'' (sample data)")
ax.plot(w, E.real, color="C0", label="E', MPL fit")
ax.plot(w, E.imag, color="C1", label="E'', MPL fit")
ax.set(xscale="log", yscale="log", xlabel="angular frequency omega [rad/s]",
       ylabel="modulus [Pa]", title=f"MPL fit: n = {fit.n:.4f}, tau0 = {fit.tau0:.4g} s")
ax.legend(fontsize=8)
plt.show()

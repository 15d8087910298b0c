"""
Calibrating to pull-off measurements
====================================

The reverse direction: which work of adhesion ``dg`` and relaxation time ``tau0`` explain
a measured pull-off force against unloading speed? Here the "measurements" are made by the
crack-front model itself at a known answer (dg = 0.15 J/m^2, tau0 = 0.02 s) with 5 %
log-normal noise at 7 speeds from 1 nm/s to 1 mm/s, and
:func:`sweep.analysis.calibrate.calibrate` fits them back with 95 % profile-likelihood
intervals. A calibration file (:doc:`/calibration`) says the same in YAML for
``sweep calibrate FILE.yaml``.
"""
import matplotlib.pyplot as plt
import numpy as np

from sweep.analysis.calibrate import calibrate, calibration_from_dict, synthesize

spec = {
    "name": "tiny",
    "fixed": {"R": 0.0103, "E0": 1.0e6, "Einf": 3.0e9, "nu": 0.5, "h0": 3.08e-8,
              "preload": 1.5e-3, "n": 0.22},
    "fit": {"dg": [0.03, 0.5], "tau0": [1.0e-3, 1.0]},
    "model": "crack",
    "numerics": {"preset": "fast"},
    "search": {"points": 8, "starts": 1},
    "profile": {"points": 5},
}
truth = {"dg": 0.15, "tau0": 0.02}
speeds = np.logspace(-9, -3, 7)                      # 1 nm/s .. 1 mm/s
# a calibration needs data to be valid: a placeholder set of three points for the synthesis
placeholder = calibration_from_dict(spec, measurements=([1e-6, 1e-5, 1e-4], [1e-3] * 3, None))
data = synthesize(placeholder, truth, speeds, noise=0.05, seed=1)
cal = calibration_from_dict(spec, measurements=(data["speed_m_s"], data["pull_off_N"], None))
# %%
# The fit: a Sobol search of the box of bounds seeds a bounded least-squares fit, then a
# profile likelihood per parameter gives its 95 % interval (``jobs=1``: in this process).

result = calibrate(cal, jobs=1)
for name, p in result["parameters"].items():
    lo, hi = p["interval"]
    print(f"{name}: {p['estimate']:.4g} in [{lo:.3g}, {hi:.3g}] ({p['status']}; "
          f"truth {truth[name]})")
print(f"{result['scenes_run']} scenes, {result['wall_s']:.1f} s")

# %%
# The fitted curve with the band of the parameter sets on the profiles.

curve = result["curve"]
fig, ax = plt.subplots(figsize=(6, 4), layout="constrained")
ax.fill_between(curve["speed_m_s"], curve["band_lo_N"], curve["band_hi_N"], color="C0",
                alpha=0.25, label="band of the profiles' parameter sets")
ax.plot(curve["speed_m_s"], curve["pull_off_N"], color="C0", label="fit")
ax.plot(data["speed_m_s"], data["pull_off_N"], "o", color="k", label="synthetic data")
ax.set(xscale="log", yscale="log", xlabel="unloading speed [m/s]", ylabel="pull-off [N]",
       title="dg and tau0 from 7 pull-off measurements")
ax.legend(fontsize=8)
plt.show()

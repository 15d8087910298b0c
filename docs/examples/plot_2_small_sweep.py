"""
A small sweep, read with pandas
===============================

A sweep is a YAML file (or a dict of the same shape, :doc:`/configs`): a grid of scene
axes, numerics and an output file. :func:`sweep.run_sweep` runs it (resuming where a file
of the same config stops) and :func:`sweep.load` reads the results as a pandas DataFrame,
one row per scene. The same on the command line::

    sweep run small.yaml -j 2
    sweep info results/small.h5
"""
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt

import sweep

out = Path(tempfile.mkdtemp()) / "small.h5"
config = {
    "name": "small",
    "grid": {"n": [0.4, 1.6], "k": 0.1, "mu": 3.24, "a0": 2.5,
             "rate": {"log10": [0, 3, 4]}},
    "numerics": {"preset": "fast"},
    "output": str(out),
}
sweep.run_sweep(config, jobs=1, progress="none")

# %%
# One row per scene: the scene's axes, the status, the pull-off with its error estimate, the
# crack speed, the model that answered and the numerics (:doc:`/results` lists every column).

df = sweep.load(out)
print(df.sort_values(["n", "rate"])[["n", "rate", "status", "pull_off", "error_estimate"]])

# %%
# Pandas does the rest: here one curve per exponent.

fig, ax = plt.subplots(figsize=(5.5, 3.8), layout="constrained")
for n, rows in df.sort_values("rate").groupby("n"):
    ax.plot(rows["rate"], rows["pull_off"], "o-", label=f"n = {n:g}")
ax.set(xscale="log", xlabel="unloading rate r-hat", ylabel="pull-off [pi dg R]",
       title="k = 0.1, mu = 3.24, a0 = 2.5 (fast preset)")
ax.legend(title="MPL exponent")
plt.show()

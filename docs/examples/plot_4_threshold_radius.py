"""
The threshold radius on a thinned grid
======================================

The paper's first result: the pull-off grows with the initial contact radius ``a0`` until
a threshold ``a0t``, beyond which it saturates. This runs the thinned grid that
``make threshold QUICK=1`` runs (``configs/quick/threshold.yaml``: 2 exponents x 7 radii x
2 rates, fast preset) and finds ``a0t`` per (n, rate) with the paper's rule
(:func:`sweep.analysis.fits.threshold_table`). The full campaign is ``make threshold``
(:doc:`/reproducing`).
"""
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt

import sweep
from sweep.analysis import fits

root = Path(sweep.__file__).resolve().parents[1]
out = Path(tempfile.mkdtemp()) / "threshold.h5"
sweep.run_sweep(root / "configs" / "quick" / "threshold.yaml", out=out, jobs=2,
                progress="none")
# %%
# The threshold per (n, rate): the first a0 whose local slope of the pull-off falls below
# 0.1, from a spline through the points (the paper's rule).

df = sweep.load(out)
table = fits.threshold_table(df)
print(table)

# %%
# The pull-off against a0 per (n, rate), the threshold dotted. The full campaign's collapse
# P_po = A a0t^B is ``sweep fit threshold``.

fig, ax = plt.subplots(figsize=(6, 4), layout="constrained")
for i, ((n, rate), rows) in enumerate(df.groupby(["n", "rate"])):
    ok = rows[rows.status == "ok"].sort_values("a0")
    ax.plot(ok.a0, ok.pull_off, "o-", color=f"C{i}", label=f"n = {n:g}, rate {rate:.3g}")
    hit = table[(table.n == n) & (table.rate == rate)]
    if len(hit) and hit.a0t.notna().all():
        ax.axvline(float(hit.a0t.iloc[0]), color=f"C{i}", ls=":", lw=1.2)
ax.set(xlabel="initial contact radius a0 [a_ref]", ylabel="pull-off [pi dg R]",
       title="threshold radius a0t (dotted) on the thinned grid")
ax.legend(fontsize=8)
plt.show()

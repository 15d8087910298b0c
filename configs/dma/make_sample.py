"""Write configs/dma/pdms-master.csv, the sample DMA master curve `sweep fit-dma` can be tried on.

    python configs/dma/make_sample.py            # (from the repository's root) rewrites it

The data are the complex modulus of a KNOWN material, the paper's PDMS fit as an MPL
retardation model (E0 = 1.458e6 Pa, Einf = 3.089e9 Pa, n = 0.2207, tau0 = 0.01876 s;
``sweep.materials.MPLRetardation``), at 5 angular frequencies a decade from 1e-2 to 1e14 rad/s
(81 rows), each modulus multiplied by exp(N(0, 0.02)) (2 % log-normal noise, numpy's
default_rng(seed=34)). So `sweep fit-dma configs/dma/pdms-master.csv --noise 0.02` should
give back those four constants within its standard errors, and the Kramers-Kronig check
should pass. Columns: omega_rad_s, E_storage_Pa, E_loss_Pa (the master-curve format of
``sweep.analysis.dma``).
"""
from pathlib import Path

import numpy as np

from sweep.materials import MPLRetardation

TRUTH = {"E0": 1.458e6, "Einf": 3.089e9, "n": 0.2207, "tau0": 0.01876}
NOISE = 0.02
SEED = 34


def sample() -> str:
    omega = np.logspace(-2, 14, 81)
    E = MPLRetardation(**TRUTH).complex_modulus(omega)
    rng = np.random.default_rng(SEED)
    storage = E.real * np.exp(rng.normal(0.0, NOISE, omega.size))
    loss = E.imag * np.exp(rng.normal(0.0, NOISE, omega.size))
    rows = [f"{w:.6g},{s:.6g},{l:.6g}" for w, s, l in zip(omega, storage, loss)]
    return "\n".join(["omega_rad_s,E_storage_Pa,E_loss_Pa", *rows]) + "\n"


if __name__ == "__main__":
    out = Path(__file__).with_name("pdms-master.csv")
    out.write_text(sample())
    print(f"wrote {out} ({len(sample().splitlines()) - 1} rows)")

"""Write the Prony-table test data of tests/data/prony/ (issue 36 item 1).

    PYTHONPATH=. python tests/data/prony/make_tables.py     # from the repository's root

The table is the paper's PDMS as an 18-arm generalized Maxwell (Wiechert) model fitted by
``sweep fit-dma`` to DMA data generated from the paper's MPL (retardation) constants
E0 = 1.458e6 Pa, Einf = 3.089e9 Pa, n = 0.2207, tau0 = 0.01876 s (``sweep/paper/pdms.py``):

* ``pdms_mpl_master.csv`` -- the MPL's complex modulus at 5 angular frequencies a decade from
  1e-2 to 1e14 rad/s (81 rows, as configs/dma/make_sample.py, without noise), full precision;
* ``pdms_fit_dma.json`` -- ``sweep fit-dma pdms_mpl_master.csv --maxwell 18 --out
  pdms_fit_dma.json`` (the ``--json`` object; its ``maxwell`` object is the table: E0 [Pa],
  18 moduli [Pa] of which NNLS sets some to 0, times [s]);
* ``pdms_prony.csv`` -- the same table as pyvisco writes its ``df_prony.csv`` (names row
  ``i,tau_i,alpha_i,E_0,E_i``, units row ``-,s,-,MPa,MPa``; E_0 the INSTANTANEOUS modulus
  Einf = E0 + sum E_i, alpha_i = E_i/E_0, E_i = E_0 alpha_i as pyvisco computes it), rows in
  descending tau;
* ``pdms_prony_ansys.mpl`` -- the same table as an ANSYS card (``/UNITS,SI``, ``MP,EX`` = the
  instantaneous modulus, ``TB,PRONY,1,1,18,SHEAR``, ``TBDATA`` with a_i = E_i/Einf and tau_i,
  three constants a line with their start slot, as ANSYS writes them);
* ``pdms_prony_visco_sweep.csv`` -- the same table in this project's CSV (relaxed E0, arms in Pa);
* ``pdms_prony_abaqus.inp`` -- the same table as an Abaqus material (``*ELASTIC,
  MODULI=INSTANTANEOUS`` with E = Einf, ``*VISCOELASTIC, TIME=PRONY`` rows ``g_i, k_i, tau_i``
  with g_i = E_i/Einf and k_i = 0), written from ``pdms_fit_dma.json`` alone by
  ``python tests/data/prony/make_tables.py --abaqus``.

Every number is written with Python's shortest round-trip repr, so the four files hold the
same table to the last bit but for the products and quotients each format's definition
needs (E_i = E_0 alpha_i, the MPa scale).
"""
from __future__ import annotations

import json
import os
import sys
from pathlib import Path

import numpy as np
from click.testing import CliRunner

from sweep.cli import cli
from sweep.materials import MPLRetardation

HERE = Path(__file__).resolve().parent
PDMS = {"E0": 1.458e6, "Einf": 3.089e9, "n": 0.2207, "tau0": 0.01876}
ARMS = 18


def master_curve() -> str:
    omega = np.logspace(-2, 14, 81)
    E = MPLRetardation(**PDMS).complex_modulus(omega)
    rows = [f"{w!r},{e.real!r},{e.imag!r}" for w, e in zip(omega.tolist(), E.tolist())]
    return "\n".join(["omega_rad_s,E_storage_Pa,E_loss_Pa", *rows]) + "\n"


def fit_dma_json(master: Path, out: Path) -> dict:
    """``sweep fit-dma MASTER --maxwell 18 --out OUT`` run in MASTER's folder; OUT's object."""
    cwd = os.getcwd()
    os.chdir(master.parent)
    try:
        res = CliRunner().invoke(cli, ["fit-dma", master.name, "--maxwell", str(ARMS),
                                       "--out", out.name], catch_exceptions=False)
    finally:
        os.chdir(cwd)
    if res.exit_code != 0:
        raise SystemExit(f"sweep fit-dma failed: {res.output}")
    return json.loads(out.read_text())


def pyvisco_csv(E0: float, moduli, times) -> str:
    Einf = E0 + float(np.sum(moduli))
    E_0 = Einf / 1e6                                    # MPa
    order = np.argsort(times)[::-1]
    lines = ["i,tau_i,alpha_i,E_0,E_i", "-,s,-,MPa,MPa"]
    for i, j in enumerate(order, start=1):
        alpha = moduli[j] / Einf
        lines.append(f"{i},{times[j]!r},{alpha!r},{E_0!r},{E_0 * alpha!r}")
    return "\n".join(lines) + "\n"


def ansys_card(E0: float, moduli, times) -> str:
    Einf = E0 + float(np.sum(moduli))
    consts = []
    for e, t in zip(moduli, times):
        consts += [e / Einf, t]
    lines = ["/COM, PDMS as an 18-arm Wiechert model (tests/data/prony/make_tables.py)",
             "/PREP7", "/UNITS,SI", f"MP,EX,1,{Einf!r}", "MP,PRXY,1,0.5",
             f"TB,PRONY,1,1,{len(times)},SHEAR", "TBTEMP,20.0"]
    for s in range(0, len(consts), 3):
        lines.append(f"TBDATA,{s + 1}," + ",".join(repr(c) for c in consts[s:s + 3]))
    return "\n".join(lines) + "\n"


def abaqus_inp(E0: float, moduli, times) -> str:
    Einf = E0 + float(np.sum(moduli))
    lines = ["** PDMS as an 18-arm Wiechert model (tests/data/prony/make_tables.py)",
             "*Material, name=PDMS", "*Density", " 965.,",
             "*Elastic, moduli=INSTANTANEOUS", f" {Einf!r}, 0.499",
             "*Viscoelastic, time=PRONY"]
    lines += [f" {e / Einf!r}, 0., {t!r}" for e, t in zip(moduli, times)]
    return "\n".join(lines) + "\n"


def project_csv(E0: float, moduli, times) -> str:
    lines = ["# visco-sweep prony", "# PDMS, 18-arm Wiechert fit (tests/data/prony/make_tables.py)",
             "# form = wiechert", f"# E0 = {E0!r}", "# modulus_unit = Pa", "# time_unit = s",
             "tau,E"]
    lines += [f"{t!r},{e!r}" for t, e in zip(times, moduli)]
    return "\n".join(lines) + "\n"


def main() -> None:
    if "--abaqus" in sys.argv[1:]:          # the Abaqus deck alone, from the committed fit
        mx = json.loads((HERE / "pdms_fit_dma.json").read_text())["maxwell"]
        (HERE / "pdms_prony_abaqus.inp").write_text(abaqus_inp(
            float(mx["E0"]), [float(x) for x in mx["moduli"]], [float(x) for x in mx["times"]]))
        return
    master = HERE / "pdms_mpl_master.csv"
    master.write_text(master_curve())
    doc = fit_dma_json(master, HERE / "pdms_fit_dma.json")
    mx = doc["maxwell"]
    E0 = float(mx["E0"])
    moduli, times = [float(x) for x in mx["moduli"]], [float(x) for x in mx["times"]]
    (HERE / "pdms_prony.csv").write_text(pyvisco_csv(E0, moduli, times))
    (HERE / "pdms_prony_ansys.mpl").write_text(ansys_card(E0, moduli, times))
    (HERE / "pdms_prony_visco_sweep.csv").write_text(project_csv(E0, moduli, times))
    (HERE / "pdms_prony_abaqus.inp").write_text(abaqus_inp(E0, moduli, times))
    print(f"wrote {HERE}: E0 = {E0:.6g} Pa, Einf = {E0 + sum(moduli):.6g} Pa, "
          f"{sum(m > 0 for m in moduli)} of {len(moduli)} arms non-zero")


if __name__ == "__main__":
    main()

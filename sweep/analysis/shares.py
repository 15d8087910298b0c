"""How much of a scene's pull-off amplification is the bulk, and how much the process zone.

The paper leaves open how much of the measured rate-dependent adhesion comes from the bulk's
viscoelastic dissipation and how much from a rate-dependent process zone at the crack tip.
For one scene with a process zone (``pz_law``), :func:`process_zone_shares` runs three rows
through the front door (:func:`sweep.simulate`, the scene's own model and numerics):

- ``both``: the scene as given (bulk and process zone);
- ``bulk``: the same scene without its process zone;
- ``relaxed``: the relaxed elastic contact (k = 1, no process zone), the pull-off with no
  dissipation at all (1.5 pi dg R in the JKR limit),

and splits the logarithm of the amplification P_both / P_relaxed into the bulk's part
ln(P_bulk / P_relaxed) and the process zone's ln(P_both / P_bulk): the shares add up to 1 by
construction, and a product law Gamma = Gamma_bulk Gamma_pz of an elastic crack is split
exactly where the pull-off scales with Gamma. The split is of the force, the quantity a test
measures; the split of the effective work of adhesion at the crack speed of the pull-off is
another (``sweep.paper.pdms.bulk_and_process_zone``: 37 % of ln dg_eff against 24 % of the
force's at 1e4 um/s on the PDMS), for the force depends on Gamma along the whole path.

Each share carries the rows' error estimates (:func:`process_zone_shares`); where the
amplification itself is not larger than that error the shares are not determined, and the
result says so beside them (a zone's 84 % of an amplification of 1.00005 is no answer).
"""
from __future__ import annotations

import dataclasses
import math

from ..errors import InputError
from ..scene import Numerics, Scene

#: an amplification ln(P_both / P_relaxed) below this many times its own error leaves the
#: shares undetermined (``determined`` False)
DETERMINED_BELOW = 3.0


def process_zone_shares(scene: Scene, numerics: Numerics | None = None, both=None) -> dict:
    """The bulk's and the process zone's shares of a scene's pull-off amplification.

    Parameters
    ----------
    scene : Scene
        A scene with a process zone (``pz_law`` other than "none"), any model, material,
        initial state or test protocol.
    numerics : Numerics, optional
        Numerics of the three rows (default: the balanced preset).
    both : Result, optional
        The scene's own row at ``numerics``, where it has been run already.

    Returns
    -------
    dict
        ``pull_off`` of the rows ``both``, ``bulk``, ``relaxed`` (pi dg R) with their
        ``status``, ``model`` and ``error_estimate`` (relative; NaN where the model gives
        none); ``amplification`` P_both / P_relaxed; ``bulk_share`` and
        ``process_zone_share`` of ln(amplification) (adding up to 1); ``share_error``, the
        shares' error from the rows' estimates, (e_both + e_bulk) / ln(amplification) for the
        zone's, (e_bulk + e_relaxed) / ln(amplification) for the bulk's (the larger of the two);
        ``determined`` (False where ln(amplification) is below :data:`DETERMINED_BELOW`
        times its error e_both + e_relaxed: the shares are given but not determined by the
        rows) and ``note`` saying why; where a row failed, or there is no amplification at
        all, no shares (NaN) and the note (a failed ``both`` row: the other two are not run).
        The ``bulk`` and ``relaxed`` rows run on the model the scene ran on (``both``'s
        ``model``), so that one model's numbers are divided; the BEM answers an elastic,
        quasi-static row with its quasi-static branch (``sweep.engine.models``), so at k = 1
        the hereditary BEM's ``both`` is divided by the branch's rows.

    Raises
    ------
    InputError
        The scene has no process zone.
    """
    if scene.pz_law == "none":
        raise InputError("scene: process_zone_shares needs a scene with a process zone "
                         "(pz_law gent-schultz, pz_v0, pz_xi)")
    from ..engine.models import simulate   # lazy: the engine loads the compiled kernels

    both = simulate(scene, numerics) if both is None else both
    # the other two rows on the model the scene ran on (auto could pick another for each:
    # the crack-front model's relaxed contact is JKR's 1.5, the BEM's 1.546 at mu 3.24)
    model = both.model_used if both.model_used in ("bem", "crack") else scene.model
    plain = dataclasses.replace(scene, pz_law="none", pz_v0=None, pz_xi=None, model=model)
    rows = {"both": both}
    if both.ok:                 # a failed scene has nothing to split: no other rows
        rows.update(bulk=simulate(plain, numerics),
                    relaxed=simulate(dataclasses.replace(plain, material="mpl", k=1.0),
                                     numerics))
    out = {name: {"pull_off": float(r.pull_off), "status": r.status, "model": r.model_used,
                  "error_estimate": float(r.error_estimate), "reason": r.reason}
           for name, r in rows.items()}
    err = {name: abs(float(r.error_estimate)) for name, r in rows.items()}
    out.update(amplification=math.nan, bulk_share=math.nan, process_zone_share=math.nan,
               share_error=math.nan, determined=False)
    failed = [name for name, r in rows.items() if not r.ok]
    if failed:
        out["note"] = (f"no shares: the {', '.join(failed)} row failed "
                       f"({'; '.join(rows[n].reason for n in failed)})")
        return out
    total = math.log(rows["both"].pull_off / rows["relaxed"].pull_off)
    out["amplification"] = math.exp(total)
    if total == 0.0:     # a negligible zone on an elastic bulk: all three rows the same
        out["note"] = "no shares: no amplification to split (the three pull-offs are equal)"
        return out
    bulk = math.log(rows["bulk"].pull_off / rows["relaxed"].pull_off)
    noise = err["both"] + err["relaxed"]
    out.update(bulk_share=bulk / total,
               process_zone_share=1.0 - bulk / total,
               share_error=max(err["both"] + err["bulk"], err["bulk"] + err["relaxed"])
               / abs(total),
               determined=bool(abs(total) > DETERMINED_BELOW * noise))
    out["note"] = "" if out["determined"] else (
        f"shares not determined: the amplification {math.exp(total):.8g} is within "
        f"{DETERMINED_BELOW:g} times the rows' error ({noise:.2g}; a crack-front row's is its "
        f"measured difference from the BEM) of none" if math.isfinite(noise) else
        "shares not determined: a row has no error estimate")
    return out

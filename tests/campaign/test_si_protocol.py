"""The test as run, in SI configs (issue 36 item 2): approach_speed [m/s], preload [N], dwell
[s], dwell_hold, speed [m/s] (the retraction); a config without dwell runs the relaxed start.

Independent values: the dimensionless protocol from the SI keys by the units' definitions
(r-hat = v tau0 / h0, P-hat = P / (pi dg R), t-hat = t / tau0), written out here; a run end
to end with the PDMS 18-arm Prony table in pyvisco's format and `sweep info --si`.
"""
import math
from pathlib import Path

import pytest

from sweep.campaign.si import SIScene, run_si
from sweep.cli import main
from sweep.errors import InputError

PRONY = Path(__file__).resolve().parents[1] / "data" / "prony" / "pdms_prony.csv"
#: a small sphere whose Tabor parameter the BEM resolves (mu 4.2 with the PDMS table)
SPHERE = dict(R=1.0e-4, nu=0.5, dg=0.1523, h0=2.0e-7)
SLS = dict(SPHERE, E0=1.0e6, Einf=1.0e7, n=0.5, tau0=0.01, material="sls")


def test_the_protocol_keys_convert_by_the_units_definitions():
    si = SIScene(**SLS, speed=1e-5, approach_speed=3e-6, preload=2e-4, dwell=60.0,
                 dwell_hold="depth")
    d = si.dimensionless()
    R, dg, h0, tau0 = SLS["R"], SLS["dg"], SLS["h0"], SLS["tau0"]
    assert d["approach_rate"] == pytest.approx(3e-6 * tau0 / h0, rel=1e-12)
    assert d["rate"] == pytest.approx(1e-5 * tau0 / h0, rel=1e-12)
    assert d["preload"] == pytest.approx(2e-4 / (math.pi * dg * R), rel=1e-12)
    assert d["dwell"] == pytest.approx(60.0 / tau0, rel=1e-12)
    assert d["dwell_hold"] == "depth" and d["a0"] is None and d["delta0"] is None
    scene = si.to_scene()
    assert scene.protocol().preload == pytest.approx(d["preload"])
    # without dwell the preload is today's relaxed start at that load
    relaxed = SIScene(**SLS, speed=1e-5, preload=2e-4).to_scene()
    assert relaxed.protocol() is None and relaxed.a0 is not None


@pytest.mark.parametrize("fields, words", [
    (dict(approach_speed=1e-6, preload=1e-4), "dwell: a test protocol needs approach_speed"),
    (dict(dwell=60.0, preload=1e-4), "approach_speed: a test protocol needs"),
    (dict(approach_speed=1e-6, dwell=60.0, a0=1e-5),
     "preload: a test protocol needs"),
    (dict(approach_speed=1e-6, dwell=60.0, preload=1e-4, dwell_hold="time"), "dwell_hold"),
    (dict(preload=1e-4, dwell_hold="depth"), "dwell_hold: 'depth' needs a test protocol")])
def test_bad_protocols_get_one_line(fields, words):
    with pytest.raises(InputError, match=words):
        SIScene(**SLS, speed=1e-5, **fields)


def test_only_the_bem_runs_it():
    si = SIScene(**SLS, speed=1e-5, approach_speed=1e-5, preload=1e-4, dwell=1.0)
    assert run_si(si, "crack")["status"] == "failed"
    out = run_si(si, "bem")
    assert out["status"] == "ok" and out["pull_off_N"] > 0
    # the cycle's work in joules: pi dg R d_ref per unit (sweep.units), with its error
    assert out["hysteresis_energy_J"] == pytest.approx(
        out["hysteresis_energy"] * out["load_ref_N"] * out["d_ref_m"], rel=1e-12)
    assert out["hysteresis_energy_J"] > 0 and 0 < out["hysteresis_error"] < 1


def test_a_prony_table_config_with_a_60_s_dwell_runs_and_info_si_shows_it(tmp_path, capsys):
    cfg = tmp_path / "lab.yaml"
    cfg.write_text(
        "name: lab\nunits: si\n"
        f"grid: {{material: [{{prony: {PRONY}}}], R: 1.0e-4, nu: 0.5, dg: 0.1523, h0: 2.0e-7,\n"
        "       approach_speed: 2.0e-7, preload: 1.0e-4, dwell: 60, speed: [2.0e-7, 2.0e-5],\n"
        "       model: bem}\n"
        f"output: {tmp_path / 'lab.h5'}\n")
    assert main(["run", str(cfg), "-j", "1", "--progress", "none"]) == 0
    capsys.readouterr()
    assert main(["info", str(tmp_path / "lab.h5"), "--si"]) == 0
    lines = capsys.readouterr().out.splitlines()
    rows = [ln.split() for ln in lines[1:]]
    assert len(rows) == 2 and all(r[3] == "ok" for r in rows)
    assert all(r[4].startswith("prony:pdms_prony:") for r in rows)
    pull_off_mN = [float(r[lines[0].split().index("pull_off[mN]")]) for r in rows]
    assert pull_off_mN[1] > pull_off_mN[0] > 0          # faster retraction, larger pull-off


def test_a_dimensionless_scene_with_a_process_zone_and_a_protocol_goes_to_si_and_back():
    """SIScene.from_dimensionless and SIScene.dimensionless are inverse: n, k, mu, rate, the
    process zone's pz_v0 and the protocol's approach_rate, preload and dwell come back."""
    dimless = dict(n=0.5, k=0.2, mu=5.0, rate=3.0, pz_law="gent-schultz", pz_v0=0.7,
                   pz_xi=0.45, approach_rate=0.2, preload=2.5, dwell=40.0, dwell_hold="depth")
    si = SIScene.from_dimensionless(**dimless, R=1e-4, E0=1e6, nu=0.5, tau0=0.01, dg=0.05)
    back = si.dimensionless()
    for key, value in dimless.items():
        if isinstance(value, str):
            assert back[key] == value, key
        else:
            assert back[key] == pytest.approx(value, rel=1e-12), key
    assert back["a0"] is None and back["delta0"] is None
    with pytest.raises(InputError, match="a protocol gives all three"):
        SIScene.from_dimensionless(n=0.5, k=0.2, mu=5.0, rate=3.0, R=1e-4, E0=1e6, nu=0.5,
                                   tau0=0.01, dg=0.05, a0=2.0, dwell=1.0)

"""The bulk's and the process zone's shares of a pull-off amplification
(:mod:`sweep.analysis.shares`): exact limits, a second model, and shares that are not
determined said to be so."""
import math

import pytest

from sweep import Scene
from sweep.analysis.shares import process_zone_shares
from sweep.cli import main
from sweep.errors import InputError

ZONE = dict(pz_law="gent-schultz", pz_v0=1.0, pz_xi=0.5)


def test_an_elastic_bulk_leaves_the_whole_amplification_to_the_process_zone():
    """k = 1: the bulk row is the relaxed row itself (the elastic branch), so the bulk's
    share is 0 exactly and the zone's 1, on the BEM (auto) and on the crack-front model."""
    for model in ("auto", "crack"):
        s = process_zone_shares(Scene(n=0.5, k=1.0, mu=5.0, a0=1.5, rate=10.0, model=model,
                                      **ZONE))
        assert s["bulk"]["pull_off"] == s["relaxed"]["pull_off"]
        assert s["bulk_share"] == 0.0 and s["process_zone_share"] == 1.0
        assert s["amplification"] > 1.5                     # the zone's, (v/v0)^xi ~ 0.7


def test_the_bem_and_the_crack_front_model_split_a_viscoelastic_scene_alike():
    """Two models of different pull-offs (3 % apart here) divide the amplification alike:
    the crack-front model's shares lie within the BEM's share error of the BEM's (a second
    method; the crack-front row's own estimates, its difference from the BEM at this mu,
    leave its shares undetermined, and the result says so)."""
    scene = dict(n=0.5, k=0.1, mu=5.0, a0=1.5, rate=10.0, **ZONE)
    bem = process_zone_shares(Scene(model="auto", **scene))
    crack = process_zone_shares(Scene(model="crack", **scene))
    assert bem["both"]["model"] == bem["bulk"]["model"] == "bem" and bem["determined"]
    assert 0.1 < bem["process_zone_share"] < 0.9
    assert bem["share_error"] < 0.02
    assert crack["process_zone_share"] == pytest.approx(bem["process_zone_share"],
                                                        abs=bem["share_error"])
    assert not crack["determined"] and "not determined" in crack["note"]
    assert bem["bulk_share"] + bem["process_zone_share"] == pytest.approx(1.0, abs=1e-12)


def test_a_negligible_amplification_is_not_split():
    """An amplification of 1 + 4e-7 (a very slow unloading): the shares are given but not
    determined, and the note says why (a zone's 84 % of an amplification of 1.00005 had been
    printed as an answer)."""
    s = process_zone_shares(Scene(n=0.5, k=0.1, mu=50.0, a0=3.0, rate=1e-8, model="crack",
                                  pz_law="gent-schultz", pz_v0=1e3, pz_xi=0.5))
    assert s["amplification"] - 1.0 < 1e-5
    assert not s["determined"] and s["share_error"] > 1.0
    assert "within 3 times" in s["note"]


def test_a_failed_row_gives_no_shares_and_a_scene_without_a_zone_is_refused(capsys):
    with pytest.raises(InputError, match="needs a scene with a process zone"):
        process_zone_shares(Scene(n=0.5, k=0.1, mu=5.0, a0=1.5, rate=10.0))
    from sweep import Numerics

    s = process_zone_shares(Scene(n=0.5, k=0.1, mu=5.0, a0=1.5, rate=10.0, model="bem",
                                  **ZONE), Numerics.preset("fast", max_steps=20))
    assert s["both"]["status"] == "failed" and s["note"].startswith("no shares: the both")
    assert math.isnan(s["bulk_share"]) and not s["determined"] and "bulk" not in s
    argv = ["scene", "--n", "0.5", "--k", "0.1", "--mu", "5", "--a0", "1.5", "--rate", "10"]
    assert main(argv + ["--shares"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("error: --shares:") and "\n" not in err
    assert main(argv + ["--pz-law", "gent-schultz", "--pz-v0", "1", "--pz-xi", "0.5",
                        "--model", "crack", "--shares"]) == 0
    line = [ln for ln in capsys.readouterr().out.splitlines() if ln.startswith("shares")]
    assert len(line) == 1 and "process zone 0.27" in line[0] and "not determined" in line[0]


def test_no_amplification_is_no_split(capsys):
    """A negligible zone on an elastic bulk: the three rows are one pull-off, and the split
    had raised ZeroDivisionError (the CLI a traceback)."""
    kw = dict(n=0.5, k=1.0, mu=5.0, a0=1.5, rate=10.0, pz_law="gent-schultz", pz_v0=1e20,
              pz_xi=0.5)
    for model in ("auto", "crack"):
        s = process_zone_shares(Scene(model=model, **kw))
        assert s["amplification"] == 1.0 and math.isnan(s["process_zone_share"])
        assert s["note"].startswith("no shares: no amplification")
    argv = ["scene", "--n", "0.5", "--k", "1", "--mu", "5", "--a0", "1.5", "--rate", "10",
            "--pz-law", "gent-schultz", "--pz-v0", "1e20", "--pz-xi", "0.5", "--model", "auto",
            "--shares"]
    assert main(argv) == 0
    assert "shares     none: no shares: no amplification" in capsys.readouterr().out

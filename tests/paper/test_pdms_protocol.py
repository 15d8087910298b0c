"""The paper's PDMS experiment as run against the relaxed start (sweep/paper/pdms_protocol.py,
`make pdms-protocol`, results/pdms/protocol.json).

Independent values: the slow limit (at 1 um/s the retraction is slow against the bulk's
creep left after the dwell, and both starts give the quasi-static pull-off of the same
preload: the ratio is 1 within the two rows' error estimates), and the committed file is what
main computes (one point recomputed at the engine check's 1e-5).
"""
import json
from pathlib import Path

import pytest

from sweep.paper import pdms_protocol
from sweep.paper.pdms import load_protocol as load
from sweep.paper.pdms import protocol_lines
from sweep.paper.pdms_protocol import protocol_point

COMMITTED = Path(__file__).resolve().parents[2] / "results" / "pdms" / "protocol.json"


@pytest.fixture(scope="module")
def committed():
    data = load(COMMITTED)
    assert data is not None, f"{COMMITTED} missing or stale: make pdms-protocol"
    return data


def test_every_point_ran_and_the_slow_limit_forgets_the_history(committed):
    assert {p["mu"] for p in committed["points"]} == set(pdms_protocol.MUS)
    for p in committed["points"]:
        assert p["relaxed"]["status"] == "ok" and p["protocol"]["status"] == "ok", p
        # the dwell left the contact smaller than the relaxed one at the same load (the bulk
        # has not crept all the way), never larger
        assert p["protocol"]["a0_hat"] < p["relaxed"]["a0_hat"]
    slow = [p for p in committed["points"] if p["speed_um_s"] == min(pdms_protocol.SPEEDS_UM_S)]
    for p in slow:
        assert abs(p["ratio"] - 1.0) <= p["combined_error"], p
    # at the same contact radius a dwell that has crept nearly all the way leaves a pull-off
    # the relaxed start's within the two rows' error estimates at every speed
    for p in committed["points"]:
        assert abs(p["ratio_same_radius"] - 1.0) <= p["combined_error_same_radius"], p


def test_the_committed_curve_is_what_main_computes(committed):
    mu, speed = 5.0, 1.0e4
    row = next(p for p in committed["points"] if p["mu"] == mu and p["speed_um_s"] == speed)
    now = protocol_point(speed, mu)
    # the committed results' engine check tolerance (sweep.paper.engine_check: 1e-5)
    for start in ("relaxed", "protocol", "relaxed_same_radius"):
        assert now[start]["pull_off_hat"] == pytest.approx(row[start]["pull_off_hat"], rel=1e-5)


def test_a_stale_file_is_ignored_with_a_word(tmp_path, capsys, committed):
    stale = dict(committed, preset="fast")
    path = tmp_path / "protocol.json"
    path.write_text(json.dumps(stale))
    assert load(path) is None
    assert "make pdms-protocol" in capsys.readouterr().out
    assert json.loads(path.read_text()) == stale          # left as it was


def test_the_report_section_has_a_row_per_speed(committed):
    lines = protocol_lines(committed, {v: 1.0 for v in pdms_protocol.SPEEDS_UM_S})
    rows = [line for line in lines if line.startswith("| ") and line[2].isdigit()]
    assert len(rows) == len(pdms_protocol.SPEEDS_UM_S)
    assert any("The bulk's history changes the pull-off by at most" in line for line in lines)


@pytest.mark.parametrize("writer, now, resumed", [
    ("a" * 40, "a" * 40, True),                    # the same clean commit resumes
    ("a" * 40, "b" * 40, False),                   # another engine computes it again
    ("a" * 40 + "-dirty", "a" * 40 + "-dirty", False),   # a dirty tree pins no code
    ("unknown", "unknown", False)])
def test_a_curve_is_resumed_only_by_the_clean_commit_that_made_it(
        tmp_path, monkeypatch, committed, writer, now, resumed):
    point = dict(committed["points"][0])
    calls = []

    def computed(speed_um, mu, **kwargs):
        calls.append((mu, speed_um))
        return dict(point, mu=float(mu), speed_um_s=float(speed_um))

    path = tmp_path / "protocol.json"
    path.write_text(json.dumps(dict(committed, git_commit=writer,
                                    points=[dict(point, mu=5.0, speed_um_s=1.0)],
                                    approach_check=committed["approach_check"])))
    monkeypatch.setattr(pdms_protocol, "provenance", lambda: {"git_commit": now})
    monkeypatch.setattr(pdms_protocol, "protocol_point", computed)
    data = pdms_protocol.protocol_curve(path, mus=(5.0,), speeds=(1.0,), log=lambda s: None)
    assert calls == ([] if resumed else [(5.0, 1.0), (5.0, 1.0e4)])
    assert data["git_commit"] == now

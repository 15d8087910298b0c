"""The agreement report (`make agreement`): merging the separately measured high-mu rows and
the summary table, on the committed measurements (no BEM run here)."""
import json
from pathlib import Path

from sweep.bench.agreement import main, merged, summary

DIR = Path(__file__).resolve().parents[2] / "results" / "agreement"


def test_high_mu_rows_merge_into_the_mu_scan():
    res = json.loads((DIR / "agreement.json").read_text())
    high = json.loads((DIR / "agreement_mu15.json").read_text())
    full = merged(res, [DIR / "agreement_mu15.json"])
    mus = [r["mu"] for r in full["mu_scan"]]
    assert mus == sorted(mus) and max(mus) == max(r["mu"] for r in high["mu_scan"])
    assert len(full["mu_scan"]) == len(res["mu_scan"]) + len(high["mu_scan"])
    assert full["sources"] == ["agreement_mu15.json"]


def test_summary_ranges_are_those_of_the_rows():
    res = merged(json.loads((DIR / "agreement.json").read_text()))
    text = summary(res)
    rate = max(r["rate"] for r in res["a0_scan"])
    rows = [r for r in res["a0_scan"] if r["rate"] == rate and r["a0"] >= 3]
    v = sorted(100 * r["crack_vs_bem"] for r in rows)
    assert f"| {v[0]:+.1f} .. {v[-1]:+.1f} % |" in text
    for r in res["mu_scan"]:
        assert f"mu = {r['mu']:g}, a0 = {r['a0']:g}" in text


def test_table_only_writes_the_merged_markdown(tmp_path):
    for name in ("agreement.json", "agreement_mu15.json"):
        (tmp_path / name).write_text((DIR / name).read_text())
    assert main(["--out", str(tmp_path / "agreement.json"), "--table-only"]) == 0
    md = (tmp_path / "agreement.md").read_text()
    assert "## Summary" in md and "| mu = 15, a0 = 3" in md
    assert "agreement_mu15.json" in md


def test_table_only_without_results_is_one_line_exit_2(tmp_path, capsys):
    assert main(["--out", str(tmp_path / "none.json"), "--table-only"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--out: no such file" in err

"""Sweep configs: format, ranges, defaults, validation (every problem at once), shipped files."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from tests import reference
from sweep.campaign.config import AXIS_DEFAULTS, config_from_dict, load_config, parse_config
from sweep.errors import InputError
from sweep.scene import Numerics, Scene, scene_id

ROOT = Path(__file__).resolve().parents[2]
CONFIGS = ROOT / "configs"


def base(**over):
    d = {"name": "t", "grid": {"n": [0.4, 1.6], "rate": [1, 100], "a0": 2.0},
         "numerics": {"preset": "fast"}}
    d.update(over)
    return d


def values(cfg, axis):
    return sorted({getattr(s, axis) for s in cfg.scenes()}, key=lambda v: (v is None, v))


# ----------------------------------------------------------------------------- format
def test_cartesian_product_and_scene_ids():
    cfg = config_from_dict(base())
    tasks = cfg.tasks()
    assert len(tasks) == 4
    assert {(s.n, s.rate) for _, s in tasks} == {(0.4, 1.0), (0.4, 100.0), (1.6, 1.0),
                                                 (1.6, 100.0)}
    for sid, s in tasks:
        assert sid == scene_id(s, Numerics.preset("fast"))
        assert s.a0 == 2.0 and s.delta0 is None


def test_defaults_documented_values():
    cfg = config_from_dict({"name": "d", "grid": {"n": 0.8, "rate": 10, "a0": 3}})
    (s,) = cfg.scenes()
    assert s.k == 0.1 and s.mu == 3.24 and s.material == "mpl" and s.stop == "pulloff"
    assert AXIS_DEFAULTS["k"] == 0.1 and AXIS_DEFAULTS["mu"] == 3.24
    assert cfg.numerics == Numerics.preset("balanced")
    assert cfg.trajectories is False
    assert cfg.output == "results/d.h5"


def test_ranges_log10_and_linspace():
    cfg = config_from_dict(base(grid={"n": 0.8, "rate": {"log10": [0, 6, 13]},
                                      "a0": {"linspace": [1, 8, 15]}}))
    rates = values(cfg, "rate")
    assert len(rates) == 13
    np.testing.assert_allclose(rates, np.logspace(0, 6, 13))
    assert any(math.isclose(r, 10 ** 0.5) for r in rates)
    np.testing.assert_allclose(values(cfg, "a0"), np.arange(1.0, 8.01, 0.5))


def test_numeric_strings_and_scalars_accepted():
    # YAML 1.1 reads 1e6 as a string; it must still be a number here
    cfg = parse_config("name: s\ngrid: {n: 0.8, rate: [1e6, 1.0e2], a0: 2}\n")
    assert values(cfg, "rate") == [100.0, 1e6]


def test_delta0_axis_and_material_stop_axes():
    cfg = config_from_dict(base(grid={"n": 0.8, "rate": 1, "delta0": [0.5, 1.0],
                                      "material": ["mpl", "sls"], "stop": "separation"}))
    assert len(cfg.tasks()) == 4
    assert {s.material for s in cfg.scenes()} == {"mpl", "sls"}
    assert all(s.a0 is None and s.stop == "separation" for s in cfg.scenes())


def test_grid_list_is_union_deduplicated():
    g1 = {"n": [0.6, 0.8], "rate": 316.227766, "a0": 3.61}
    g2 = {"n": 0.8, "rate": [100, 316.227766], "a0": 3.61}
    cfg = config_from_dict(base(grid=[g1, g2]))
    ids = [sid for sid, _ in cfg.tasks()]
    assert len(ids) == len(set(ids)) == 3


def test_numerics_preset_with_overrides():
    cfg = config_from_dict(base(numerics={"preset": "fast", "nodes": 120}))
    assert cfg.numerics == Numerics.preset("fast", nodes=120)
    cfg = config_from_dict(base(numerics={"nodes": 80, "step": 0.2}))
    assert cfg.numerics.nodes == 80 and cfg.numerics.step == 0.2


def test_config_hash_tracks_results_not_formatting():
    a = parse_config("name: a\ngrid: {n: [0.4, 1.6], rate: 1, a0: 2}\n")
    b = parse_config("# a comment\nname: other_name\ngrid:\n  n: [0.4, 1.6]\n  rate: 1.0\n"
                     "  a0: 2\n  k: 0.1\n")
    assert a.config_hash == b.config_hash
    c = parse_config("name: a\ngrid: {n: [0.4, 1.6], rate: 2, a0: 2}\n")
    d = parse_config("name: a\ngrid: {n: [0.4, 1.6], rate: 1, a0: 2}\nnumerics: {preset: fast}\n")
    e = parse_config("name: a\ngrid: {n: [0.4, 1.6], rate: 1, a0: 2}\n"
                     "store: {trajectories: true}\n")
    assert len({a.config_hash, c.config_hash, d.config_hash, e.config_hash}) == 4


def test_output_relative_to_cwd(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    cfg = config_from_dict(base(output="sub/x.h5"))
    assert cfg.output_path() == tmp_path / "sub" / "x.h5"
    assert cfg.output_path("/abs/y.h5") == Path("/abs/y.h5")


# ----------------------------------------------------------------------------- validation
def msg(**over) -> str:
    with pytest.raises(InputError) as info:
        config_from_dict(base(**over))
    text = str(info.value)
    assert "\n" not in text
    return text


def test_every_problem_reported_at_once():
    text = msg(grid={"n": [-1, "abc"], "rate": {"log10": [0, 2]}, "foo": 1, "a0": 0.01},
               numerics={"preset": "quick", "nodes": 3, "bar": 1},
               store={"trajectories": "yes", "x": 1}, zz=1, name="bad name")
    for needle in ["zz: unknown key", "name:", "grid.foo: unknown axis", "grid.n[0]",
                   "grid.n[1] must be a number", "grid.rate.log10", "grid.a0 must be in",
                   "numerics.preset", "numerics.nodes", "numerics: unknown key(s) bar",
                   "store.trajectories", "store.x: unknown key"]:
        assert needle in text, (needle, text)
    assert text.startswith("<dict>: 12 problems: ")


@pytest.mark.parametrize("over, needle", [
    ({"grid": {"n": 6, "rate": 1, "a0": 2}}, "grid.n must be in (0, 5] (got 6)"),
    ({"grid": {"n": 0.8, "rate": 0, "a0": 2}}, "grid.rate must be in (0, 1e+12]"),
    ({"grid": {"n": 0.8, "rate": 1, "a0": 2, "mu": 0.001}}, "grid.mu must be in [0.01, 1e+06]"),
    ({"grid": {"n": 0.8, "rate": 1, "a0": 2, "delta0": 1}}, "exactly one of the axes a0"),
    ({"grid": {"n": 0.8, "rate": 1}}, "exactly one of the axes a0"),
    ({"grid": {"rate": 1, "a0": 2}}, "grid.n: required axis is missing"),
    ({"grid": {"n": 0.8, "rate": [], "a0": 2}}, "grid.rate: must not be an empty list"),
    ({"grid": {"n": 0.8, "rate": [True], "a0": 2}}, "grid.rate[0] must be a number"),
    ({"grid": {"n": 0.8, "rate": {"log10": [0, 2, 2.5]}, "a0": 2}}, "(num) must be an integer"),
    ({"grid": {"n": 0.8, "rate": {"geomspace": [1, 2, 3]}, "a0": 2}}, "a range must be"),
    ({"grid": {"n": 0.8, "rate": 1, "a0": 2, "material": "elastic"}},
     "grid.material must be mpl, sls or a Prony table, given as {prony: path} or inline "
     "{tau: [...], E: [...], E0: ...} (got 'elastic')"),
    ({"units": "si", "grid": {"R": 1e-4, "E0": 1e6, "Einf": 1e7, "nu": 0.5, "n": 0.8,
                              "tau0": 0.1, "dg": 0.05, "h0": 2e-7, "preload": 1e-5,
                              "speed": 1e-6, "material": ["mpl", "foo"]}},
     "grid.material[1] must be mpl, sls or a Prony table, given as {prony: path} or inline"),
    ({"grid": [{"n": 0.8, "rate": 1, "a0": 2}, {"n": 9, "rate": 1, "a0": 2}]}, "grid[1].n"),
    ({"grid": "n=1"}, "grid: must be a mapping of axes"),
    ({"grid": []}, "grid: must not be an empty list"),
    ({"numerics": "fast"}, "numerics: must be a mapping"),
    ({"numerics": {"nodes": 10}}, "numerics.nodes must be an integer in [20, 5000]"),
    ({"store": {"trajectories": 1}}, "store.trajectories: must be true or false"),
    ({"output": 3}, "output: must be a file path string"),
    ({"output": "results/"}, "output: must name a file"),
    ({"name": None}, "name: required key is missing"),
    ({"grid": {"n": 0.8, "rate": {"linspace": [1, 2, 10000]}, "a0": {"linspace": [1, 2, 100]},
               "k": {"linspace": [0.1, 0.2, 300]}}}, "more than the maximum"),
])
def test_bad_values_name_key_and_allowed(over, needle):
    text = msg(**over)
    assert needle in text, text


def test_integer_fields_take_numeric_strings_and_whole_floats():
    """docs/configs.md: numeric strings such as "1e6" wherever a number is expected. YAML 1.1
    reads `1e6` as the string '1e6'; integer fields refused it ("numerics.max_steps must be an
    integer (got '1e6')"). An exact integer as a string or float is that integer, and the
    scene ids (which hash the numerics) are those of the plain integer."""
    text = ("name: t\ngrid: {{n: 0.8, a0: 2, rate: {{log10: [0, 2, {num}]}}}}\n"
            "numerics: {{preset: fast, max_steps: {steps}, nodes: {nodes}}}\n")
    plain = parse_config(text.format(num=3, steps=1000000, nodes=200))
    assert plain.tasks()[0][1].rate == 1.0 and len(plain.tasks()) == 3
    for num, steps, nodes in (('"3"', "1e6", "2e2"), ("3.0", "1.0e+6", '"200"'),
                              ("3", '"1000000"', "200.0")):
        cfg = parse_config(text.format(num=num, steps=steps, nodes=nodes))
        assert [sid for sid, _ in cfg.tasks()] == [sid for sid, _ in plain.tasks()]
        assert cfg.config_hash == plain.config_hash
        assert cfg.numerics.max_steps == 1000000 and type(cfg.numerics.max_steps) is int
        assert cfg.numerics.nodes == 200 and type(cfg.numerics.nodes) is int


@pytest.mark.parametrize("over, needle", [
    ({"numerics": {"preset": "fast", "max_steps": "1.5e3"}}, None),
    ({"numerics": {"preset": "fast", "max_steps": 1000.5}},
     "numerics.max_steps must be an integer (got 1000.5)"),
    ({"numerics": {"preset": "fast", "nodes": "1.5"}},
     "numerics.nodes must be an integer (got '1.5')"),
    ({"numerics": {"preset": "fast", "nodes": "two"}},
     "numerics.nodes must be an integer (got 'two')"),
    ({"numerics": {"preset": "fast", "nodes": True}},
     "numerics.nodes must be an integer (got True)"),
    ({"grid": {"n": 0.8, "rate": {"log10": [0, 2, "2.5"]}, "a0": 2}},
     "grid.rate.log10[2] (num) must be an integer (got '2.5')"),
])
def test_integer_fields_refuse_fractions(over, needle):
    if needle is None:              # "1.5e3" is 1500, an integer: accepted
        assert config_from_dict(base(**over)).numerics.max_steps == 1500
        return
    text = msg(**over)
    assert needle in text, text


def test_missing_grid_and_non_mapping():
    with pytest.raises(InputError, match="grid: required key is missing"):
        config_from_dict({"name": "x"})
    with pytest.raises(InputError, match="config must be a mapping"):
        parse_config("- a\n- b\n")
    with pytest.raises(InputError, match="config is empty"):
        parse_config("")


def test_malformed_yaml_one_line_with_position():
    with pytest.raises(InputError) as info:
        parse_config("name: x\ngrid: {n: [0.4, 1.6\n", source="bad.yaml")
    text = str(info.value)
    assert text.startswith("bad.yaml: not valid YAML at line") and "\n" not in text


def test_duplicate_keys_rejected():
    with pytest.raises(InputError, match="duplicate key 'n'"):
        parse_config("name: x\ngrid:\n  n: 0.4\n  n: 0.8\n  rate: 1\n  a0: 2\n")


def test_safe_loader_never_builds_objects_or_runs_code(tmp_path):
    marker = tmp_path / "pwned"
    evil = (f"name: !!python/object/apply:os.system ['touch {marker}']\n"
            "grid: {n: 0.8, rate: 1, a0: 2}\n")
    with pytest.raises(InputError, match="not valid YAML"):
        parse_config(evil)
    assert not marker.exists()
    with pytest.raises(InputError, match="not valid YAML"):
        parse_config("name: !!python/name:os.system\ngrid: {n: 0.8, rate: 1, a0: 2}\n")


def test_missing_file(tmp_path):
    with pytest.raises(InputError, match="no such file"):
        load_config(tmp_path / "nope.yaml")
    with pytest.raises(InputError, match="is a directory"):
        load_config(tmp_path)


# ----------------------------------------------------------------------------- shipped
def test_shipped_configs_are_valid():
    names = {p.stem for p in CONFIGS.glob("*.yaml")}
    assert {"smoke", "threshold", "v_vs_r", "fig3"} <= names
    for p in CONFIGS.glob("*.yaml"):
        cfg = load_config(p)
        assert cfg.name == p.stem
        assert cfg.output == f"results/{p.stem}.h5"
        assert len(cfg.tasks()) >= 1


def test_smoke_config_is_small_and_fast():
    cfg = load_config(CONFIGS / "smoke.yaml")
    assert 2 <= len(cfg.tasks()) <= 8
    assert cfg.numerics == Numerics.preset("fast")


def test_threshold_campaign():
    cfg = load_config(CONFIGS / "threshold.yaml")
    assert values(cfg, "n") == [0.4, 0.6, 0.8, 1.6]
    assert values(cfg, "k") == [0.1]
    a0 = values(cfg, "a0")
    assert a0[0] <= 1.5 and a0[-1] >= 7.0 and len(a0) >= 10
    rates = values(cfg, "rate")
    assert math.isclose(rates[0], 1.0) and math.isclose(rates[-1], 1e6)
    assert any(math.isclose(r, 10 ** 0.5) for r in rates)  # the paper's reference rate
    assert cfg.numerics == Numerics.preset("fast", max_nodes=1000)  # fits a0 = 8 (535 nodes)
    # a0 covers the collapse P_po = 0.3 a0t^2.7 up to the saturation 1.5/k
    assert a0[-1] > (1.5 / 0.1 / 0.3) ** (1 / 2.7)


def test_v_vs_r_campaign():
    cfg = load_config(CONFIGS / "v_vs_r.yaml")
    mpl = sorted({(s.n, s.k) for s in cfg.scenes() if s.material == "mpl"})
    assert sorted({n for n, _ in mpl}) == [0.4, 0.6, 0.8, 1.6]
    assert sorted({k for _, k in mpl}) == [0.01, 0.05, 0.1]
    assert {(s.material, s.k) for s in cfg.scenes() if s.material != "mpl"} == {("sls", 0.1)}
    rates = values(cfg, "rate")
    assert np.log10(rates[-1] / rates[0]) >= 5
    for s in cfg.scenes():  # above the threshold radius of its k
        assert s.a0 >= (1.5 / s.k / 0.3) ** (1 / 2.7)


def test_fig3_matches_paper_panels():
    cfg = load_config(CONFIGS / "fig3.yaml")
    assert cfg.trajectories is True
    fig3 = reference.paper_values()["fig3_trajectories"]
    want = set()
    for panel in ("a", "b", "c"):
        p = fig3[panel]
        axes = {k: (v if isinstance(v, list) else [v]) for k, v in p.items()}
        for n in axes["n"]:
            for a0 in axes["a0"]:
                for rate in axes["rate"]:
                    want.add((float(n), float(a0), round(float(rate), 3)))  # YAML: 1.0e2 is a str
    got = {(s.n, s.a0, round(s.rate, 3)) for s in cfg.scenes()}
    assert got == want
    assert len(cfg.tasks()) == len(want) == 8


def test_to_dict_round_trip():
    cfg = load_config(CONFIGS / "threshold.yaml")
    again = config_from_dict(cfg.to_dict())
    assert again.config_hash == cfg.config_hash
    assert isinstance(Scene.from_dict(cfg.scenes()[0].to_dict()), Scene)


# ----------------------------------------------------------------------------- units: si
PDMS_SI = {"R": 5.19e-3, "E0": 1.458e6, "Einf": 3.089e9, "nu": 0.5, "n": 0.2207,
           "tau0": 0.01876, "dg": 0.1523, "h0": 30.8e-9, "preload": 1.5e-3}


def si_base(**over):
    grid = {"model": "pb", **PDMS_SI, "speed": [1e-6, 1e-4]}
    grid.update(over)
    return {"name": "si", "units": "si", "grid": {k: v for k, v in grid.items() if v is not None}}


def test_si_grid_becomes_the_dimensionless_scenes():
    """Closed forms, computed here: E0* = E0/(1 - nu^2), mu = (R dg^2/(E0*^2 h0^3))^(1/3),
    rate = speed tau0/h0, k = E0/Einf, a0 the relaxed JKR radius at the preload."""
    from sweep.theory import jkr_load

    cfg = config_from_dict(si_base())
    assert cfg.units == "si"
    tasks = cfg.tasks()
    assert len(tasks) == 2
    e0s = PDMS_SI["E0"] / (1 - PDMS_SI["nu"] ** 2)
    mu = (PDMS_SI["R"] * PDMS_SI["dg"] ** 2 / (e0s**2 * PDMS_SI["h0"] ** 3)) ** (1 / 3)
    for (sid, s), speed in zip(tasks, (1e-6, 1e-4)):
        assert s.model == "pb" and s.material == "mpl" and s.n == PDMS_SI["n"]
        assert s.mu == pytest.approx(mu, rel=1e-12)
        assert s.k == pytest.approx(PDMS_SI["E0"] / PDMS_SI["Einf"], rel=1e-12)
        assert s.rate == pytest.approx(speed * PDMS_SI["tau0"] / PDMS_SI["h0"], rel=1e-12)
        load_hat = -PDMS_SI["preload"] / (math.pi * PDMS_SI["dg"] * PDMS_SI["R"])
        assert float(jkr_load(s.a0)) == pytest.approx(-load_hat, rel=1e-9)
        assert sid == scene_id(s, Numerics.preset("balanced"))
    si = dict(cfg.si_tasks())
    assert [si[sid].speed for sid, _ in tasks] == [1e-6, 1e-4]
    # the same scenes given in the dimensionless axes have the same ids (no new id form)
    s0 = tasks[0][1]
    dim = config_from_dict({"name": "d", "grid": {"model": "pb", "n": s0.n, "k": s0.k,
                                                   "mu": s0.mu, "a0": s0.a0, "rate": s0.rate}})
    assert dim.tasks()[0][0] == tasks[0][0]


def test_si_config_round_trips_through_to_dict_and_yaml():
    cfg = config_from_dict(si_base(speed={"log10": [-6, -4, 3]}))
    again = config_from_dict(cfg.to_dict())
    assert again.units == "si" and again.config_hash == cfg.config_hash
    assert parse_config(cfg.text).config_hash == cfg.config_hash


@pytest.mark.parametrize("over, needle", [
    ({"R": -1}, "grid.R must be > 0 (got -1)"),
    ({"nu": 0.6}, "grid.nu must be in [0, 0.5] (got 0.6)"),
    ({"E0": None}, "grid.E0: required SI field is missing (relaxed Young's modulus, Pa)"),
    ({"speed": None}, "grid.speed: required SI field is missing"),
    ({"a0": 1e-4}, "grid: give exactly one of preload [N], a0 [m] and indentation [m]"),
    ({"Einf": 1e6}, "Einf must be >= E0"),
    ({"rate": 3}, "grid.rate: unknown SI field"),
    ({"h0": "abc"}, "grid.h0 must be a number (got 'abc')"),
    ({"model": "fem"}, "grid.model must be one of"),
])
def test_bad_si_grid_one_line_naming_the_field(over, needle):
    with pytest.raises(InputError) as exc:
        config_from_dict(si_base(**over))
    text = str(exc.value)
    assert needle in text and "\n" not in text


def test_units_must_be_known():
    with pytest.raises(InputError, match="units: must be one of dimensionless, si"):
        config_from_dict({**base(), "units": "cgs"})


def test_shipped_pdms_config_is_the_papers_case():
    from tests.reference import paper_values

    pv = paper_values()["pdms_experiment"]
    cfg = load_config(CONFIGS / "pdms.yaml")
    sis = [si for _, si in cfg.si_tasks()]
    speeds_um = sorted({si.speed * 1e6 for si in sis})
    assert speeds_um[0] == pytest.approx(float(pv["rate_range_um_s"][0]))
    assert speeds_um[-1] == pytest.approx(float(pv["rate_range_um_s"][1]))
    assert all(si.preload == pytest.approx(pv["preload_mN"] * 1e-3) for si in sis)
    assert {s.model for s in cfg.scenes()} <= {"crack", "pb", "auto"}
    assert cfg.scenes()[0].mu == pytest.approx(103, abs=0.5)


def test_numerics_asked_as_an_accuracy_resolve_to_the_cheapest_preset_with_refinements():
    """`numerics: {pull_off_rtol: ...}` alone (issue 33 item 1): Numerics.for_tolerance."""
    from sweep.scene import Numerics
    cfg = config_from_dict({"name": "t", "grid": {"n": 0.4, "rate": 1.0, "a0": 2.0},
                            "numerics": {"pull_off_rtol": 0.01, "max_nodes": 800}})
    assert cfg.numerics == Numerics.for_tolerance(0.01, max_nodes=800)
    assert cfg.numerics.refinements > 0 and cfg.numerics.mesh == "graded"


# ----------------------------------------------------------------------------- Prony tables
PRONY = ROOT / "tests" / "data" / "prony"


def test_a_table_is_a_material_value_file_or_inline():
    """``material: [{prony: file}, inline, sls]``: one scene per table, k from the table (the
    default k is replaced), the id from the table's numbers: the same table inline and from
    its file is one scene (de-duplicated); to_dict and the YAML text read back to the same
    config hash."""
    from sweep.materials import read_prony
    from sweep.scene import scene_table

    inline = scene_table({"prony": str(PRONY / "pdms_prony_visco_sweep.csv")}).spec
    cfg = config_from_dict(base(grid={"material": [{"prony": str(PRONY / "pdms_prony.csv")},
                                                   inline, "sls",
                                                   {"tau": [0.5], "E": [1.0], "E0": 1.0}],
                                      "n": 0.8, "rate": [1, 100], "a0": 2.0}))
    mats = [s.material for s in cfg.scenes()]
    assert len(mats) == 6                        # the PDMS inline and from file: one table
    table = read_prony(PRONY / "pdms_prony.csv")
    assert str(mats[0]) == f"prony:pdms_prony:{table.content_hash()}"
    assert cfg.scenes()[0].k == pytest.approx(table.k, rel=1e-12)
    assert cfg.scenes()[4].k == pytest.approx(0.5, rel=1e-14)     # E0 / (E0 + E)
    assert config_from_dict(cfg.to_dict()).config_hash == cfg.config_hash
    assert parse_config(cfg.text).config_hash == cfg.config_hash


def test_relative_table_paths_are_read_from_the_working_directory(monkeypatch):
    monkeypatch.chdir(ROOT)
    cfg = parse_config("name: p\ngrid: {material: {prony: tests/data/prony/pdms_prony.csv}, "
                       "n: 0.8, rate: 1, a0: 2}\n")
    assert cfg.scenes()[0].material.name == "pdms_prony"


@pytest.mark.parametrize("material, needle", [
    ("{prony: nope.csv}", "grid.material: nope.csv: cannot read the Prony table"),
    ("[{tau: [1, 2], E: [1], E0: 1}]", "grid.material[0]: "),
    ("[{tau: [1], E: [-1], E0: 1}]", "must be >= 0"),
    ("[3]", "grid.material[0] must be mpl, sls or a Prony table"),
])
def test_bad_tables_in_a_config_one_line(material, needle):
    with pytest.raises(InputError) as exc:
        parse_config(f"name: p\ngrid: {{material: {material}, n: 0.8, rate: 1, a0: 2}}\n")
    assert needle in str(exc.value) and "\n" not in str(exc.value)


def test_a_conflicting_k_with_a_table_is_refused():
    with pytest.raises(InputError, match=r"k: the Prony table inline fixes k = E0/Einf = 0\.5"):
        parse_config("name: p\ngrid: {material: [{tau: [1], E: [1], E0: 1}], k: 0.2, n: 0.8, "
                     "rate: 1, a0: 2}\n")


def test_si_grid_with_a_table_needs_no_moduli_and_refuses_other_ones():
    """In an SI grid a table replaces E0, Einf, n and tau0: E0/Einf the table's (Pa), tau0
    1 s, k = E0/Einf; a given E0 that differs, or an n, is refused."""
    from sweep.materials import read_prony

    grid = {"material": {"prony": str(PRONY / "pdms_prony.csv")}, "R": 5.19e-3, "nu": 0.5,
            "dg": 0.1523, "h0": 30.8e-9, "preload": 1.5e-3, "speed": 1e-4, "model": "crack"}
    cfg = config_from_dict({"name": "s", "units": "si", "grid": grid})
    [(sid, si)] = cfg.si_tasks()
    t = read_prony(PRONY / "pdms_prony.csv")
    assert (si.E0, si.Einf, si.tau0) == (pytest.approx(t.E0), pytest.approx(t.Einf), 1.0)
    assert si.rate == pytest.approx(1e-4 * 1.0 / 30.8e-9, rel=1e-12)
    assert cfg.scenes()[0].k == pytest.approx(t.E0 / t.Einf, rel=1e-12)
    assert config_from_dict(cfg.to_dict()).config_hash == cfg.config_hash
    for over, needle in (({"E0": 2e6}, "E0: the Prony table pdms_prony gives E0 = 1.45835e+06"),
                         ({"n": 0.5}, "n: unused with a Prony table")):
        with pytest.raises(InputError) as exc:
            config_from_dict({"name": "s", "units": "si", "grid": {**grid, **over}})
        assert needle in str(exc.value)
    with pytest.raises(InputError, match="E0, Einf, n, tau0: required for material mpl"):
        config_from_dict({"name": "s", "units": "si",
                          "grid": {**grid, "material": ["mpl", grid["material"]]}})


def test_a_compliant_machine_with_a_protocol_is_refused_when_the_config_loads():
    """Every such scene failed at run time, auto included ("a compliant machine ... not a test
    protocol"), where other impossible combinations are refused at load: one line naming the
    parameter."""
    text = msg(grid={"n": 0.8, "k": 0.1, "mu": 3.24, "rate": 10.0, "approach_rate": 10.0,
                     "preload": 2.0, "dwell": 1.0, "machine_stiffness": 1.0})
    assert "machine_stiffness: a compliant machine runs the unloading from a relaxed" in text
    with pytest.raises(InputError, match="machine_stiffness"):
        Scene(n=0.8, k=0.1, mu=3.24, rate=10.0, approach_rate=10.0, preload=2.0, dwell=1.0,
              machine_stiffness=1.0)


def test_the_configs_the_docs_show_write_distinct_results_files():
    """Each sweep config in the README and docs/ writes its own results file: two configs of
    one name (the README's SI `name: gmm` and configs.md's dimensionless one) both wrote
    results/gmm.h5, and the second run was refused ("units differ ...")."""
    import re

    import yaml

    outputs = {}
    for page in [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]:
        text = page.read_text()
        for m in re.finditer(r"^```ya?ml\n(.*?)^```", text, re.S | re.M):
            d = yaml.safe_load(m.group(1))
            if not (isinstance(d, dict) and "grid" in d and "name" in d):
                continue
            where = f"{page.relative_to(ROOT)}:{text[:m.start()].count(chr(10)) + 1}"
            out = d.get("output", f"results/{d['name']}.h5")
            assert out not in outputs, f"{where} and {outputs[out]} both write {out}"
            outputs[out] = where
    assert "results/gmm.h5" in outputs and len(outputs) >= 5


def test_configs_md_shows_how_several_problems_are_reported(tmp_path, capsys, monkeypatch):
    """docs/configs.md said the problems are reported "one line each"; they are one line, joined
    by "; ". The page's example is what `sweep run` prints for that config."""
    import re

    from sweep.cli import main

    text = " ".join((ROOT / "docs" / "configs.md").read_text().split())
    assert "one line each" not in text
    shown = re.search(r"`(error: bad\.yaml: 2 problems: [^`]*)`", text).group(1)
    cfg = tmp_path / "bad.yaml"
    cfg.write_text("name: bad\ngrid: {n: -1, rate: 0, a0: 2}\n")
    monkeypatch.chdir(tmp_path)
    assert main(["run", "bad.yaml"]) == 2
    assert capsys.readouterr().err == shown + "\n"


@pytest.mark.parametrize("text, got", [("name: 123", "123"), ("name: 2024-01-02",
                                                             "datetime.date(2024, 1, 2)"),
                                       ("name: 1e3", None)])
def test_a_name_yaml_reads_as_no_string_says_to_quote_it(text, got):
    """`name: 123` said "must be a string of letters, digits ... (got 123)", which 123 is;
    YAML read it as a number: the message says to quote it. (`1e3` is a string in YAML 1.1.)"""
    src = text + "\ngrid: {n: 0.8, rate: 1, a0: 2}\n"
    if got is None:
        assert parse_config(src).name == "1e3"
        return
    with pytest.raises(InputError) as info:
        parse_config(src)
    value = text.split(": ")[1]
    assert str(info.value) == (f"<string>: name: must be a string, quoted in YAML where it "
                               f'reads as something else (name: "{value}") (got {got})')


def test_a_grid_point_s_own_problems_come_with_the_others():
    """A protocol missing two of its keys had been reported only once the numerics' problems
    were fixed, though docs/configs.md says every problem is reported at once."""
    from sweep.campaign.config import config_from_dict

    with pytest.raises(InputError) as err:
        config_from_dict({"name": "x", "grid": {"n": 0.8, "a0": 2, "rate": 1,
                                                "approach_rate": 1},
                          "numerics": {"max_nodes": 10, "refinements": 9}})
    text = str(err.value)
    assert "3 problems" in text and "numerics.max_nodes" in text
    assert "a protocol needs approach_rate, preload and dwell together" in text


def test_copies_by_unused_n_counts_the_sls_and_table_scenes_a_grid_over_n_repeats():
    """n is unused by sls and a Prony table: crossed with three n, each of their scenes runs
    three times to the same numbers, and the config says how many copies that makes."""
    crossed = config_from_dict({"name": "x", "grid": {"material": ["mpl", "sls"],
                                                      "n": [0.4, 0.8, 1.6], "rate": [1, 10],
                                                      "a0": 2.0}})
    assert len(crossed.tasks()) == 12 and crossed.copies_by_unused_n() == 4
    apart = config_from_dict({"name": "x", "grid": [
        {"material": "mpl", "n": [0.4, 0.8, 1.6], "rate": [1, 10], "a0": 2.0},
        {"material": "sls", "n": 1.0, "rate": [1, 10], "a0": 2.0}]})
    assert len(apart.tasks()) == 8 and apart.copies_by_unused_n() == 0

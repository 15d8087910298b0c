"""One definition of a scene: every list of scene parameters derives from the Scene fields.

Config axes, their defaults and limits, the `sweep scene` options, the store's columns and
`sweep info`, the plots' grouping and the docs table all come from the field metadata in
sweep/scene.py, so a new scene parameter is added there only.
"""
from __future__ import annotations

import dataclasses
import re
from pathlib import Path

import pytest

from sweep.campaign import config
from sweep.campaign import store
from sweep import Numerics, Result, Scene
from sweep.cli import cli
from sweep.errors import InputError
from sweep.scene import AXES, RESULT_SCALARS, SCENE_AXES

ROOT = Path(__file__).resolve().parents[1]


def test_every_list_of_scene_parameters_is_the_scene_fields():
    fields = [f.name for f in dataclasses.fields(Scene)]
    assert list(SCENE_AXES) == fields
    assert sorted(config.AXES) == sorted(fields)
    assert config.AXES[-1] == "rate"                      # the fastest-varying axis
    assert list(store.SCENE_PARAMS) == fields
    options = {p.name for p in cli.commands["scene"].params}
    assert set(fields) <= options
    row = Result(scene=Scene(n=1, rate=1, a0=2), numerics=Numerics()).to_row()
    assert [c for c in row if c in fields] == fields


def test_defaults_and_limits_come_from_the_metadata():
    for a in AXES.values():
        field = next(f for f in dataclasses.fields(Scene) if f.name == a.name)
        assert a.required == (field.default is dataclasses.MISSING)
        if a.default is not None:
            assert config.AXIS_DEFAULTS[a.name] == a.default
        if a.numeric:
            lo, hi = a.limits
            with pytest.raises(InputError, match=a.name):
                a.check(hi * 2 + 1)
            assert a.check(hi) == hi
            if a.lo_open:
                with pytest.raises(InputError, match=a.name):
                    a.check(lo)
        else:
            with pytest.raises(InputError, match=a.name):
                a.check("nonsense")


def test_result_scalars_are_the_scalar_result_fields():
    scalar = [f.name for f in dataclasses.fields(Result)
              if f.name not in ("scene", "numerics", "trajectory", "final_gap")]
    assert list(RESULT_SCALARS) == scalar


def test_docs_table_matches_the_metadata():
    text = (ROOT / "docs" / "configs.md").read_text()
    rows = re.findall(r"^\| `(\w+)` \| ([^|]+) \| ([^|]+) \|", text, flags=re.M)
    assert [r[0] for r in rows] == list(config.AXES)
    for name, default, allowed in rows:
        a = AXES[name]
        want = "required" if a.required else ("--" if a.default is None else f"{a.default:g}"
                                              if a.numeric else a.default)
        assert default.strip() == want, name
        assert allowed.strip() == a.allowed(), name


def test_a_value_just_past_a_bound_is_printed_in_full():
    """Six digits printed k = 1.0000001 as 1, the bound it crosses: "k must be in (0, 1] (got
    1)". The value is printed in full there; elsewhere (and at the bound itself) as before."""
    from sweep.errors import InputError

    cases = {1.0000001: "(got 1.0000001)", 0.0: "(got 0)", 1.5: "(got 1.5)"}
    for k, got in cases.items():
        with pytest.raises(InputError) as info:
            Scene(n=0.8, k=k, mu=3.24, a0=2.0, rate=10.0)
        assert str(info.value) == f"k must be in (0, 1] {got}"


def test_a_preset_with_an_unknown_override_names_the_allowed_fields():
    """Numerics.preset("fast", bogus=1) raised a plain TypeError, where from_dict names the
    allowed keys in an InputError (a one-line message at the CLI)."""
    from sweep import Numerics
    from sweep.errors import InputError

    with pytest.raises(InputError, match=r"numerics: unknown key\(s\) bogus \(allowed: "):
        Numerics.preset("fast", bogus=1)
    assert Numerics.preset("fast", nodes=120).nodes == 120


def test_a_quoted_reason_is_cut_at_a_word():
    """A fallback quoting the BEM's reason cut it mid-word ("... above pull_o)")."""
    from sweep.errors import shortened

    text = "unresolved: the pull-off moves by 0.046, above pull_off_rtol = 0.03; raise it"
    assert shortened(text, 200) == text
    assert shortened(text, 50) == "unresolved: the pull-off moves by 0.046, above ..."

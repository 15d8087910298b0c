"""Stable scene ids and results files that keep working (issue 12, item 4).

(a) The ids of a fixed set of scenes stay those recorded in tests/data/scene_ids.yaml
    (written by the version-1 id form), also after a field with a default is added.
(b) tests/data/results_v1.h5, written by version 1 (config tests/data/results_v1.yaml),
    loads, shows in ``sweep info`` and resumes with nothing recomputed; a file of a newer id
    version is refused with exit 2 and one line, and is left untouched.
"""
from __future__ import annotations

import dataclasses
import io
import json
import shutil

import h5py
import pytest

from tests import reference
from sweep import Numerics, Scene, scene_id
from sweep.cli import main
from sweep.errors import InputError
from sweep.campaign.config import parse_config
from sweep.scene import ENGINE_REVISION, SCENE_ID_VERSION, axis
from sweep.campaign.scheduler import older_revision_rows, run_sweep
from sweep.campaign.store import load, load_trajectory, read_attrs, recorded_numerics

V1_FILE = reference.DATA / "results_v1.h5"


def _recorded():
    return reference.load("scene_ids")


def test_ids_stay_as_recorded():
    for case in _recorded():
        assert scene_id(Scene(**case["scene"]), Numerics(**case["numerics"])) == case["id"]


@dataclasses.dataclass(frozen=True, kw_only=True)
class GrownScene(Scene):
    """Scene with a field added later (as a new physical parameter would be)."""

    adhesion_hysteresis: float = axis(0.0, help="a new parameter", limits=(0.0, 1.0), order=8)


@dataclasses.dataclass(frozen=True, kw_only=True)
class GrownNumerics(Numerics):
    line_search: str = "backtracking"


def test_a_defaulted_new_field_renames_no_scene():
    for case in _recorded():
        scene = GrownScene(**case["scene"])
        numerics = GrownNumerics(**case["numerics"])
        assert scene_id(scene, numerics) == case["id"]
        # the new field enters the id as soon as it leaves its default
        moved = dataclasses.replace(scene, adhesion_hysteresis=0.5)
        assert scene_id(moved, numerics) != case["id"]


def test_the_lennard_jones_tail_switch_keeps_every_id_at_its_default():
    # Numerics.lj_tail (added with the tail, session 49) is not in an id at its default True;
    # False, the truncated model, is another scene; it is a bool
    for case in _recorded():
        numerics = Numerics(**case["numerics"])
        assert numerics.lj_tail is True
        assert scene_id(Scene(**case["scene"]), numerics) == case["id"]
        truncated = dataclasses.replace(numerics, lj_tail=False)
        assert scene_id(Scene(**case["scene"]), truncated) != case["id"]
    for bad in ("no", 0, None):
        with pytest.raises(InputError, match="lj_tail must be true or false"):
            Numerics(lj_tail=bad)


def _pinned_config(path):
    """The file's config with its preset replaced by the numerics its rows were run with
    (the presets were redefined when the graded mesh came; explicit numerics keep ids)."""
    return dataclasses.replace(parse_config(read_attrs(path)["config_text"]),
                               numerics=recorded_numerics(path))


def test_recorded_numerics_are_the_rows(tmp_path):
    ran = recorded_numerics(V1_FILE)
    row = load(V1_FILE).iloc[0]
    assert (ran.nodes, ran.step, ran.da_max, ran.mesh) == (row.num_nodes, row.num_step,
                                                          row.num_da_max, "uniform")
    # a file written now records every field: its rows give back the config's numerics
    cfg = parse_config(read_attrs(V1_FILE)["config_text"])
    out = tmp_path / "now.h5"
    run_sweep(cfg, jobs=1, out=out, simulate=_fake, progress="none")
    assert recorded_numerics(out) == cfg.numerics != ran
    assert recorded_numerics(tmp_path / "nothing.h5") is None


def test_version_1_file_loads_and_shows_in_info(capsys):
    df = load(V1_FILE)
    # the ids in the file are the ids of the scenes and numerics its rows record
    for _, row in df.iterrows():
        scene = Scene(**{k: (None if isinstance(row[k], float) and row[k] != row[k] else row[k])
                         for k in ("n", "k", "mu", "rate", "a0", "delta0", "material", "stop")})
        numerics = _pinned_config(V1_FILE).numerics
        assert scene_id(scene, numerics) == row["scene_id"]
    assert set(df.status) == {"ok"}
    assert len(load_trajectory(V1_FILE, df.scene_id[0])["P"]) > 2
    assert main(["info", str(V1_FILE)]) == 0
    out = capsys.readouterr().out
    assert "scenes: 3 finished of 3" in out and "material: mpl, sls" in out
    # its rows were computed without the Lennard-Jones tail, and info says so
    assert (f"engine: rows of an earlier engine than this one (revision {ENGINE_REVISION}): "
            "3 of revision 1 (loads without the Lennard-Jones tail beyond the mesh") in out


def _must_not_run(scene, numerics):
    raise AssertionError(f"scene recomputed: {scene}")


def test_version_1_file_resumes_with_nothing_recomputed(tmp_path):
    path = tmp_path / "v1.h5"
    shutil.copyfile(V1_FILE, path)
    cfg = _pinned_config(path)
    report = run_sweep(cfg, jobs=1, out=path, simulate=_must_not_run, progress="none")
    assert (report.total, report.skipped, report.ran) == (3, 3, 0)
    assert sorted(load(path).scene_id) == sorted(load(V1_FILE).scene_id)


def test_rows_of_an_earlier_engine_revision_are_kept_and_named_on_resume(tmp_path):
    # the v1 file's rows were computed without the Lennard-Jones tail (revision 1, no
    # engine_revision column): resuming keeps them and says so in one line; rows run now
    # record this engine's revision
    path = tmp_path / "v1.h5"
    shutil.copyfile(V1_FILE, path)
    text = read_attrs(path)["config_text"].replace("n: [0.4, 1.6]", "n: [0.4, 1.0, 1.6]")
    pinned = text.replace("numerics: {preset: fast, nodes: 80}",
                          "numerics: " + json.dumps(recorded_numerics(path).to_dict()))
    stream = io.StringIO()
    run_sweep(parse_config(pinned), jobs=1, out=path, simulate=_fake, progress="log",
              stream=stream)
    said = [ln for ln in stream.getvalue().splitlines() if "earlier engine" in ln]
    assert len(said) == 1 and "3 of revision 1 (loads without the Lennard-Jones tail" in said[0]
    assert f"this engine is revision {ENGINE_REVISION}" in said[0]
    df = load(path)
    assert df.engine_revision.isna().sum() == 3
    assert list(df.engine_revision.dropna()) == [ENGINE_REVISION]
    assert older_revision_rows(df.to_dict("records"), set(df.scene_id)) == {1: 3}


def test_a_redefined_preset_is_refused_in_one_line(tmp_path, capsys):
    # the file's own config says `preset: fast`, whose numerics changed with the graded
    # mesh: resuming would mix two discretizations under one config, so it is refused
    path = tmp_path / "v1.h5"
    shutil.copyfile(V1_FILE, path)
    before = path.read_bytes()
    cfg_path = tmp_path / "cfg.yaml"
    cfg_path.write_text(read_attrs(path)["config_text"])
    assert main(["run", str(cfg_path), "--out", str(path), "--progress", "none"]) == 2
    err = [ln for ln in capsys.readouterr().err.splitlines() if ln.strip()]
    assert len(err) == 1 and "numerics meant other values" in err[0], err
    assert path.read_bytes() == before
    assert main(["info", str(path)]) == 0


def test_newer_id_version_is_refused_in_one_line(tmp_path, capsys):
    path = tmp_path / "future.h5"
    shutil.copyfile(V1_FILE, path)
    with h5py.File(path, "r+") as f:
        f.attrs["scene_id_version"] = SCENE_ID_VERSION + 1
    before = path.read_bytes()
    cfg_path = tmp_path / "cfg.yaml"
    cfg_path.write_text(read_attrs(path)["config_text"])
    assert main(["run", str(cfg_path), "--out", str(path), "--progress", "none"]) == 2
    err = [ln for ln in capsys.readouterr().err.splitlines() if ln.strip()]
    assert len(err) == 1 and "scene id version" in err[0], err
    assert path.read_bytes() == before
    assert main(["info", str(path)]) == 0          # reading it still works


def _fake(scene, numerics):
    from sweep.scene import Result
    return Result(scene=scene, numerics=numerics, status="ok", pull_off=1.0)


def test_new_files_record_the_id_version(tmp_path):
    cfg = parse_config(read_attrs(V1_FILE)["config_text"])
    run_sweep(cfg, jobs=1, out=tmp_path / "new.h5", simulate=_fake, progress="none")
    assert read_attrs(tmp_path / "new.h5")["scene_id_version"] == SCENE_ID_VERSION


def test_version_1_file_grows_or_refuses_in_one_line(tmp_path, capsys):
    # a grown version of the v1 file's config (its preset was redefined since): refused with
    # the reason, the file untouched and still loading; the pinned numerics grow it
    path = tmp_path / "v1.h5"
    shutil.copyfile(V1_FILE, path)
    before = path.read_bytes()
    text = read_attrs(path)["config_text"].replace("n: [0.4, 1.6]", "n: [0.4, 1.0, 1.6]")
    cfg_path = tmp_path / "cfg.yaml"
    cfg_path.write_text(text)
    assert main(["run", str(cfg_path), "--out", str(path), "--progress", "none"]) == 2
    err = [ln for ln in capsys.readouterr().err.splitlines() if ln.strip()]
    assert len(err) == 1 and "numerics meant other values" in err[0], err
    assert "its rows ran with other values than this config's (" in err[0], err
    assert "mesh 'uniform' -> 'graded'" in err[0], err
    assert "give the file's values in this config's numerics" in err[0], err
    assert path.read_bytes() == before and len(load(path)) == 3
    # the same grown config with the rows' numerics given explicitly grows the file: the
    # three finished scenes are kept, only the new one (n = 1.0) runs
    pinned = text.replace("numerics: {preset: fast, nodes: 80}",
                          "numerics: " + json.dumps(recorded_numerics(path).to_dict()))
    assert pinned != text
    ran = []

    def record(scene, numerics):
        ran.append(scene.n)
        return _fake(scene, numerics)

    report = run_sweep(parse_config(pinned), jobs=1, out=path, simulate=record,
                       progress="none")
    assert (report.total, report.skipped, report.ran, ran) == (4, 3, 1, [1.0])
    df = load(path)
    assert len(df) == 4 and set(load(V1_FILE).scene_id) < set(df.scene_id)
    # numerics other than the rows' are refused, naming the field
    cfg_path.write_text(pinned.replace('"da_max": 1.0', '"da_max": 0.5'))
    assert main(["run", str(cfg_path), "--out", str(path), "--progress", "none"]) == 2
    err = [ln for ln in capsys.readouterr().err.splitlines() if ln.strip()]
    assert len(err) == 1 and "da_max 1.0 -> 0.5" in err[0], err

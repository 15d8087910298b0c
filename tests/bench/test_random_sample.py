"""The random sample across the declared ranges (issue 21, "done when"): its configs are what
the generator writes, and the outcome classes of a stored row."""
from __future__ import annotations

import pytest
import yaml

from sweep.bench import random_sample
from sweep.campaign.config import load_config


def test_the_committed_configs_are_the_generators():
    for model in random_sample.MODELS:
        path = random_sample.CONFIGS / f"{model}.yaml"
        committed = yaml.safe_load(path.read_text())
        assert committed == random_sample.sample_config(60, 21, model)
        cfg = load_config(path)
        assert len(cfg.scenes()) == 60 and {s.model for s in cfg.scenes()} == {model}
        assert cfg.numerics.time_budget_s == random_sample.BUDGET_S


def test_outcome_classes():
    row = lambda status, reason="": {"status": status, "reason": reason}   # noqa: E731
    assert random_sample.outcome(row("ok")) == "ok"
    assert random_sample.outcome(row("error", "TypeError")) == "error"
    assert random_sample.outcome(row("failed", "no stable contact of radius a0 = 0.4")) == "refused"
    assert random_sample.outcome(row("failed", "time budget: 20 s")) == "failed"


def test_the_sweep_wall_is_the_span_of_its_scenes_not_their_sum():
    # two workers: scenes of 3, 2 and 4 s, the third started when the second ended; the
    # wall runs from the first start (t = 10) to the last end (t = 16)
    import pandas as pd

    df = pd.DataFrame({"finished_at": [13.0, 12.0, 16.0], "task_wall_s": [3.0, 2.0, 4.0]})
    assert random_sample.scene_span(df) == 6.0
    assert df.task_wall_s.sum() == 9.0


@pytest.mark.parametrize("process_zone", [False, True])
def test_the_committed_protocol_configs_are_the_generators(process_zone):
    path = random_sample.CONFIGS / ("protocol_pz.yaml" if process_zone else "protocol.yaml")
    assert yaml.safe_load(path.read_text()) == random_sample.protocol_config(process_zone)
    scenes = load_config(path).scenes()
    count = random_sample.PROTOCOL_PZ_COUNT if process_zone else random_sample.PROTOCOL_COUNT
    assert len(scenes) == count
    assert all(s.protocol() is not None and s.model == "auto" for s in scenes)
    # the sample spans both holds, dwells and none; both materials, or the process zone
    assert {s.dwell_hold for s in scenes} == {"force", "depth"}
    assert any(s.dwell == 0.0 for s in scenes) and any(s.dwell > 0.0 for s in scenes)
    if process_zone:
        assert {s.pz_law for s in scenes} == {"gent-schultz"}
    else:
        assert {s.material for s in scenes} == {"mpl", "sls"}


def test_a_protocol_rows_failure_names_its_protocol_not_an_a0():
    row = {"n": 0.5, "k": 0.1, "mu": 1.0, "a0": float("nan"), "rate": 1.0, "material": "mpl",
           "approach_rate": 2.0, "preload": 1.0, "dwell": 0.0, "dwell_hold": "force",
           "reason": "time budget: 20 s"}
    failure = random_sample._failure(row)
    assert "a0" not in failure and failure["preload"] == 1.0 and failure["reason"] == row["reason"]
    relaxed = dict(row, a0=2.0, approach_rate=float("nan"), preload=float("nan"),
                   dwell=float("nan"))
    assert set(random_sample._failure(relaxed)) == {"n", "k", "mu", "a0", "rate", "material",
                                                    "reason"}

"""The random sample across the declared ranges (issue 21, "done when"): its configs are what
the generator writes, and the outcome classes of a stored row."""
from __future__ import annotations

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

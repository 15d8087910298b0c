"""A row is a row (issue 33 item 3): a scene gives the same row, bit for bit, whichever
process runs it and whatever that process ran before (the per-process caches of relaxed
starts and meshes, the disk cache of Prony series and influence matrices): caches save time,
never change a number. Each side runs in a fresh Python process; the cold side with an empty
disk cache."""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

#: scenes that share what the caches keep: the first two the relaxed start (graded mesh,
#: same mu and a0), the third and fourth the tip-following mesh's (mu = 6), the last the
#: crack-front model's Persson-Brener table
SCENES = [dict(n=0.4, k=0.1, mu=3.24, a0=2.0, rate=1.0),
          dict(n=0.8, k=0.1, mu=3.24, a0=2.0, rate=100.0),
          dict(n=0.8, k=0.2, mu=6.0, a0=2.5, rate=10.0),
          dict(n=0.4, k=0.2, mu=6.0, a0=2.5, rate=1.0),
          dict(n=0.8, k=0.1, mu=30.0, a0=3.0, rate=10.0, model="crack")]

#: columns that say when and how long, not what: they differ between any two runs
TIMING = ("wall_s",)

_RUN = """
import json, math, sys
from sweep import Numerics, Scene, simulate
scenes = json.loads(sys.argv[1])
rows = []
for s in scenes:
    row = simulate(Scene(**s), Numerics.preset("fast")).to_row()
    rows.append({k: (v.hex() if isinstance(v, float) else v) for k, v in row.items()})
print(json.dumps(rows))
"""


def _run(scenes, cache_dir) -> list[dict]:
    env = dict(os.environ, SWEEP_CACHE_DIR=str(cache_dir),
               PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))
    out = subprocess.run([sys.executable, "-c", _RUN, json.dumps(scenes)], env=env, cwd=ROOT,
                         capture_output=True, text=True, timeout=900)
    assert out.returncode == 0, out.stderr[-2000:]
    rows = json.loads(out.stdout.strip().splitlines()[-1])
    return [{k: v for k, v in r.items() if k not in TIMING} for r in rows]


def test_a_scene_alone_in_a_cold_process_and_after_others_in_a_warm_one(tmp_path):
    warm = _run(SCENES, tmp_path / "warm")                 # in order, caches filling
    assert all(r["status"] == "ok" for r in warm), [r["reason"] for r in warm]
    assert [r["model_used"] for r in warm] == ["bem"] * 4 + ["crack"]
    assert "tip-following" in warm[2]["reason"] and "tip-following" in warm[3]["reason"]
    for i in (1, 3, 4):                                     # the ones whose start was cached
        cold = _run([SCENES[i]], tmp_path / f"cold{i}")     # alone, empty disk cache
        assert cold[0] == warm[i], {k: (cold[0][k], warm[i][k]) for k in cold[0]
                                    if cold[0][k] != warm[i].get(k)}
    backwards = _run(SCENES[::-1], tmp_path / "warm")       # another order, warm disk cache
    assert backwards[::-1] == warm

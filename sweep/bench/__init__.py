"""Measurement of the engine: speed benchmarks (:mod:`.benchmarks`), the accuracy/time trade
(:mod:`.tradeoff`), agreement between models (:mod:`.agreement`), the cheaper models' errors
against the BEM that the model chooser reads (:mod:`.model_errors`), the error estimate's
coverage of the true error (:mod:`.error_coverage`), a random sample across the declared
ranges (:mod:`.random_sample`), stability at the extremes (:mod:`.extremes`) and the plain
numpy baseline the speed is measured against (:mod:`.plain_solver`).
"""


def measurement_main(prog: str, doc: str, measure, default_out, argv=None) -> int:
    """The command line of a measurement module: ``--out PATH`` (default ``default_out``),
    ``measure()``'s mapping written there as JSON."""
    import argparse
    import json
    from pathlib import Path

    from ..campaign.store import to_jsonable

    ap = argparse.ArgumentParser(prog=prog, description=doc.splitlines()[0])
    ap.add_argument("--out", default=str(default_out), help="where to write the results (JSON)")
    args = ap.parse_args(argv)
    data = measure()
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(to_jsonable(data), indent=1) + "\n", encoding="utf-8")
    print(f"wrote {out}")
    return 0

"""visco-sweep: viscoelastic adhesive contact of a rigid sphere, as a parameter-sweep engine.

Public API (units and conventions: see ``sweep.units`` and DESIGN.md section 2)::

    from sweep import Scene, Numerics, simulate
    result = simulate(Scene(n=0.8, k=0.1, mu=3.24, a0=3.61, rate=316.2), Numerics.preset("balanced"))
"""
__version__ = "0.1.0"

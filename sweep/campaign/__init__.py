"""The campaign layer: from a YAML config to a results file of many scenes.

Data flow: :mod:`.config` (a grid of scenes; :mod:`.si` for grids in SI units) ->
:mod:`.scheduler` (the scenes over the cores or a dask cluster, each through
:func:`sweep.simulate`) -> :mod:`.store` (the crash-safe HDF5 file, read back with pandas).
"""

"""The engine: everything that solves one scene.

Data flow: a :class:`sweep.Scene` and its :class:`sweep.Numerics` -> :mod:`.problem` (every
derived number, once) -> :mod:`.mesh` and :mod:`.initial` (the relaxed state) -> the kernels
(:mod:`sweep.kernels`) -> :mod:`.postprocess` -> a :class:`sweep.Result`.

=============  =================================================================================
module         owns
=============  =================================================================================
problem        the prepared problem: h0, l0, the tip zone, the tip gap, the loading speed, the
               Prony series, the mesh; the one place these are derived
mesh           radial meshes (graded, uniform) and their cached influence matrices
diskcache      the on-disk cache of influence matrices and Prony series
initial        the relaxed (elastic) initial state at delta0 or a0
bem            the boundary-element model on the graded mesh (Prony recursion)
exact          the same model with the exact hereditary integral (validation)
tip_following  the BEM on a mesh refined around the crack tip that follows it
quasistatic    the elastic, quasi-static branch (k = 1)
crack_front    the crack-front model: a JKR contact whose edge opens with Gamma(v)
postprocess    a finished unloading turned into a result: the pull-off, the state and the
               crack speed there (:func:`.postprocess.finish`)
resolution     the error estimate: the pull-off change against a solve at half the
               resolution in space and time, plus the Prony fit's error
models         the model registry and :func:`simulate`, the one entry for one scene
=============  =================================================================================
"""

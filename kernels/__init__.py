"""The compiled core (installed as ``sweep.kernels``): Numba ``@njit(cache=True)`` functions on
plain arrays, no I/O and no Python objects.

=============  =================================================================================
module         owns
=============  =================================================================================
interface      the Lennard-Jones traction law, its stiffness, the contact-radius crossing
influence      the overlapping-triangle influence matrix of the axisymmetric half-space
history        the Prony recursion of the hereditary integral (O(N M) per step)
blas           BLAS/LAPACK (scipy's) called from compiled code
jacobian       Newton's linear algebra: a kept factorization, the crack-tip zone exact
solve          the per-step Newton solve and the unloading loop with its stop rule
=============  =================================================================================

The folder sits at the top of the repository (``kernels/``); the wheel installs it inside the
``sweep`` distribution, never as a top-level package of its own.
"""

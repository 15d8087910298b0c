"""BLAS and LAPACK from compiled kernels: the routines scipy ships, called on row-major blocks
(Numba kernels).

Numba's ``np.dot``/``np.linalg`` need contiguous arrays and offer no LU solve; the kernels of
:mod:`kernels.jacobian` factorize and solve blocks of preallocated flat buffers and multiply
by row blocks of the influence matrix (a leading dimension other than the block's width).
The routines of ``scipy.linalg.cython_blas`` and ``cython_lapack`` take such blocks through
their leading dimension. Their addresses are
registered with LLVM under a symbol name at import, so the compiled kernels refer to them by
name (and stay cacheable, as Numba's own LAPACK bindings do).

A row-major (rows, ld) array is, to Fortran, its transpose: an (ld, rows) column-major
matrix with leading dimension ld; each wrapper below states what it computes in row-major
terms.
"""
from __future__ import annotations

import llvmlite.binding as ll
import numpy as np
from numba import njit, types
from numba.extending import get_cython_function_address


def _bind(module: str, name: str, nargs: int):
    symbol = f"visco_sweep_{name}"
    ll.add_symbol(symbol, get_cython_function_address(f"scipy.linalg.cython_{module}", name))
    return types.ExternalFunction(symbol, types.void(*([types.voidptr] * nargs)))


_dgemv = _bind("blas", "dgemv", 11)
_sgemv = _bind("blas", "sgemv", 11)
_dgetrf = _bind("lapack", "dgetrf", 6)
_sgetrf = _bind("lapack", "sgetrf", 6)
_dgetrs = _bind("lapack", "dgetrs", 9)
_sgetrs = _bind("lapack", "sgetrs", 9)

_N = ord("N")
_T = ord("T")


# the two helpers below are inlined where they are called (``inline='always'``): compiled
# on their own they would be specialized for every literal argument (the transposition
# code, the zeros), each specialization a compile of its own (docs/performance.md)
@njit(cache=True, inline='always')
def _ints(a, b, c, d):
    out = np.empty(4, np.int32)
    out[0] = a
    out[1] = b
    out[2] = c
    out[3] = d
    return out


@njit(cache=True, inline='always')
def _gemv(trans, M, rows, cols, x, y, alpha, beta):
    """dgemv (sgemv for float32 ``M``, ``x``, ``y``) on the Fortran view of M[:rows, :cols]
    (cols x rows): ``trans`` T gives M @ x into y[:rows], N gives M^T @ x into y[:cols]."""
    n_out = rows if trans == _T else cols
    if n_out == 0:
        return
    if rows == 0 or cols == 0:
        for i in range(n_out):
            y[i] *= beta
        return
    code = np.array([trans], np.uint8)
    dims = _ints(cols, rows, M.shape[1], 1)
    ab = np.array([alpha, beta], M.dtype)
    if M.itemsize == 4:
        _sgemv(code.ctypes, dims[0:].ctypes, dims[1:].ctypes, ab[0:].ctypes, M.ctypes,
               dims[2:].ctypes, x.ctypes, dims[3:].ctypes, ab[1:].ctypes, y.ctypes,
               dims[3:].ctypes)
    else:
        _dgemv(code.ctypes, dims[0:].ctypes, dims[1:].ctypes, ab[0:].ctypes, M.ctypes,
               dims[2:].ctypes, x.ctypes, dims[3:].ctypes, ab[1:].ctypes, y.ctypes,
               dims[3:].ctypes)


@njit(cache=True)
def gemv_rows(M, rows, cols, x, y, alpha, beta):
    """y[:rows] = alpha M[:rows, :cols] @ x[:cols] + beta y[:rows] (M row-major, C order;
    M, x and y all float64 or all float32)."""
    _gemv(_T, M, rows, cols, x, y, alpha, beta)


@njit(cache=True)
def gemv_cols(M, rows, cols, x, y, alpha, beta):
    """y[:cols] = alpha M[:rows, :cols]^T @ x[:rows] + beta y[:cols] (M row-major; M, x and
    y all float64 or all float32)."""
    _gemv(_N, M, rows, cols, x, y, alpha, beta)


@njit(cache=True)
def lu_factor(K, piv):
    """LU factorization (partial pivoting) of the square C-order ``K`` (float64, or float32:
    single precision) in place, pivots in ``piv`` (int32). The factors are those of K^T to
    LAPACK; :func:`lu_solve` accounts for it. Returns LAPACK's info (0: success, > 0:
    exactly singular)."""
    dims = _ints(K.shape[0], 0, 0, 0)
    if K.itemsize == 4:
        _sgetrf(dims.ctypes, dims.ctypes, K.ctypes, dims.ctypes, piv.ctypes, dims[1:].ctypes)
    else:
        _dgetrf(dims.ctypes, dims.ctypes, K.ctypes, dims.ctypes, piv.ctypes, dims[1:].ctypes)
    return dims[1]


@njit(cache=True)
def lu_solve(K, piv, B):
    """Solve K X = B^T in place of B for the factors of :func:`lu_factor`: ``B`` (p, n)
    C order, of K's dtype, holds the p right-hand sides as rows (and receives the
    solutions)."""
    if B.shape[0] == 0:
        return
    trans = np.array([_T], np.uint8)
    dims = _ints(K.shape[0], B.shape[0], 0, 0)
    if K.itemsize == 4:
        _sgetrs(trans.ctypes, dims[0:].ctypes, dims[1:].ctypes, K.ctypes, dims[0:].ctypes,
                piv.ctypes, B.ctypes, dims[0:].ctypes, dims[2:].ctypes)
    else:
        _dgetrs(trans.ctypes, dims[0:].ctypes, dims[1:].ctypes, K.ctypes, dims[0:].ctypes,
                piv.ctypes, B.ctypes, dims[0:].ctypes, dims[2:].ctypes)

"""A monotonic clock that compiled code can read: the time budget's checks inside a kernel.

A scene's time budget (``sweep.engine.budget``) was checked only between kernel calls; one call
of the unloading kernel (2000 steps) on a large mesh ran for minutes past it (a process-zone
scene refined to 2301 nodes: 105 s for a 20 s budget). Numba has no clock of its own, so
:func:`monotonic` calls the C library's ``clock_gettime`` (CLOCK_MONOTONIC, the clock of
``time.perf_counter`` on Linux) from the compiled code, through an intrinsic: the call is a
symbol the machine code names, so the kernels stay cacheable.

A deadline is handed to a kernel as seconds from now and turned into this clock's time by
:func:`deadline_after` (compiled), so that the kernels never compare their clock with
Python's.
"""
from __future__ import annotations

import math
import sys

from llvmlite import ir
from numba import njit, types
from numba.core import cgutils
from numba.extending import intrinsic

#: clock_gettime's CLOCK_MONOTONIC: 1 on Linux, 6 on macOS
CLOCK_MONOTONIC = 6 if sys.platform == "darwin" else 1


@intrinsic
def monotonic(typingctx):
    """Seconds on the C library's CLOCK_MONOTONIC (compiled code only)."""
    def codegen(context, builder, signature, args):
        i64, i32, f64 = ir.IntType(64), ir.IntType(32), ir.DoubleType()
        timespec = ir.LiteralStructType([i64, i64])
        fn = cgutils.get_or_insert_function(
            builder.module, ir.FunctionType(i32, [i32, timespec.as_pointer()]),
            "clock_gettime")
        ts = cgutils.alloca_once(builder, timespec)
        builder.call(fn, [ir.Constant(i32, CLOCK_MONOTONIC), ts])
        sec = builder.sitofp(builder.load(cgutils.gep_inbounds(builder, ts, 0, 0)), f64)
        nsec = builder.sitofp(builder.load(cgutils.gep_inbounds(builder, ts, 0, 1)), f64)
        return builder.fadd(sec, builder.fmul(nsec, ir.Constant(f64, 1e-9)))
    return types.float64(), codegen


@njit(cache=True)
def now() -> float:
    """:func:`monotonic` read from Python (seconds; only differences mean anything)."""
    return monotonic()


@njit(cache=True)
def deadline_after(seconds: float) -> float:
    """The kernels' clock time ``seconds`` from now (inf for inf: no deadline)."""
    if seconds == math.inf:
        return math.inf
    return monotonic() + seconds


@njit(cache=True, inline='always')
def past(deadline: float) -> bool:
    """Whether the kernels' clock is past ``deadline`` (from :func:`deadline_after`); never
    for inf, without reading the clock."""
    return deadline < math.inf and monotonic() > deadline

"""Prony-series hereditary integral: O(N M) recursive update per time step (Numba kernels).

With Chat(t) = 1 - sum_i c_i exp(-t/tau_i), traction piecewise linear in time over a step
dt and a fully relaxed start (all q_i = 0), docs/design.md section 4:

    q_i(n+1) = e_i q_i(n) + b_i (sigma(n+1) - sigma(n)),  e_i = exp(-dt/tau_i),
    b_i = tau_i (1 - e_i)/dt,
    u(n+1)   = A [ C_eff sigma(n+1) - H(n) ],   C_eff = 1 - sum_i c_i b_i,
    H(n)     = sum_i c_i (e_i q_i(n) - b_i sigma(n)).

A mode with tau_i = inf (lumped glassy) has e_i = b_i = 1.
"""
from __future__ import annotations

import numpy as np
from numba import njit

#: below this dt/tau, b_i = 1 - x/2 (its series, exact to rounding there) instead of
#: -expm1(-x)/x (undefined at x = 0)
SERIES_BELOW = 1e-12


@njit(cache=True)
def step_coefficients(weights, times, dt, e, b):
    """Fill e_i, b_i for a step dt and return C_eff = 1 - sum c_i b_i."""
    ceff = 1.0
    for i in range(weights.size):
        tau = times[i]
        if np.isinf(tau):
            e[i] = 1.0
            b[i] = 1.0
        else:
            x = dt / tau
            e[i] = np.exp(-x)
            b[i] = -np.expm1(-x) / x if x > SERIES_BELOW else 1.0 - 0.5 * x
        ceff -= weights[i] * b[i]
    return ceff


@njit(cache=True)
def history_vector(weights, e, b, q, sigma, H):
    """H = sum_i c_i (e_i q_i - b_i sigma) for every node. q has shape (M, N)."""
    N = sigma.size
    for j in range(N):
        H[j] = 0.0
    for i in range(weights.size):
        ci = weights[i]
        cei = ci * e[i]
        cbi = ci * b[i]
        for j in range(N):
            H[j] += cei * q[i, j] - cbi * sigma[j]


@njit(cache=True)
def update_modes(e, b, q, sigma_new, sigma_old):
    """q_i <- e_i q_i + b_i (sigma_new - sigma_old), in place."""
    N = sigma_new.size
    for i in range(e.size):
        ei = e[i]
        bi = b[i]
        for j in range(N):
            q[i, j] = ei * q[i, j] + bi * (sigma_new[j] - sigma_old[j])

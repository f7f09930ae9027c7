"""numba kernels of the fused LIF layer (:class:`bgfn.models.lif.FusedLIF`): Eq. (eq:LIF) over all ``T`` SNN steps
and its BPTT backward pass with the ATan surrogate (Eq. eq:surrogate_gradient), one pass over memory each.

Why numba: written as torch operations, one LIF step is three passes over a [B, N, D] tensor (charge, fire,
reset) and its backward pass seven more (the surrogate, then the membrane's chain rule), each reading and writing
the whole tensor; at the paper's size these tensors do not stay in the cache from one operation to the next. Here
each neuron's ``T`` steps run in registers: the forward pass reads the currents once and writes the spikes and the
surrogate derivative once; the backward pass reads the upstream gradient and the surrogate once and writes the
gradient of the currents once.

Layout: every array is ``[T, M]`` float32 and C-contiguous (``M`` = all neurons of the batch). The neurons are
cut into chunks of :data:`CHUNK`; each chunk runs its ``T`` steps over contiguous rows, which LLVM vectorizes.
The chunks are independent, so the result does not depend on how many threads share them: the same bits with
one thread or many.

The surrogate derivative is stored with the spike in its sign (``-g'`` where the neuron fired, ``+g'`` where it
did not; ``g' > 0`` always), so the backward pass needs no second saved tensor for the reset term.
"""

from __future__ import annotations

import threading

import numba
import numpy as np
from numba import prange

#: Neurons per chunk: a chunk's T x CHUNK floats of each array stay in the L2 cache while its steps run.
CHUNK = 8192

_JIT = dict(cache=True, error_model="numpy")        # numpy's division semantics: no zero check, so loops vectorize


@numba.njit(inline="always", **_JIT)
def _steps_forward(current, spikes, surrogate, v, lo, hi, tau, u_thr, k, half_alpha):
    """Neurons ``lo:hi``, all ``T`` steps from rest: charge, fire, hard reset (Eq. eq:LIF); ``v`` holds
    SpikingJelly's V."""
    # rows sliced as [t, lo:hi] of the C-contiguous arrays: numba knows them contiguous, so LLVM vectorizes
    v = v[lo:hi]
    v[:] = 0.0
    for t in range(current.shape[0]):
        c, s, g_out = current[t, lo:hi], spikes[t, lo:hi], surrogate[t, lo:hi]
        for j in range(c.size):
            # V - V/tau + I: SpikingJelly's charge with its rounding (== I + beta V), so spikes are bit-identical
            u = v[j] - v[j] / tau + c[j]
            x = (u - u_thr) * k
            g = half_alpha / (x * x + np.float32(1.0))       # g'(U - U_thr), Eq. (eq:surrogate_gradient)
            fire = u >= u_thr
            s[j] = np.float32(1.0) if fire else np.float32(0.0)
            g_out[j] = -g if fire else g                     # the spike in the sign
            v[j] = np.float32(0.0) if fire else u            # hard reset to 0


@numba.njit(inline="always", **_JIT)
def _steps_backward(grad_spikes, surrogate, grad_current, lo, hi, beta):
    """Neurons ``lo:hi``, the steps in reverse: dL/dU(t) = dL/dS(t) g'(t) + dL/dU(t+1) (1 - S(t)) beta."""
    T = grad_spikes.shape[0]
    last, gs, gi = surrogate[T - 1, lo:hi], grad_spikes[T - 1, lo:hi], grad_current[T - 1, lo:hi]
    for j in range(gs.size):
        gi[j] = gs[j] * abs(last[j])
    for t in range(T - 2, -1, -1):
        gs, g_t = grad_spikes[t, lo:hi], surrogate[t, lo:hi]
        gi, gi_next = grad_current[t, lo:hi], grad_current[t + 1, lo:hi]
        for j in range(gs.size):
            keep = beta if g_t[j] > 0 else np.float32(0.0)   # reset detached: no path through a fired neuron
            gi[j] = gs[j] * abs(g_t[j]) + gi_next[j] * keep


# Each pass twice, over numba's threads (prange) and on the calling thread (range): two functions, not one compiled
# twice, because numba's cache keys a function by its name and line, not by the parallel flag.
@numba.njit(parallel=True, **_JIT)
def _forward_parallel(current, spikes, surrogate, v, tau, u_thr, k, half_alpha):
    M = current.shape[1]
    for c in prange((M + CHUNK - 1) // CHUNK):
        _steps_forward(current, spikes, surrogate, v, c * CHUNK, min(M, (c + 1) * CHUNK), tau, u_thr, k, half_alpha)


@numba.njit(**_JIT)
def _forward_serial(current, spikes, surrogate, v, tau, u_thr, k, half_alpha):
    M = current.shape[1]
    for c in range((M + CHUNK - 1) // CHUNK):
        _steps_forward(current, spikes, surrogate, v, c * CHUNK, min(M, (c + 1) * CHUNK), tau, u_thr, k, half_alpha)


@numba.njit(parallel=True, **_JIT)
def _backward_parallel(grad_spikes, surrogate, grad_current, beta):
    M = grad_spikes.shape[1]
    for c in prange((M + CHUNK - 1) // CHUNK):
        _steps_backward(grad_spikes, surrogate, grad_current, c * CHUNK, min(M, (c + 1) * CHUNK), beta)


@numba.njit(**_JIT)
def _backward_serial(grad_spikes, surrogate, grad_current, beta):
    M = grad_spikes.shape[1]
    for c in range((M + CHUNK - 1) // CHUNK):
        _steps_backward(grad_spikes, surrogate, grad_current, c * CHUNK, min(M, (c + 1) * CHUNK), beta)


def _parallel(threads: int) -> bool:
    """Use numba's threads: more than one wanted, and called from the main thread (numba's default threading
    layer must not be entered by two threads at once, as a Dask worker's task threads would)."""
    if threads <= 1 or threading.current_thread() is not threading.main_thread():
        return False
    numba.set_num_threads(min(int(threads), numba.config.NUMBA_NUM_THREADS))
    return True


def lif_forward(current: np.ndarray, spikes: np.ndarray, surrogate: np.ndarray, v: np.ndarray, tau: float,
                u_thr: float, alpha: float, threads: int = 1) -> None:
    """Eq. (eq:LIF) from rest over all steps, written into ``spikes``, ``surrogate`` and ``v``.

    Parameters
    ----------
    current : float32 array [T, M]
        Input current I(t) of ``M`` neurons.
    spikes : float32 array [T, M]
        Out: S(t) in {0, 1}.
    surrogate : float32 array [T, M]
        Out: g'(U(t) - U_thr) (Eq. eq:surrogate_gradient), negated where S(t) = 1.
    v : float32 array [M]
        Out: SpikingJelly's membrane state V after the last step (0 where the neuron fired).
    tau, u_thr, alpha : float
        Time constant (beta = 1 - 1/tau), threshold, ATan steepness.
    threads : int
        Threads to share the neurons (the caller's torch threads); the result is the same for any number.
    """
    f32 = np.float32
    args = (current, spikes, surrogate, v, f32(tau), f32(u_thr), f32(np.pi / 2.0 * alpha), f32(alpha / 2.0))
    (_forward_parallel if _parallel(threads) else _forward_serial)(*args)


def lif_backward(grad_spikes: np.ndarray, surrogate: np.ndarray, grad_current: np.ndarray, beta: float,
                 threads: int = 1) -> None:
    """BPTT through :func:`lif_forward`: dL/dI(t) written into ``grad_current`` [T, M] (float32, like the inputs)."""
    (_backward_parallel if _parallel(threads) else _backward_serial)(grad_spikes, surrogate, grad_current,
                                                                     np.float32(beta))

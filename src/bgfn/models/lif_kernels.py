"""numba kernels of the fused LIF layer (:class:`bgfn.models.lif.FusedLIF`): Eq. (eq:LIF) over all ``T`` SNN steps
and its BPTT backward pass with the ATan surrogate (Eq. eq:surrogate_gradient), one pass over memory each.

Written as torch operations, one LIF step is several passes over a [B, N, D] tensor too large for the cache, so
memory traffic set the layer's cost. Here each neuron's ``T`` steps run in registers: the forward pass reads the
currents and writes the spikes once; the backward pass recomputes the potentials of a chunk in a cache-sized buffer
(the same arithmetic, so the same bits) and writes the currents' gradient once. Every array is ``[T, M]`` float32,
C-contiguous, cut into independent chunks of :data:`CHUNK` neurons: the same bits with one thread or many.
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
def _charge(v, current, tau):
    """U(t) = V - V/tau + I: SpikingJelly's charge with its rounding (== I + beta V), so spikes are bit-identical."""
    return v - v / tau + current


@numba.njit(inline="always", **_JIT)
def _steps_forward(current, spikes, v, lo, hi, tau, u_thr):
    """Neurons ``lo:hi``, all ``T`` steps from rest: charge, fire, hard reset to 0 (Eq. eq:LIF); ``v`` holds
    SpikingJelly's V."""
    # rows sliced as [t, lo:hi] of the C-contiguous arrays: numba knows them contiguous, so LLVM vectorizes
    v = v[lo:hi]
    v[:] = 0.0
    for t in range(current.shape[0]):
        c, s = current[t, lo:hi], spikes[t, lo:hi]
        for j in range(c.size):
            u = _charge(v[j], c[j], tau)
            fire = u >= u_thr
            s[j] = np.float32(1.0) if fire else np.float32(0.0)
            v[j] = np.float32(0.0) if fire else u


@numba.njit(inline="always", **_JIT)
def _steps_backward(current, grad_spikes, grad_current, lo, hi, tau, u_thr, k, half_alpha, beta):
    """Neurons ``lo:hi``: U(t) recomputed as in the forward pass, then the steps in reverse,
    dL/dU(t) = dL/dS(t) g'(U(t) - U_thr) + dL/dU(t+1) (1 - S(t)) beta (reset detached)."""
    T, n = current.shape[0], hi - lo
    u = np.empty((T, n), dtype=np.float32)         # this chunk's potentials: T x CHUNK floats, in the cache
    v = np.zeros(n, dtype=np.float32)
    for t in range(T):
        c, u_t = current[t, lo:hi], u[t]
        for j in range(n):
            u_t[j] = _charge(v[j], c[j], tau)
            v[j] = np.float32(0.0) if u_t[j] >= u_thr else u_t[j]
    for t in range(T - 1, -1, -1):
        gs, gi, u_t = grad_spikes[t, lo:hi], grad_current[t, lo:hi], u[t]
        if t == T - 1:                              # nothing after the last step
            for j in range(n):
                x = (u_t[j] - u_thr) * k
                gi[j] = gs[j] * (half_alpha / (x * x + np.float32(1.0)))       # g', Eq. (eq:surrogate_gradient)
        else:
            gi_next = grad_current[t + 1, lo:hi]
            for j in range(n):
                x = (u_t[j] - u_thr) * k
                keep = np.float32(0.0) if u_t[j] >= u_thr else beta            # no path through a fired neuron
                gi[j] = gs[j] * (half_alpha / (x * x + np.float32(1.0))) + gi_next[j] * keep


# Each pass twice, over numba's threads (prange) and on the calling thread (range): two functions, not one compiled
# twice, because numba's cache keys a function by its name and line, not by the parallel flag.
@numba.njit(parallel=True, **_JIT)
def _forward_parallel(current, spikes, v, tau, u_thr):
    M = current.shape[1]
    for c in prange((M + CHUNK - 1) // CHUNK):
        _steps_forward(current, spikes, v, c * CHUNK, min(M, (c + 1) * CHUNK), tau, u_thr)


@numba.njit(**_JIT)
def _forward_serial(current, spikes, v, tau, u_thr):
    M = current.shape[1]
    for c in range((M + CHUNK - 1) // CHUNK):
        _steps_forward(current, spikes, v, c * CHUNK, min(M, (c + 1) * CHUNK), tau, u_thr)


@numba.njit(parallel=True, **_JIT)
def _backward_parallel(current, grad_spikes, grad_current, tau, u_thr, k, half_alpha, beta):
    M = current.shape[1]
    for c in prange((M + CHUNK - 1) // CHUNK):
        _steps_backward(current, grad_spikes, grad_current, c * CHUNK, min(M, (c + 1) * CHUNK), tau, u_thr, k,
                        half_alpha, beta)


@numba.njit(**_JIT)
def _backward_serial(current, grad_spikes, grad_current, tau, u_thr, k, half_alpha, beta):
    M = current.shape[1]
    for c in range((M + CHUNK - 1) // CHUNK):
        _steps_backward(current, grad_spikes, grad_current, c * CHUNK, min(M, (c + 1) * CHUNK), tau, u_thr, k,
                        half_alpha, beta)


def _parallel(threads: int) -> bool:
    """Use numba's threads: more than one wanted, and called from the main thread (numba's default threading
    layer must not be entered by two threads at once, as a Dask worker's task threads would)."""
    if threads <= 1 or threading.current_thread() is not threading.main_thread():
        return False
    numba.set_num_threads(min(int(threads), numba.config.NUMBA_NUM_THREADS))
    return True


def lif_forward(current: np.ndarray, spikes: np.ndarray, v: np.ndarray, tau: float, u_thr: float,
                threads: int = 1) -> None:
    """Eq. (eq:LIF) from rest over all steps, written into ``spikes`` and ``v``.

    Parameters
    ----------
    current : float32 array [T, M]
        Input current I(t) of ``M`` neurons.
    spikes : float32 array [T, M]
        Out: S(t) in {0, 1}.
    v : float32 array [M]
        Out: SpikingJelly's membrane state V after the last step (0 where the neuron fired).
    tau, u_thr : float
        Time constant (beta = 1 - 1/tau) and threshold.
    threads : int
        Threads to share the neurons (the caller's torch threads); the result is the same for any number.
    """
    (_forward_parallel if _parallel(threads) else _forward_serial)(current, spikes, v, np.float32(tau),
                                                                   np.float32(u_thr))


def lif_backward(current: np.ndarray, grad_spikes: np.ndarray, grad_current: np.ndarray, tau: float, u_thr: float,
                 alpha: float, beta: float, threads: int = 1) -> None:
    """BPTT through :func:`lif_forward` on the same ``current`` [T, M]: dL/dI(t) written into ``grad_current``
    [T, M] (float32, like the inputs) from dL/dS(t) in ``grad_spikes``; ``alpha`` is the ATan steepness, ``beta``
    the decay factor of ``tau`` (:func:`bgfn.models.lif.beta_from_tau`)."""
    f32 = np.float32
    (_backward_parallel if _parallel(threads) else _backward_serial)(
        current, grad_spikes, grad_current, f32(tau), f32(u_thr), f32(np.pi / 2.0 * alpha), f32(alpha / 2.0),
        f32(beta))

"""LIF neurons of the paper (Eq. eq:LIF) on SpikingJelly, with the ATan surrogate (Eq. eq:surrogate_gradient).

SpikingJelly's ``LIFNode(decay_input=False, v_reset=0)`` is the paper's recursion: its ``H[t]`` is the paper's
``U(t)``, its input ``X[t]`` the paper's ``I(t)``, and ``beta = 1 - 1/tau`` (tau = 2: beta = 0.5, Spikformer's
setting); :func:`lif_reference` writes the paper's equation out literally and the tests check the node against it.
The backward pass uses the ATan surrogate's derivative (:func:`atan_surrogate_grad`); training is BPTT through the
``T_s`` SNN steps. :class:`FusedLIFNode` runs the multi-step pass on the CPU as one autograd node whose forward and
backward passes are numba kernels (:mod:`bgfn.models.lif_kernels`): SpikingJelly's many small operations per step
made BGFN train many times slower than its ANN twin. Spikes are bit-identical, gradients equal within float32
rounding; on CUDA, or for a setting it does not cover, it falls back to SpikingJelly's own implementation.
"""

from __future__ import annotations

import math

import torch
from spikingjelly.activation_based import neuron, surrogate

from . import lif_kernels

#: Membrane time constant of every LIF layer (SpikingJelly ``tau``); beta = 1 - 1/tau = 0.5.
DEFAULT_TAU = 2.0
#: Firing threshold U_thr of the LIF layers.
DEFAULT_THRESHOLD = 1.0
#: Threshold of the LIF after the attention product (Spikformer uses half the common threshold).
DEFAULT_ATTN_THRESHOLD = 0.5
#: Steepness alpha of the ATan surrogate (SpikingJelly's default).
DEFAULT_ALPHA = 2.0


def beta_from_tau(tau: float) -> float:
    """Decay factor beta of Eq. (eq:LIF) for a SpikingJelly time constant ``tau`` (``decay_input=False``)."""
    return 1.0 - 1.0 / tau


def tau_from_beta(beta: float) -> float:
    """SpikingJelly time constant for the paper's decay factor ``beta`` in (0, 1)."""
    if not 0.0 < beta < 1.0:
        raise ValueError(f"beta must lie in (0, 1), got {beta}")
    return 1.0 / (1.0 - beta)


class FusedLIF(torch.autograd.Function):
    """Eq. (eq:LIF) over all ``T`` steps as one autograd node (hard reset to 0, reset gradient detached).

    Forward, from H(0) = 0: ``U(t) = H(t-1) + I(t)``, ``S(t) = [U(t) >= U_thr]``, ``H(t) = (1 - S(t)) beta U(t)``.
    Backward (``S`` in the reset term is detached, as SpikingJelly's ``detach_reset=True``)::

        dL/dU(t) = dL/dS(t) g'(U(t) - U_thr) + dL/dU(t+1) (1 - S(t)) beta,     dL/dI(t) = dL/dU(t)

    with ``g'`` the ATan surrogate derivative (Eq. eq:surrogate_gradient). Both passes are the numba kernels of
    :mod:`bgfn.models.lif_kernels` (float32 on the CPU); the backward pass recomputes U(t) from the saved currents.
    """

    @staticmethod
    def forward(ctx, current: torch.Tensor, tau: float, u_thr: float, alpha: float):    # current [T, ...]
        T = current.shape[0]
        cur = current.detach().contiguous().view(T, -1)                                # [T, M]
        spikes, v = torch.empty_like(cur), torch.empty_like(cur[0])                    # [T, M]; SpikingJelly's V
        lif_kernels.lif_forward(cur.numpy(), spikes.numpy(), v.numpy(), tau, u_thr, threads=torch.get_num_threads())
        ctx.save_for_backward(cur)              # the backward pass recomputes U(t) from the currents
        ctx.params = (tau, u_thr, alpha, beta_from_tau(tau))
        ctx.mark_non_differentiable(v)          # the state between calls; every forward pass starts at rest
        ctx.set_materialize_grads(False)        # v has no gradient: no [B, N, D] of zeros for it in each backward
        return spikes.view(current.shape), v.view(current.shape[1:])   # spikes, SpikingJelly's v after the last step

    @staticmethod
    def backward(ctx, grad_spikes: torch.Tensor, grad_v: None):   # spikes: the one differentiable output
        (cur,) = ctx.saved_tensors                                                     # [T, M]
        grad = grad_spikes.contiguous().view(cur.shape)
        grad_current = torch.empty_like(cur)
        lif_kernels.lif_backward(cur.numpy(), grad.numpy(), grad_current.numpy(), *ctx.params,
                                 threads=torch.get_num_threads())
        return grad_current.view(grad_spikes.shape), None, None, None


class FusedLIFNode(neuron.LIFNode):
    """SpikingJelly's multi-step ``LIFNode`` whose CPU pass is :class:`FusedLIF` (module docstring).

    It is a ``LIFNode`` (hooks, ``reset_net``, firing-rate and energy counts see it as one); the fused pass
    runs for float32 currents when the membrane starts from rest (after a reset) and the layer is the paper's
    (hard reset to 0, ``decay_input=False``, ATan surrogate, detached reset, no stored potential sequence);
    otherwise, and on CUDA, SpikingJelly's own implementation runs.
    """

    def _fusable(self, x_seq: torch.Tensor) -> bool:
        v = self._memories.get("v")
        return (not x_seq.is_cuda and x_seq.dtype == torch.float32 and isinstance(v, float) and v == 0.0
                and self.v_reset == 0.0 and not self.decay_input and self.detach_reset and not self.store_v_seq
                and isinstance(self.surrogate_function, surrogate.ATan)
                and getattr(self, "_neuron_precision", None) is None)

    def multi_step_forward(self, x_seq: torch.Tensor, *args, **kwargs):
        if args or kwargs or not self._fusable(x_seq):
            return super().multi_step_forward(x_seq, *args, **kwargs)
        spikes, v = FusedLIF.apply(x_seq, float(self.tau), float(self.v_threshold),
                                   float(self.surrogate_function.alpha))
        self._memories["v"] = v
        return spikes


def make_lif(tau: float = DEFAULT_TAU, v_threshold: float = DEFAULT_THRESHOLD, alpha: float = DEFAULT_ALPHA,
             detach_reset: bool = True, fused: bool = True) -> neuron.LIFNode:
    """A multi-step LIF layer of Eq. (eq:LIF): input ``[T, ...]`` currents, output ``[T, ...]`` spikes in {0, 1}.

    Parameters
    ----------
    tau : float
        Membrane time constant (> 1); beta = 1 - 1/tau.
    v_threshold : float
        Firing threshold U_thr.
    alpha : float
        Steepness of the ATan surrogate gradient, Eq. (eq:surrogate_gradient).
    detach_reset : bool
        Stop the gradient through the reset term (as in Spikformer/SeqSNN); the forward pass is unchanged.
    fused : bool
        :class:`FusedLIFNode` (default; the same dynamics, faster on the CPU) or SpikingJelly's ``LIFNode``.
    """
    node = FusedLIFNode if fused else neuron.LIFNode
    return node(tau=float(tau), decay_input=False, v_threshold=float(v_threshold), v_reset=0.0,
                          surrogate_function=surrogate.ATan(alpha=float(alpha)), detach_reset=detach_reset,
                          step_mode="m")


def lif_reference(current: torch.Tensor, beta: float, u_thr: float = DEFAULT_THRESHOLD,
                  v_reset: float = 0.0) -> tuple[torch.Tensor, torch.Tensor]:
    """The paper's Eq. (eq:LIF), step by step, starting from H(0) = 0.

    Parameters
    ----------
    current : Tensor, shape [T, ...]
        Input current I(t).
    beta, u_thr, v_reset : float
        Decay factor, threshold and reset potential.

    Returns
    -------
    spikes : Tensor, shape [T, ...]
        S(t) in {0, 1}.
    potential : Tensor, shape [T, ...]
        U(t) before the reset.
    """
    h = torch.zeros_like(current[0])
    spikes, potential = [], []
    for i_t in current:
        u = h + i_t                                   # U(t) = H(t - dt) + I(t)
        s = (u >= u_thr).to(current.dtype)            # S(t) = Heaviside(U - U_thr)
        h = v_reset * s + (1.0 - s) * beta * u        # H(t) = V_reset S + (1 - S) beta U
        spikes.append(s)
        potential.append(u)
    return torch.stack(spikes), torch.stack(potential)


def atan_surrogate_grad(x: torch.Tensor, alpha: float = DEFAULT_ALPHA) -> torch.Tensor:
    """Derivative of Eq. (eq:surrogate_gradient) ``arctan(pi/2 alpha x)/pi + 1/2`` at ``x = U - U_thr``."""
    return alpha / (2.0 * (1.0 + (math.pi / 2.0 * alpha * x) ** 2))


def lif_modules(model: torch.nn.Module) -> list[neuron.LIFNode]:
    """All LIF layers of ``model`` (for spike hooks and firing-rate counts)."""
    return [m for m in model.modules() if isinstance(m, neuron.LIFNode)]

"""Forward passes over the evaluation windows in the network's inference form (BatchNorm folded), as every
energy measurement runs them; the spike predicates the counting rules test.
"""

from __future__ import annotations

import copy
from typing import Callable, Iterable

import numpy as np
import torch
from spikingjelly.activation_based import functional, neuron
from torch import nn
from torch.nn.utils.fusion import fuse_conv_bn_eval, fuse_linear_bn_eval


# ---------------------------------------------------------------------------------------------------
# BatchNorm folding: the inference form of a network, in which BatchNorm costs nothing.
# ---------------------------------------------------------------------------------------------------
def fold_batchnorm(model: nn.Module) -> nn.Module:
    """A copy of ``model`` (eval mode) with every BatchNorm folded into the Linear/Conv registered just before it.

    ``W' = W * g / sqrt(var + eps)``, ``b' = (b - mean) * g / sqrt(var + eps) + beta`` (exact at inference);
    the BatchNorm is replaced by ``nn.Identity``. A BatchNorm without such a predecessor is left in place.
    """
    m = copy.deepcopy(model).eval()
    for parent in m.modules():
        names = list(parent._modules)
        for prev, cur in zip(names[:-1], names[1:]):
            a, b = parent._modules[prev], parent._modules[cur]
            if not isinstance(b, nn.modules.batchnorm._BatchNorm) or not b.track_running_stats:
                continue
            if isinstance(a, nn.Linear) and a.out_features == b.num_features:
                parent._modules[prev] = fuse_linear_bn_eval(a, b)
            elif isinstance(a, (nn.Conv1d, nn.Conv2d, nn.Conv3d)) and a.out_channels == b.num_features:
                parent._modules[prev] = fuse_conv_bn_eval(a, b)
            else:
                continue
            parent._modules[cur] = nn.Identity()
    return m


# ---------------------------------------------------------------------------------------------------
# Forward passes over the evaluation windows, as every energy measurement runs them.
# ---------------------------------------------------------------------------------------------------
#: Module types whose output is spikes: SpikingJelly's neurons (BGFN's LIF layers, :mod:`bgfn.models.lif`).
SPIKE_MODULES: tuple[type, ...] = (neuron.BaseNode,)


def as_tensor(windows) -> torch.Tensor:
    """Windows [M, N, C] (ndarray, tensor or anything with ``.x``) as a float32 tensor."""
    x = getattr(windows, "x", windows)
    return torch.as_tensor(np.asarray(x) if not torch.is_tensor(x) else x, dtype=torch.float32)


def batches(windows, batch_size: int) -> Iterable[torch.Tensor]:
    """Consecutive batches [<= batch_size, N, C] of ``windows``.

    Raises
    ------
    ValueError
        No window: a rate or a count per prediction needs at least one.
    """
    x = as_tensor(windows)
    if len(x) == 0:
        raise ValueError("no evaluation windows: the firing rates need at least one window")
    for i in range(0, len(x), batch_size):
        yield x[i:i + batch_size]


def reset_membranes(model: nn.Module) -> None:
    """Membrane potentials of every LIF layer back to 0 (a batch never sees the previous batch's state)."""
    functional.reset_net(model)


def is_spiking_model(model: nn.Module) -> bool:
    """True for a spiking network (its class says ``spiking = True``, as :class:`bgfn.models.bgfn.BGFN`)."""
    return bool(getattr(model, "spiking", False))


def is_spike_count(x: torch.Tensor) -> bool:
    """True if ``x`` holds spike counts: non-negative integers (binary spikes, or sums of spike trains)."""
    if x.dtype == torch.bool:
        return True
    if not x.dtype.is_floating_point:
        return bool((x >= 0).all())
    return bool(((x >= 0) & (x == torch.round(x))).all())


def is_binary(x: torch.Tensor) -> bool:
    """True if every entry of ``x`` is 0 or 1 (one spike train, not a sum of several)."""
    return bool((x.eq(0) | x.eq(1)).all())


@torch.no_grad()
def run_batches(model: nn.Module, windows, batch_size: int, hooks: list, reset: bool = True,
                before_batch: Callable[[torch.Tensor], None] | None = None) -> None:
    """Run ``model`` over ``windows`` in eval mode, then remove ``hooks`` and restore its training mode.

    Parameters
    ----------
    model : nn.Module
        The model the ``hooks`` (handles of ``register_forward_hook`` & co.) are registered on.
    windows : array [M, N, C] or WindowSet-like
        Normalized input windows.
    batch_size : int
        Windows per forward pass.
    hooks : list of RemovableHandle
        Removed when the passes end, also on an error.
    reset : bool
        Reset the membranes before every batch and after the last (spiking models).
    before_batch : callable, optional
        Called with every batch [B, N, C] before its forward pass (book-keeping of the batch size).
    """
    was_training = model.training
    model.eval()
    try:
        for xb in batches(windows, batch_size):
            if before_batch is not None:
                before_batch(xb)
            if reset:
                reset_membranes(model)
            model(xb)
        if reset:
            reset_membranes(model)
    finally:
        for h in hooks:
            h.remove()
        model.train(was_training)

"""Firing rates of BGFN's spiking (LIF) layers on the evaluation windows.

The rate of a LIF layer is the fraction of ones of its output: spikes / (T_s * windows * tokens * neurons).
These are the *output* rates of the neurons, shown per layer in notebook 05; the energy itself uses the
*input* rate of every spike-driven layer, which :func:`bgfn.energy.counts.layer_counts` measures on the same
passes.
"""

from __future__ import annotations

import pandas as pd
import torch
from torch import nn

from bgfn.energy.passes import SPIKE_MODULES, run_batches


@torch.no_grad()
def measure_firing_rates(model: nn.Module, windows, batch_size: int = 32) -> dict[str, float]:
    """Firing rate of every spiking (LIF) layer: fraction of ones of its output over all windows.

    Parameters
    ----------
    model : nn.Module
        A spiking model (its LIF layers are SpikingJelly ``BaseNode`` subclasses); evaluated in eval mode.
    windows : array [M, N, C] or WindowSet-like (``.x``)
        Normalized input windows (the evaluation windows).
    batch_size : int
        Windows per forward pass; membrane potentials are reset between batches.

    Returns
    -------
    dict
        Module path (``'blocks.0.attn.q.lif'``) -> rate in [0, 1] = spikes / (T * B * neurons), pooled over
        all windows, in execution order.
    """
    sums: dict[str, float] = {}
    counts: dict[str, int] = {}

    def hook(name):
        def fn(_mod, _inp, out):                 # out: spikes [T, B, ...]
            out = out.detach()
            sums[name] = sums.get(name, 0.0) + float(out.double().sum())
            counts[name] = counts.get(name, 0) + out.numel()
        return fn

    hooks = [mod.register_forward_hook(hook(name)) for name, mod in model.named_modules()
             if isinstance(mod, SPIKE_MODULES)]
    if not hooks:
        raise ValueError(f"{type(model).__name__} has no spiking (SpikingJelly neuron) layer")
    run_batches(model, windows, batch_size, hooks)
    return {k: sums[k] / counts[k] for k in sums}


def rates_table(rates: dict[str, float]) -> pd.DataFrame:
    """:func:`measure_firing_rates` as a one-column table ``firing_rate`` indexed by ``LIF layer``."""
    return pd.Series(rates, name="firing_rate").rename_axis("LIF layer").to_frame()

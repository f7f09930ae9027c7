"""Counting operations: MACs and SOPs of every counted layer per prediction (:class:`LayerCount`), the firing
rates of the LIF layers on the evaluation windows, and the analytic sweeps over the mean rate and T_s.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Callable

import numpy as np
import pandas as pd
import torch
from torch import nn

from bgfn.energy.passes import SPIKE_MODULES, is_spiking_model, run_batches
from bgfn.energy.rules import (COUNTED, E_AC_PJ, E_MAC_PJ, LayerSums, Tally, check_supported, count_linear_or_conv,
                               count_softmax_attention, count_spiking_self_attention, ssa_dense_ops, ssa_sops)
from bgfn.models import build_model
from bgfn.models.baselines import TwinBlock
from bgfn.models.bgfn import SSA, Block


# ---------------------------------------------------------------------------------------------------
# MACs and SOPs of every counted layer, per prediction: :class:`LayerCount` and :func:`layer_counts`.
# ---------------------------------------------------------------------------------------------------
@dataclass
class LayerCount:
    """Operations of one layer, per prediction (one window).

    Attributes
    ----------
    name : str
        Module path (``blocks.0.attn.q.linear``); attention products are ``<block>.attn.qkv_matmul`` (BGFN)
        and ``<block>.attention`` (twin).
    kind : str
        ``'linear'``, ``'conv'``, ``'ssa'`` (spiking attention products) or ``'attention'`` (ANN attention).
    spiking : bool
        Driven by spikes (counted as SOPs) or by real values (MACs).
    time_steps : int
        T of the spike input (1 for real-valued layers).
    dense : float
        Operations per prediction if every input were active: ``T * FLOPs`` (MACs for real-valued layers).
    rate : float
        Input spike rate in [0, 1]: spikes per input neuron and time step of each of the ``trains`` spike
        trains the input merges (1.0 for real-valued layers; for ``'ssa'`` the effective rate
        ``sops / dense``).
    trains : int
        Number of binary spike trains summed into the input: 1, except for the layers reading the residual
        stream of the spiking Transformer (``1 + 2 l`` for Q/K/V of block ``l``, ``2 + 2 l`` for its first
        MLP layer). ``sops = trains * rate * dense`` (Spikformer counts a residual value ``k`` as ``k`` spikes).
    macs, sops : float
        Multiply-accumulates and synaptic operations per prediction (ops).
    geometry : dict
        ``'ssa'``: ``T, H, N, dh`` and the rates ``rate_q, rate_k, rate_v``; ``exact_sops`` = the count
        SpikingJelly's counter reports for the two products (nonzero products of two binary matrices, spikes
        times fan-out for a spike matrix times an integer one), for the cross-check.
    """

    name: str
    kind: str
    spiking: bool
    time_steps: int
    dense: float
    rate: float
    macs: float
    sops: float
    geometry: dict = field(default_factory=dict)
    trains: int = 1


# ----------------------------------------------------------------------------------------------- sums -> rows
def _ssa_row(s: LayerSums) -> LayerCount:
    """Spiking self-attention products: Spikformer's formula with the mean Q, K, V rates."""
    rq, rk, rv = (s.qkv / s.qkv_numel).tolist()
    g = s.geometry
    dense = ssa_dense_ops(g["T"], g["H"], g["N"], g["dh"])
    sops = ssa_sops(g["T"], g["H"], g["N"], g["dh"], rq, rk, rv)
    geometry = {**g, "rate_q": rq, "rate_k": rk, "rate_v": rv, "exact_sops": s.exact / max(s.preds, 1)}
    return LayerCount(s.name, "ssa", True, g["T"], dense, sops / dense if dense else 0.0, 0.0, sops, geometry)


def _spike_driven_row(s: LayerSums) -> LayerCount:
    """A layer reading spikes: ``sops = (input spikes per neuron and step) * T * FLOPs``."""
    count_rate = s.in_sum / s.in_numel if s.in_numel else 0.0     # spikes per input neuron and step, all trains
    dense = s.dense / max(s.preds, 1)
    return LayerCount(s.name, s.kind, True, s.time_steps, dense, count_rate / s.trains, 0.0, count_rate * dense,
                      trains=s.trains)


def _dense_row(s: LayerSums) -> LayerCount:
    """A layer reading real values: every operation is a MAC."""
    dense = s.dense / max(s.preds, 1)
    return LayerCount(s.name, s.kind, False, 1, dense, 1.0, dense, 0.0)


def _row(s: LayerSums) -> LayerCount:
    if s.kind == "ssa":
        return _ssa_row(s)
    return _spike_driven_row(s) if s.spiking else _dense_row(s)


# ----------------------------------------------------------------------------------------------- counting pass
def _install_rules(model: nn.Module, tally: Tally) -> list:
    """Register the rule of every block kind of ``model`` (:mod:`bgfn.energy.rules`); returns the hooks."""
    hooks = []
    for name, mod in model.named_modules():
        if tally.spiking_model and isinstance(mod, Block):
            hooks += tally.stream.follow(name, mod)
        if isinstance(mod, SSA):
            hooks += count_spiking_self_attention(tally, name, mod)
        elif isinstance(mod, TwinBlock):
            hooks += count_softmax_attention(tally, name, mod)
        if isinstance(mod, COUNTED):
            hooks += count_linear_or_conv(tally, name, mod)
    return hooks


@torch.no_grad()
def layer_counts(model: nn.Module, windows, batch_size: int = 32) -> list[LayerCount]:
    """MACs and SOPs of every counted layer of ``model`` per prediction, on ``windows``.

    Parameters
    ----------
    model : nn.Module
        BGFN, its Transformer twin, or any model of Linear/Conv/LIF/SSA layers (others raise ValueError).
    windows : array [M, N, C] or WindowSet-like
        Normalized evaluation windows.
    batch_size : int
        Windows per forward pass.

    Returns
    -------
    list of LayerCount
        In execution order; an attention row comes right before the output projection of its block.
    """
    check_supported(model)
    tally = Tally(is_spiking_model(model))
    hooks = _install_rules(model, tally)
    run_batches(model, windows, batch_size, hooks, reset=tally.spiking_model, before_batch=tally.start_batch)
    return [_row(s) for s in tally.layers.values()]


# ----------------------------------------------------------------------------------------------- rates
def with_rates(structure: list[LayerCount], rates_from: list[LayerCount], scale: float = 1.0) -> list[LayerCount]:
    """Counts of ``structure`` (shapes, T) with the input rates of ``rates_from`` (same layer names), times ``scale``.

    Used by the analytic sweeps: the shapes come from a model with another ``T_s``, the rates (and which
    layers are spike-driven) from the trained model. Rates are not clipped (a residual input can carry
    more than one spike per neuron and step).
    """
    src = {c.name: c for c in rates_from}
    out = []
    for c in structure:
        if c.name not in src:
            raise KeyError(f"no measured rate for layer {c.name!r}")
        s = src[c.name]
        if not s.spiking:                  # real-valued input in the trained model: dense MACs
            out.append(replace(c, spiking=False, time_steps=1, rate=1.0, macs=c.dense, sops=0.0, trains=1))
            continue
        if c.kind == "ssa":
            g = c.geometry
            rq, rk, rv = (scale * s.geometry[k] for k in ("rate_q", "rate_k", "rate_v"))
            sops = ssa_sops(g["T"], g["H"], g["N"], g["dh"], rq, rk, rv)
            out.append(replace(c, rate=sops / c.dense if c.dense else 0.0, sops=sops,
                               geometry={**g, "rate_q": rq, "rate_k": rk, "rate_v": rv, "exact_sops": float("nan")}))
        else:
            rate = scale * s.rate
            out.append(replace(c, rate=rate, sops=rate * c.trains * c.dense))
    return out


def mean_rate(counts: list[LayerCount]) -> float:
    """Effective mean input rate of the spike-driven layers: ``sum(sops) / sum(trains * dense)``."""
    dense = sum(c.trains * c.dense for c in counts if c.spiking)
    return sum(c.sops for c in counts if c.spiking) / dense if dense else float("nan")


# ---------------------------------------------------------------------------------------------------
# Firing rates of BGFN's spiking (LIF) layers on the evaluation windows.
# ---------------------------------------------------------------------------------------------------
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


# ---------------------------------------------------------------------------------------------------
# Analytic sweeps around the trained model: the reduction against the twin as a function of the mean firing
# ---------------------------------------------------------------------------------------------------
def _energy_pj(counts: list[LayerCount], e_mac: float, e_ac: float) -> float:
    """Energy per prediction, pJ: the per-layer energies summed."""
    return sum(e_mac * c.macs + e_ac * c.sops for c in counts)


def reduction_vs_rate(snn_counts: list[LayerCount], ann_counts: list[LayerCount], rates,
                      e_mac: float = E_MAC_PJ, e_ac: float = E_AC_PJ) -> pd.DataFrame:
    """Reduction (%) if every spike rate of the SNN were scaled so that the mean rate is ``r`` (analytic).

    ``E_snn(r) = e_mac * MACs + e_ac * r * sum(trains * dense)`` (all SOP terms, the SSA's included, are
    linear in a common rate scale). Returns ``mean_firing_rate, energy_uj, reduction_pct``; ``break_even_rate`` (the
    rate at which the SNN costs as much as the ANN) is in ``.attrs``.
    """
    macs = sum(c.macs for c in snn_counts)
    dense = sum(c.trains * c.dense for c in snn_counts if c.spiking)
    e_ann = _energy_pj(ann_counts, e_mac, e_ac)
    r = np.asarray(rates, float)
    e = e_mac * macs + e_ac * r * dense
    df = pd.DataFrame({"mean_firing_rate": r, "energy_uj": e * 1e-6, "reduction_pct": 100.0 * (1.0 - e / e_ann)})
    df.attrs["break_even_rate"] = (e_ann - e_mac * macs) / (e_ac * dense) if dense else float("nan")
    return df


def same_size_builder(size_cfgs: dict[str, dict], in_channels: int, seed: int = 0,
                      methods: tuple[str, str] = ("bgfn", "transformer")
                      ) -> Callable[[int], tuple[nn.Module, nn.Module]]:
    """``build(T_s) -> (snn, ann)``: untrained models of the trained sizes with ``T_s`` time steps.

    Parameters
    ----------
    size_cfgs : dict
        Method -> size configuration of the trained model (``TrainedModel.size_cfg``).
    in_channels : int
        Input channels per IMU sample.
    seed : int
        Torch seed set before building (the weights do not matter for the counts, only the shapes).
    methods : (str, str)
        The SNN and the ANN method ids.
    """
    def build(ts: int):
        torch.manual_seed(seed)
        return tuple(build_model(m, {**size_cfgs[m], "time_steps": ts}, in_channels=in_channels) for m in methods)

    return build


def reduction_vs_time_steps(build: Callable[[int], tuple[nn.Module, nn.Module]], windows,
                            rates_from: list[LayerCount], time_steps, e_mac: float = E_MAC_PJ,
                            e_ac: float = E_AC_PJ) -> pd.DataFrame:
    """Reduction (%) as a function of ``T_s``, with the trained model's per-layer spike rates held fixed.

    Parameters
    ----------
    build : callable
        ``build(T_s) -> (snn, ann)``: untrained models of the same size with ``T_s`` time steps (only their
        shapes are used; :func:`same_size_builder`).
    windows : array [M, N, C]
        A few windows (shapes only; one is enough).
    rates_from : list of LayerCount
        :func:`bgfn.energy.counts.layer_counts` of the trained SNN (its input rates, by layer name).
    time_steps : iterable of int
    e_mac, e_ac : float
        Energy per MAC and per accumulate, pJ.

    Returns
    -------
    DataFrame
        ``time_steps, snn_energy_uj, ann_energy_uj, reduction_pct``.
    """
    out = []
    for ts in time_steps:
        snn, ann = build(int(ts))
        s = with_rates(layer_counts(snn, windows), rates_from)
        a = layer_counts(ann, windows)
        es, ea = _energy_pj(s, e_mac, e_ac), _energy_pj(a, e_mac, e_ac)
        out.append({"time_steps": int(ts), "snn_energy_uj": es * 1e-6, "ann_energy_uj": ea * 1e-6,
                    "reduction_pct": 100.0 * (1.0 - es / ea)})
    return pd.DataFrame(out)

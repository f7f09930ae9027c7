"""Theoretical inference energy of BGFN and of its ANN Transformer twin on 45 nm CMOS (paper Sec. 4.2).

The paper states that BGFN needs much less energy (its figure: `data/paper/claims.yaml`) than a conventional Transformer "on a 45 nm
neuromorphic hardware platform" (Horowitz 2014). It gives no counting rule; we use the one of Spikformer
(Zhou et al. 2023) and of the syops counter that SeqSNN (Lv et al. 2024, the code BGFN builds on) uses:

* every multiply-accumulate of a layer with real-valued input costs ``E_MAC`` (4.6 pJ, 32-bit float:
  3.7 pJ multiply + 0.9 pJ add), every synaptic operation driven by a spike costs ``E_AC`` (0.9 pJ add);
* a Linear/Conv layer whose input is a spike tensor ``[T, B, ...]`` does, per prediction::

      SOP = r_in * T * FLOPs            (FLOPs = multiply-accumulates of one time step when every input is 1)

  with ``r_in`` the *input* spike rate (spikes per input neuron and time step, measured on the evaluation
  windows). Because ``r_in * T * FLOPs = (number of input spikes) * fan-out``, this is the exact number of
  weight accumulations an event-driven chip performs;
* the first layer (the convolutional spike encoder, Eq. eq:spike_input) reads real-valued IMU samples and
  counts as dense MACs, as does the readout ``head`` (it reads the mean of the spikes);
* residual additions make the block inputs spike *counts* (0, 1, 2, ...): the input of Q/K/V of block ``l``
  sums ``n = 1 + 2 l`` binary spike trains (embedding, then each block's attention and MLP outputs), that of
  its first MLP layer ``n = 2 + 2 l``. As in Spikformer/syops (``Nspks_max = 30``) a count ``k`` is ``k``
  spikes: ``SOP = n * r_in * T * FLOPs`` with ``r_in = sum(input) / (n * numel(input))`` the mean firing rate
  of the ``n`` merged trains (in [0, 1]; equal to W a + W b computed as two spike-driven passes);
* spiking self-attention (no softmax) per block, with ``H`` heads of width ``d_h``, ``N`` tokens, ``T`` steps
  and the Q, K, V firing rates ``r_q, r_k, r_v`` (fractions of ones of the LIF outputs), in the order BGFN
  evaluates it (``SSA.attend``)::

      d_h <  N  (Q (K^T V)):  SOP_attn = (min(r_k, r_v) + r_q) * T * H * N * d_h^2
      d_h >= N  ((Q K^T) V):  SOP_attn = (min(r_q, r_k) + r_v) * T * H * N^2 * d_h

  This is Spikformer's ``energy_consumption_calculation`` formula (``T * H * N * d_h^2 * (min(fr_k, fr_v) +
  fr_q)``): the product of two spike matrices is driven by the sparser one (each of its spikes adds one
  row/column of the other, ``d_h`` or ``N`` accumulates), the product of a spike matrix with the integer
  matrix ``K^T V`` (or ``Q K^T``) by the spikes of ``Q`` (or ``V``);
* BatchNorm is folded into the preceding Linear/Conv (exact at inference: :func:`fold_batchnorm`), so it costs
  nothing; biases, LIF membrane updates, residual additions, LayerNorm, softmax, GELU and memory traffic are
  not counted, for either model (Spikformer's convention: only synaptic operations / matmuls);
* the ANN twin (:class:`bgfn.models.baselines.TransformerTwin`) costs ``E_MAC`` per multiply-accumulate of
  every matmul, attention included: ``Q K^T`` and ``A V`` are ``N^2 * D`` MACs each per block.

``E = E_MAC * MACs + E_AC * SOPs`` per prediction (one window), reported in microjoules.

API
---
:func:`measure_firing_rates` (rates of every LIF layer), :func:`layer_counts` (per-layer MACs/SOPs),
:func:`energy_table` (the DataFrame ``model, layer, firing_rate, macs, sops, energy_uj`` with a ``total``
row), :func:`reduction_pct`, the analytic sweeps :func:`reduction_vs_rate` and :func:`reduction_vs_time_steps`,
and the cross-check with SpikingJelly 2.0's operation counter :func:`spikingjelly_counts`.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass, field, replace
from typing import Callable, Iterable

import numpy as np
import pandas as pd
import torch
from torch import nn

from bgfn.models.baselines import TwinBlock
from bgfn.models.bgfn import SSA, Block

#: Horowitz (2014), 45 nm, 32-bit float: multiply 3.7 pJ + add 0.9 pJ (pJ per MAC).
E_MAC_PJ = 4.6
#: Horowitz (2014), 45 nm, 32-bit float add (pJ per accumulate / synaptic operation).
E_AC_PJ = 0.9
#: Columns of :func:`energy_table` (and of ``results/<profile>/tables/energy.csv``).
COLUMNS = ("model", "layer", "firing_rate", "macs", "sops", "energy_uj")


# ----------------------------------------------------------------------------------------------- helpers
def _as_tensor(windows) -> torch.Tensor:
    """Windows [M, N, C] (ndarray, tensor or anything with ``.x``) as a float32 tensor."""
    x = getattr(windows, "x", windows)
    return torch.as_tensor(np.asarray(x) if not torch.is_tensor(x) else x, dtype=torch.float32)


def _batches(windows, batch_size: int) -> Iterable[torch.Tensor]:
    x = _as_tensor(windows)
    if len(x) == 0:
        raise ValueError("no evaluation windows: the firing rates need at least one window")
    for i in range(0, len(x), batch_size):
        yield x[i:i + batch_size]


def _reset(model: nn.Module) -> None:
    from spikingjelly.activation_based import functional

    functional.reset_net(model)


def _is_spiking_model(model: nn.Module) -> bool:
    return bool(getattr(model, "spiking", False))


def is_spike_count(x: torch.Tensor) -> bool:
    """True if ``x`` holds spike counts: non-negative integers (binary spikes, or sums of spike trains)."""
    if x.dtype == torch.bool:
        return True
    if not x.dtype.is_floating_point:
        return bool((x >= 0).all())
    return bool(((x >= 0) & (x == torch.round(x))).all())


def _spike_modules() -> tuple[type, ...]:
    from spikingjelly.activation_based import neuron

    return (neuron.BaseNode,)


# ----------------------------------------------------------------------------------------------- firing rates
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
    hooks = []

    def hook(name):
        def fn(_mod, _inp, out):
            out = out.detach()
            sums[name] = sums.get(name, 0.0) + float(out.double().sum())
            counts[name] = counts.get(name, 0) + out.numel()
        return fn

    for name, mod in model.named_modules():
        if isinstance(mod, _spike_modules()):
            hooks.append(mod.register_forward_hook(hook(name)))
    if not hooks:
        raise ValueError(f"{type(model).__name__} has no spiking (SpikingJelly neuron) layer")
    was_training = model.training
    model.eval()
    try:
        for xb in _batches(windows, batch_size):
            _reset(model)
            model(xb)
        _reset(model)
    finally:
        for h in hooks:
            h.remove()
        model.train(was_training)
    return {k: sums[k] / counts[k] for k in sums}


# ----------------------------------------------------------------------------------------------- counting
def ssa_sops(time_steps: int, heads: int, tokens: int, head_dim: int, rate_q: float, rate_k: float,
             rate_v: float) -> float:
    """Synaptic operations of the spiking self-attention products of one block, per prediction (Spikformer).

    ``d_h < N`` (BGFN computes ``Q (K^T V)``): ``(min(r_k, r_v) + r_q) * T * H * N * d_h^2``;
    ``d_h >= N`` (``(Q K^T) V``): ``(min(r_q, r_k) + r_v) * T * H * N^2 * d_h``.
    """
    if SSA.kv_first(tokens, head_dim):
        return (min(rate_k, rate_v) + rate_q) * time_steps * heads * tokens * head_dim ** 2
    return (min(rate_q, rate_k) + rate_v) * time_steps * heads * tokens ** 2 * head_dim


def ssa_dense_ops(time_steps: int, heads: int, tokens: int, head_dim: int) -> float:
    """Accumulates of both SSA products if every Q, K, V neuron fired (``ssa_sops`` with all rates 1)."""
    return ssa_sops(time_steps, heads, tokens, head_dim, 1.0, 1.0, 1.0)


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
        Multiply-accumulates and synaptic operations per prediction.
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


class _Acc:
    """Running sums of one layer over batches."""

    def __init__(self, name, kind):
        self.name, self.kind = name, kind
        self.spiking = None
        self.time_steps = 1
        self.in_sum = 0.0       # sum of input spikes (spiking) over all batches
        self.in_numel = 0
        self.dense = 0.0        # dense ops summed over all predictions
        self.preds = 0
        self.geom: dict = {}
        self.qkv = np.zeros(3)  # spike sums of Q, K, V (ssa)
        self.qkv_numel = 0
        self.exact = 0.0        # nonzero-product accumulates of the SSA (cross-check)
        self.trains = 1         # spike trains merged into the input (residual stream)


_COUNTED = (nn.Linear, nn.Conv1d, nn.Conv2d, nn.Conv3d)
_FREE = (nn.modules.batchnorm._BatchNorm, nn.LayerNorm, nn.Identity, nn.Dropout, nn.GELU, nn.ReLU, nn.Tanh,
         nn.Sequential, nn.ModuleList)


def _check_supported(model: nn.Module) -> None:
    """Refuse models with parametrized layers this module cannot count (e.g. nn.LSTM)."""
    bad = sorted({type(m).__name__ for m in model.modules()
                  if any(True for _ in m.parameters(recurse=False))
                  and not isinstance(m, _COUNTED + _FREE + _spike_modules())})
    if bad:
        raise ValueError(f"bgfn.energy cannot count layers of type {', '.join(bad)} "
                         "(supported: Linear, Conv, BatchNorm, LayerNorm, LIF, SSA, the Transformer twin)")


@torch.no_grad()
def layer_counts(model: nn.Module, windows, batch_size: int = 32) -> list[LayerCount]:
    """MACs and SOPs of every counted layer of ``model`` per prediction, on ``windows`` (see module doc).

    Forward hooks read the input of every Linear/Conv layer (spike counts -> SOPs with its measured input
    rate, real values -> MACs; for a spike-fed convolution ``rate * dense`` includes the padded positions, an
    upper bound -- BGFN's only convolution reads real values), the Q/K/V spikes of every spiking self-attention (Spikformer formula,
    :func:`ssa_sops`) and the token count of every twin attention (``2 N^2 D`` MACs). Rows are in execution
    order; the attention row comes right before the output projection of its block.
    """
    _check_supported(model)
    spiking_model = _is_spiking_model(model)
    accs: dict[str, _Acc] = {}
    order: list[str] = []
    hooks = []
    batch = {"B": 0}

    def acc(name, kind):
        if name not in accs:
            accs[name] = _Acc(name, kind)
            order.append(name)
        return accs[name]

    def weight_hook(name, mod):
        def fn(_m, inputs, out):
            x = inputs[0].detach()
            a = acc(name, "linear" if isinstance(mod, nn.Linear) else "conv")
            if isinstance(mod, nn.Linear):
                dense = x.numel() * mod.out_features                         # (numel / Din) tokens * Din * Dout
            else:
                per_out = (mod.in_channels // mod.groups) * math.prod(mod.kernel_size)
                dense = out.numel() * per_out
            # spike-driven only if every batch's input holds spike counts (a real-valued batch -> MACs)
            spk = spiking_model and is_spike_count(x)
            a.spiking = spk if a.spiking is None else (a.spiking and spk)
            if spk:
                xs = float(x.double().sum())
                a.in_sum += xs
                a.in_numel += x.numel()
                a.time_steps = int(x.shape[0]) if x.dim() >= 3 else 1
                if inputs[0] is stream["tensor"]:      # the residual stream: the sum of stream["n"] spike trains
                    a.trains = stream["n"]
            a.dense += dense
            a.preds += batch["B"]
        return fn

    def ssa_hooks(name, mod):
        store: dict[str, torch.Tensor] = {}

        def keep(key):
            def fn(_m, _inp, out):
                store[key] = out.detach()
            return fn

        def attn_pre(_m, inputs):
            q, k, v = store.pop("q"), store.pop("k"), store.pop("v")                 # [T, B, N, D] spikes
            T, B, N, D = q.shape
            H = int(mod.heads)
            dh = D // H
            a = acc(f"{name}.qkv_matmul", "ssa")
            a.spiking = True
            a.time_steps = T
            a.geom = {"T": T, "H": H, "N": N, "dh": dh}
            a.qkv += [float(q.double().sum()), float(k.double().sum()), float(v.double().sum())]
            a.qkv_numel += q.numel()
            a.preds += B
            # The count SpikingJelly's counter reports for the two products (cross-check): a product of two
            # binary matrices costs its nonzero products (= sum of the result), a spike matrix times an
            # integer matrix costs (spikes x fan-out); K^T V (or Q K^T) is binary only if no entry exceeds 1.
            split = lambda t: t.reshape(T, B, N, H, dh).transpose(2, 3).double()       # [T, B, H, N, dh]
            qs, ks, vs = split(q), split(k), split(v)
            if SSA.kv_first(N, dh):
                kv = ks.transpose(-2, -1) @ vs                                      # [T, B, H, dh, dh]
                second = float((qs @ kv).sum()) if float(kv.max()) <= 1 else float(qs.sum()) * dh
                a.exact += float(kv.sum()) + second
            else:
                qk = qs @ ks.transpose(-2, -1)                                      # [T, B, H, N, N]
                second = float((qk @ vs).sum()) if float(qk.max()) <= 1 else float(vs.sum()) * N
                a.exact += float(qk.sum()) + second
        hooks.append(mod.q.register_forward_hook(keep("q")))
        hooks.append(mod.k.register_forward_hook(keep("k")))
        hooks.append(mod.v.register_forward_hook(keep("v")))
        hooks.append(mod.attn_lif.register_forward_pre_hook(attn_pre))

    def twin_hooks(name, mod):
        def proj_pre(_m, inputs):
            x = inputs[0]                                                           # [B, N, D]
            B, N, D = x.shape
            a = acc(f"{name}.attention", "attention")
            a.spiking = False
            a.dense += B * 2.0 * N * N * D        # Q K^T: H*N*N*dh, A V: H*N*N*dh (H*dh = D)
            a.preds += B
        hooks.append(mod.proj.register_forward_pre_hook(proj_pre))

    # Residual stream of the spiking blocks (x = x + attn(x); x = x + mlp(x)): the tensor object that Q/K/V
    # and the MLP read, and how many binary spike trains it sums (1 + 2 l at block l's input). A layer whose
    # input *is* that tensor gets ``trains = n`` (its rate is then given per train). Spike totals are checked
    # at every step, so a changed block wiring raises instead of miscounting.
    stream: dict = {"n": 0, "sum": 0.0, "tensor": None}

    def _sum(t):
        return float(t.detach().double().sum())

    def _binary(t):
        return bool((t.eq(0) | t.eq(1)).all())

    def block_pre(name):
        def fn(_m, inputs):
            x = inputs[0]
            if stream["n"] == 0:                       # first block: the stream is the embedding's spikes
                if not _binary(x):
                    raise ValueError(f"{name}: the input of the first block is not binary spikes")
                stream.update(n=1, sum=_sum(x))
            elif _sum(x) != stream["sum"]:
                raise ValueError(f"{name}: block input is not the residual sum tracked so far; "
                                 "bgfn.energy must follow the changed block wiring")
            stream["tensor"] = x
        return fn

    def residual_add(name):
        def fn(_m, _inp, out):
            if not _binary(out):
                raise ValueError(f"{name}: output added to the residual stream is not binary spikes")
            stream["n"] += 1
            stream["sum"] += _sum(out)
            stream["tensor"] = None
        return fn

    def mlp_pre(name):
        def fn(_m, inputs):
            if _sum(inputs[0]) != stream["sum"]:
                raise ValueError(f"{name}: MLP input is not x + attn(x); bgfn.energy must follow the block wiring")
            stream["tensor"] = inputs[0]
        return fn

    def block_post(name):
        def fn(_m, _inp, out):
            if _sum(out) != stream["sum"]:
                raise ValueError(f"{name}: block output is not x + attn(x) + mlp(.); "
                                 "bgfn.energy must follow the block wiring")
            stream["tensor"] = None
        return fn

    def model_pre(_m, _inp):
        stream.update(n=0, sum=0.0, tensor=None)

    ssa_t, twin_t, block_t = (SSA,), (TwinBlock,), (Block,)
    if spiking_model:
        hooks.append(model.register_forward_pre_hook(model_pre))
    for name, mod in model.named_modules():
        if spiking_model and block_t and isinstance(mod, block_t):
            hooks.append(mod.register_forward_pre_hook(block_pre(name)))
            hooks.append(mod.attn.register_forward_hook(residual_add(f"{name}.attn")))
            hooks.append(mod.mlp.register_forward_pre_hook(mlp_pre(f"{name}.mlp")))
            hooks.append(mod.mlp.register_forward_hook(residual_add(f"{name}.mlp")))
            hooks.append(mod.register_forward_hook(block_post(name)))
        if ssa_t and isinstance(mod, ssa_t):
            ssa_hooks(name, mod)
        elif twin_t and isinstance(mod, twin_t):
            twin_hooks(name, mod)
        if isinstance(mod, _COUNTED):
            hooks.append(mod.register_forward_hook(weight_hook(name, mod)))

    was_training = model.training
    model.eval()
    try:
        for xb in _batches(windows, batch_size):
            batch["B"] = len(xb)
            if spiking_model:
                _reset(model)
            model(xb)
        if spiking_model:
            _reset(model)
    finally:
        for h in hooks:
            h.remove()
        model.train(was_training)

    rows = []
    for name in order:
        a = accs[name]
        preds = max(a.preds, 1)
        if a.kind == "ssa":
            rq, rk, rv = (a.qkv / a.qkv_numel).tolist()
            g = a.geom
            dense = ssa_dense_ops(g["T"], g["H"], g["N"], g["dh"])
            sops = ssa_sops(g["T"], g["H"], g["N"], g["dh"], rq, rk, rv)
            geom = {**g, "rate_q": rq, "rate_k": rk, "rate_v": rv, "exact_sops": a.exact / preds}
            rows.append(LayerCount(name, "ssa", True, g["T"], dense, sops / dense if dense else 0.0, 0.0, sops,
                                   geom))
        elif a.spiking:
            count_rate = a.in_sum / a.in_numel if a.in_numel else 0.0    # spikes per input neuron and step
            dense = a.dense / preds
            rows.append(LayerCount(name, a.kind, True, a.time_steps, dense, count_rate / a.trains, 0.0,
                                   count_rate * dense, trains=a.trains))
        else:
            dense = a.dense / preds
            rows.append(LayerCount(name, a.kind, False, 1, dense, 1.0, dense, 0.0))
    return rows


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


def table_from_counts(counts: list[LayerCount], model_name: str, e_mac: float = E_MAC_PJ,
                      e_ac: float = E_AC_PJ) -> pd.DataFrame:
    """The per-layer energy table of ``counts`` with a ``total`` row (columns :data:`COLUMNS`).

    ``energy_uj = (e_mac * macs + e_ac * sops) * 1e-6`` (pJ -> uJ). The ``total`` row's ``firing_rate`` is
    the effective mean input rate of the spike-driven layers, ``sum(sops) / sum(trains * dense)`` (1.0 for
    an ANN).
    """
    rows = [{"model": model_name, "layer": c.name, "firing_rate": float(c.rate), "macs": float(c.macs),
             "sops": float(c.sops), "energy_uj": (e_mac * c.macs + e_ac * c.sops) * 1e-6} for c in counts]
    dense_spk = sum(c.trains * c.dense for c in counts if c.spiking)
    sops = sum(c.sops for c in counts)
    macs = sum(c.macs for c in counts)
    rows.append({"model": model_name, "layer": "total",
                 "firing_rate": float(sops / dense_spk) if dense_spk else 1.0,
                 "macs": float(macs), "sops": float(sops), "energy_uj": (e_mac * macs + e_ac * sops) * 1e-6})
    return pd.DataFrame(rows, columns=list(COLUMNS))


def model_name(model: nn.Module) -> str:
    """Method id of ``model`` (``bgfn``, ``transformer``, ...) from :data:`bgfn.models.MODELS`."""
    from bgfn.models import MODELS

    for key, cls in MODELS.items():
        if type(model) is cls:
            return key
    return type(model).__name__.lower()


def energy_table(model: nn.Module, windows, e_mac: float = E_MAC_PJ, e_ac: float = E_AC_PJ,
                 batch_size: int = 32, name: str | None = None) -> pd.DataFrame:
    """Per-layer firing rate, MACs, SOPs and energy (uJ per prediction) of ``model`` on ``windows``.

    Parameters
    ----------
    model : nn.Module
        BGFN (spike-driven layers -> SOPs) or an ANN such as the Transformer twin (all MACs).
    windows : array [M, N, C] or WindowSet-like
        Normalized evaluation windows.
    e_mac, e_ac : float
        Energy per MAC and per accumulate, pJ (Horowitz 2014, 45 nm float32: 4.6 and 0.9).
    batch_size : int
        Windows per forward pass.
    name : str, optional
        Value of the ``model`` column (default: the method id, :func:`model_name`).

    Returns
    -------
    DataFrame
        Columns ``model, layer, firing_rate, macs, sops, energy_uj``; one row per counted layer in execution
        order and a final ``total`` row.
    """
    return table_from_counts(layer_counts(model, windows, batch_size), name or model_name(model), e_mac, e_ac)


def total_energy_uj(table: pd.DataFrame) -> float:
    """Energy per prediction (uJ) of the ``total`` row of an :func:`energy_table`."""
    tot = table.loc[table["layer"] == "total", "energy_uj"]
    if len(tot) != 1:
        raise ValueError("table has no (or several) 'total' rows")
    return float(tot.iloc[0])


def reduction_pct(snn, ann) -> float:
    """Energy saved by the SNN relative to the ANN, %: ``100 * (1 - E_snn / E_ann)``.

    ``snn`` and ``ann`` are :func:`energy_table` frames (their ``total`` rows) or energies (uJ).
    """
    e_snn = total_energy_uj(snn) if isinstance(snn, pd.DataFrame) else float(snn)
    e_ann = total_energy_uj(ann) if isinstance(ann, pd.DataFrame) else float(ann)
    if not e_ann > 0:
        raise ValueError(f"ANN energy must be positive, got {e_ann}")
    return 100.0 * (1.0 - e_snn / e_ann)


# ----------------------------------------------------------------------------------------------- sweeps
def _energy_pj(counts: list[LayerCount], e_mac: float, e_ac: float) -> float:
    return sum(e_mac * c.macs + e_ac * c.sops for c in counts)


def mean_rate(counts: list[LayerCount]) -> float:
    """Effective mean input rate of the spike-driven layers: ``sum(sops) / sum(trains * dense)``."""
    dense = sum(c.trains * c.dense for c in counts if c.spiking)
    return sum(c.sops for c in counts if c.spiking) / dense if dense else float("nan")


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


def reduction_vs_time_steps(build: Callable[[int], tuple[nn.Module, nn.Module]], windows,
                            rates_from: list[LayerCount], time_steps, e_mac: float = E_MAC_PJ,
                            e_ac: float = E_AC_PJ) -> pd.DataFrame:
    """Reduction (%) as a function of ``T_s``, with the trained model's per-layer spike rates held fixed.

    Parameters
    ----------
    build : callable
        ``build(T_s) -> (snn, ann)``: untrained models of the same size with ``T_s`` time steps (only their
        shapes are used).
    windows : array [M, N, C]
        A few windows (shapes only; one is enough).
    rates_from : list of LayerCount
        :func:`layer_counts` of the trained SNN (its input rates, by layer name).
    time_steps : iterable of int

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


# ----------------------------------------------------------------------------------------------- checkpoints
def energy_checkpoint(profile: str, method: str, cfg: dict | None = None, dataset: str | None = None,
                      seed: int | None = None, must_exist: bool = True):
    """The checkpoint of the energy estimate (:func:`bgfn.checkpoints.checkpoint_path`).

    ``dataset``/``seed`` default to the profile's ``energy.dataset``/``energy.seed`` and, when those are
    null, to the first of ``train.datasets``/``train.seeds`` (what notebook 03 trains first).

    Raises
    ------
    FileNotFoundError
        The checkpoint is missing (``must_exist``); the message names the file and the notebook that writes it.
    """
    from bgfn.checkpoints import checkpoint_path
    from bgfn.config import load_profile

    cfg = cfg if cfg is not None else load_profile(profile)
    ecfg, tcfg = cfg.get("energy") or {}, cfg.get("train") or {}
    dataset = dataset or ecfg.get("dataset") or (tcfg.get("datasets") or [None])[0]
    seed = seed if seed is not None else ecfg.get("seed")
    seed = seed if seed is not None else (tcfg.get("seeds") or [0])[0]
    if dataset is None:
        raise ValueError(f"profile {profile!r}: no dataset (energy.dataset and train.datasets are empty)")
    path = checkpoint_path(profile, dataset, method, int(seed), create=False)
    if must_exist and not path.is_file():
        raise FileNotFoundError(
            f"trained {method} model not found: {path} -- notebook 03_bgfn_training.ipynb writes it "
            f"(run `make reproduce PROFILE={profile}`, or `python -m bgfn.train --profile {profile} "
            f"--dataset {dataset} --method {method} --seed {int(seed)}`)")
    return path


# ----------------------------------------------------------------------------------------------- BN folding
def fold_batchnorm(model: nn.Module) -> nn.Module:
    """A copy of ``model`` (eval mode) with every BatchNorm folded into the Linear/Conv registered just before it.

    ``W' = W * g / sqrt(var + eps)``, ``b' = (b - mean) * g / sqrt(var + eps) + beta`` (exact at inference);
    the BatchNorm is replaced by ``nn.Identity``. A BatchNorm without such a predecessor is left in place.
    """
    from torch.nn.utils.fusion import fuse_conv_bn_eval, fuse_linear_bn_eval

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


# ----------------------------------------------------------------------------------------------- SpikingJelly
def _sj_rules():
    """SpikingJelly counter rules extended to spike *counts* (integers >= 0, e.g. residual sums of spikes).

    SpikingJelly 2.0 treats an operand as spikes only if it is binary; any other operand makes the product
    dense MACs (Spikingformer's stricter convention). These rules apply Spikformer/syops' convention instead:
    a binary operand drives the product (``nnz * fan-out``, both binary: the number of nonzero products, as
    SpikingJelly does); otherwise a spike-count operand drives it (``sum * fan-out``).
    """
    aten = torch.ops.aten

    def binary(x):
        return x.dtype == torch.bool or bool((x.eq(0) | x.eq(1)).all())

    def kinds(x, y):
        return binary(x), binary(y), is_spike_count(x), is_spike_count(y)

    def syn(x, y, out, m_axis, n_axis):
        bx, by, cx, cy = kinds(x, y)
        if bx and by:
            return int(out.double().sum().item())
        if bx:
            return int(x.count_nonzero().item()) * y.shape[n_axis]
        if by:
            return int(y.count_nonzero().item()) * x.shape[m_axis]
        if cx:
            return int(x.double().sum().item()) * y.shape[n_axis]
        if cy:
            return int(y.double().sum().item()) * x.shape[m_axis]
        return 0

    def mac(x, y, dims):
        return 0 if any(kinds(x, y)) else math.prod(dims)

    syn_rules = {
        aten.mm.default: lambda a, k, o: syn(a[0], a[1], o, 0, 1),
        aten.addmm.default: lambda a, k, o: syn(a[1], a[2], o, 0, 1),
        aten.bmm.default: lambda a, k, o: syn(a[0], a[1], o, 1, 2),
    }
    mac_rules = {
        aten.mm.default: lambda a, k, o: mac(a[0], a[1], (*a[0].shape, a[1].shape[1])),
        aten.addmm.default: lambda a, k, o: mac(a[1], a[2], (*a[1].shape, a[2].shape[1])),
        aten.bmm.default: lambda a, k, o: mac(a[0], a[1], (*a[0].shape, a[1].shape[2])),
    }
    return syn_rules, mac_rules


@torch.no_grad()
def spikingjelly_counts(model: nn.Module, windows, e_mac: float = E_MAC_PJ, e_ac: float = E_AC_PJ,
                        multispike: bool = True, batch_size: int = 32) -> dict:
    """Compute energy of ``model`` per prediction from SpikingJelly 2.0's ``MACCounter`` and ``SynOpCounter``.

    The model's BatchNorms are folded first (:func:`fold_batchnorm`; otherwise SpikingJelly counts BN as
    MACs), softmax attention runs on PyTorch's math kernel (so that its matmuls reach the counters as
    ``bmm``), and ``E = e_mac * MACs + e_ac * SynOps`` (no memory term). SpikingJelly's ``ACCounter`` is not
    used: it also counts the additions inside LIF updates, residuals and reductions, which the Spikformer
    convention (and :func:`energy_table`) leaves out.

    Parameters
    ----------
    multispike : bool
        ``True``: spike-count operands (integers >= 0) drive accumulates, as in :func:`energy_table`
        (rules :func:`_sj_rules`, passed through SpikingJelly's ``extra_rules``); ``False``: SpikingJelly's
        default rules (non-binary operands -> MACs).

    Returns
    -------
    dict
        ``macs``, ``synops``, ``energy_uj`` per prediction, ``per_scope`` (module path -> energy, uJ) and
        ``model`` (the folded copy, for counting it with :func:`layer_counts` on the same spikes).
    """
    from spikingjelly.activation_based.op_counter import DispatchCounterMode, MACCounter, SynOpCounter
    from torch.nn.attention import SDPBackend, sdpa_kernel

    folded = fold_batchnorm(model)
    syn_rules, mac_rules = _sj_rules() if multispike else ({}, {})
    macc, sync = MACCounter(extra_rules=mac_rules), SynOpCounter(extra_rules=syn_rules)
    n = 0
    with DispatchCounterMode([macc, sync]), sdpa_kernel(SDPBackend.MATH):
        for xb in _batches(windows, batch_size):
            if _is_spiking_model(folded):
                _reset(folded)
            folded(xb)
            n += len(xb)
    if _is_spiking_model(folded):
        _reset(folded)
    macs, synops = macc.get_total() / n, sync.get_total() / n
    scopes: dict[str, float] = {}
    for counter, e in ((macc, e_mac), (sync, e_ac)):
        for scope, ops in counter.get_counts().items():
            scopes[scope] = scopes.get(scope, 0.0) + e * sum(ops.values()) / n * 1e-6
    return {"macs": macs, "synops": synops, "energy_uj": (e_mac * macs + e_ac * synops) * 1e-6,
            "per_scope": scopes, "model": folded}

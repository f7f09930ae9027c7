"""How each operation of BGFN and of its Transformer twin is counted, and what it costs on 45 nm CMOS (paper
Sec. 4.2): the energy of one MAC and one AC (Horowitz 2014), the residual stream of the spiking blocks, the rule
of every block kind (Spikformer / syops convention).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import torch
from torch import nn

from bgfn.energy.passes import SPIKE_MODULES, is_binary, is_spike_count
from bgfn.models.bgfn import SSA

# ---------------------------------------------------------------------------------------------------
# Energy of one operation on 45 nm CMOS (Horowitz 2014), the paper's hardware assumption (Sec. 4.2).
# ---------------------------------------------------------------------------------------------------
#: Horowitz (2014), 45 nm, 32-bit float: multiply 3.7 pJ + add 0.9 pJ (pJ per MAC).
E_MAC_PJ = 4.6


#: Horowitz (2014), 45 nm, 32-bit float add (pJ per accumulate / synaptic operation).
E_AC_PJ = 0.9


def energy_uj(macs: float, sops: float, e_mac: float = E_MAC_PJ, e_ac: float = E_AC_PJ) -> float:
    """``E = E_MAC * MACs + E_AC * SOPs``, converted from pJ to µJ.

    Parameters
    ----------
    macs, sops : float
        Multiply-accumulates and synaptic operations (ops, per prediction).
    e_mac, e_ac : float
        Energy per MAC and per accumulate, pJ.

    Returns
    -------
    float
        Energy, µJ (per prediction when the counts are).
    """
    return (e_mac * macs + e_ac * sops) * 1e-6


# ---------------------------------------------------------------------------------------------------
# The residual stream of BGFN's spiking blocks: how many spike trains the layers that read it merge.
# ---------------------------------------------------------------------------------------------------
def _total(t: torch.Tensor) -> float:
    return float(t.detach().double().sum())


class ResidualStream:
    """The tensor the spiking blocks pass on, and the number ``n`` of binary spike trains it sums.

    Attributes
    ----------
    n : int
        Spike trains merged into the stream so far (0 before the first block of a forward pass).
    total : float
        Its spike total (checked against every block input and output).
    tensor : torch.Tensor or None
        The stream tensor [T, B, N, D] a layer may read right now (the object, compared by identity).
    """

    def __init__(self):
        self.reset()

    def reset(self) -> None:
        """Start of a forward pass: no stream yet."""
        self.n, self.total, self.tensor = 0, 0.0, None

    def trains_of(self, x: torch.Tensor) -> int | None:
        """``n`` if ``x`` is the stream tensor (a layer reading it merges ``n`` trains), else None."""
        return self.n if x is self.tensor else None

    def follow(self, name: str, block: nn.Module) -> list:
        """Hooks on a spiking :class:`~bgfn.models.bgfn.Block` (``attn``, ``mlp``) that follow the stream.

        Returns
        -------
        list of RemovableHandle
        """

        def block_input(_m, inputs):
            x = inputs[0]                                    # [T, B, N, D]
            if self.n == 0:                                  # first block: the stream is the embedding's spikes
                if not is_binary(x):
                    raise ValueError(f"{name}: the input of the first block is not binary spikes")
                self.n, self.total = 1, _total(x)
            elif _total(x) != self.total:
                raise ValueError(f"{name}: block input is not the residual sum tracked so far; "
                                 "bgfn.energy must follow the changed block wiring")
            self.tensor = x

        def added(part):
            def fn(_m, _inp, out):                           # SSA or MLP output, added to the stream
                if not is_binary(out):
                    raise ValueError(f"{name}.{part}: output added to the residual stream is not binary spikes")
                self.n += 1
                self.total += _total(out)
                self.tensor = None
            return fn

        def mlp_input(_m, inputs):
            if _total(inputs[0]) != self.total:
                raise ValueError(f"{name}.mlp: MLP input is not x + attn(x); bgfn.energy must follow the block "
                                 "wiring")
            self.tensor = inputs[0]

        def block_output(_m, _inp, out):
            if _total(out) != self.total:
                raise ValueError(f"{name}: block output is not x + attn(x) + mlp(.); "
                                 "bgfn.energy must follow the block wiring")
            self.tensor = None

        return [block.register_forward_pre_hook(block_input),
                block.attn.register_forward_hook(added("attn")),
                block.mlp.register_forward_pre_hook(mlp_input),
                block.mlp.register_forward_hook(added("mlp")),
                block.register_forward_hook(block_output)]


# ---------------------------------------------------------------------------------------------------
# How each block of BGFN and of its Transformer twin is counted (Spikformer / syops convention, paper Sec. 4.2).
# ---------------------------------------------------------------------------------------------------
#: Layers with weights that are counted (:func:`count_linear_or_conv`).
COUNTED = (nn.Linear, nn.Conv1d, nn.Conv2d, nn.Conv3d)


#: Layers with parameters that cost nothing under the convention (BatchNorm: folded) or only group others.
FREE = (nn.modules.batchnorm._BatchNorm, nn.LayerNorm, nn.Identity, nn.Dropout, nn.GELU, nn.ReLU, nn.Tanh,
        nn.Sequential, nn.ModuleList)


# ----------------------------------------------------------------------------------------------- formulas
def linear_or_conv_ops(layer: nn.Module, x: torch.Tensor, out: torch.Tensor) -> int:
    """Multiply-accumulates of one call of a Linear/Conv layer if every input were nonzero (its FLOPs).

    Linear: ``numel(x) / D_in`` input vectors times ``D_in * D_out``; Conv: every output value sums
    ``(C_in / groups) * prod(kernel)`` products (padded positions included).
    """
    if isinstance(layer, nn.Linear):
        return x.numel() * layer.out_features
    per_out = (layer.in_channels // layer.groups) * math.prod(layer.kernel_size)
    return out.numel() * per_out


def ssa_sops(time_steps: int, heads: int, tokens: int, head_dim: int, rate_q: float, rate_k: float,
             rate_v: float) -> float:
    """Synaptic operations of the spiking self-attention products of one block, per prediction (Spikformer).

    ``d_h < N`` (BGFN computes ``Q (K^T V)``): ``(min(r_k, r_v) + r_q) * T * H * N * d_h^2``;
    ``d_h >= N`` (``(Q K^T) V``): ``(min(r_q, r_k) + r_v) * T * H * N^2 * d_h``.

    Spikformer's ``energy_consumption_calculation``: the product of two spike matrices is driven by the
    sparser one (each of its spikes adds one row/column of the other), the product of a spike matrix with the
    integer matrix ``K^T V`` (or ``Q K^T``) by the spikes of ``Q`` (or ``V``). The order is the one BGFN
    evaluates (:meth:`bgfn.models.bgfn.SSA.kv_first`).

    Returns
    -------
    float
        SOPs (ops) of the two products, all heads and steps.
    """
    if SSA.kv_first(tokens, head_dim):
        return (min(rate_k, rate_v) + rate_q) * time_steps * heads * tokens * head_dim ** 2
    return (min(rate_q, rate_k) + rate_v) * time_steps * heads * tokens ** 2 * head_dim


def ssa_dense_ops(time_steps: int, heads: int, tokens: int, head_dim: int) -> float:
    """Accumulates of both SSA products if every Q, K, V neuron fired (``ssa_sops`` with all rates 1)."""
    return ssa_sops(time_steps, heads, tokens, head_dim, 1.0, 1.0, 1.0)


def ssa_exact_sops(q: torch.Tensor, k: torch.Tensor, v: torch.Tensor, heads: int) -> float:
    """The count SpikingJelly's counter reports for the two SSA products of one batch (the cross-check).

    A product of two binary matrices costs its nonzero products (= the sum of the result); a spike matrix
    times an integer matrix costs spikes x fan-out. ``K^T V`` (or ``Q K^T``) is binary only if no entry of it
    exceeds 1 (over all heads and steps: SpikingJelly sees one ``bmm``).

    Parameters
    ----------
    q, k, v : Tensor [T, B, N, D]
        Spikes of the Q, K, V layers.
    heads : int

    Returns
    -------
    float
        Accumulates of the batch (all its windows).
    """
    T, B, N, D = q.shape
    dh = D // heads
    split = lambda t: t.reshape(T, B, N, heads, dh).transpose(2, 3).double()     # [T, B, H, N, dh]
    qs, ks, vs = split(q), split(k), split(v)
    if SSA.kv_first(N, dh):
        kv = ks.transpose(-2, -1) @ vs                                          # [T, B, H, dh, dh]
        second = float((qs @ kv).sum()) if float(kv.max()) <= 1 else float(qs.sum()) * dh
        return float(kv.sum()) + second
    qk = qs @ ks.transpose(-2, -1)                                              # [T, B, H, N, N]
    second = float((qk @ vs).sum()) if float(qk.max()) <= 1 else float(vs.sum()) * N
    return float(qk.sum()) + second


def softmax_attention_macs(tokens: int, dim: int, windows: int = 1) -> float:
    """MACs of the twin's two attention products for ``windows`` predictions: ``Q K^T`` and ``A V`` cost
    ``H * N^2 * d_h = N^2 * D`` each per block (softmax and scaling not counted)."""
    return windows * 2.0 * tokens * tokens * dim


# ----------------------------------------------------------------------------------------------- running sums
@dataclass
class LayerSums:
    """Running sums of one counted layer over the batches of one counting pass.

    ``kind`` is ``'linear'``, ``'conv'``, ``'ssa'`` or ``'attention'``; ``spiking`` stays None until the layer
    ran. ``dense`` sums the all-inputs-active operations of every prediction, ``in_sum``/``in_numel`` the input
    spikes of a spike-driven layer, ``qkv``/``qkv_numel`` the Q, K, V spikes of an SSA and ``exact`` its
    SpikingJelly count (:func:`ssa_exact_sops`).
    """

    name: str
    kind: str
    spiking: bool | None = None
    time_steps: int = 1
    in_sum: float = 0.0
    in_numel: int = 0
    dense: float = 0.0
    preds: int = 0
    geometry: dict = field(default_factory=dict)
    qkv: np.ndarray = field(default_factory=lambda: np.zeros(3))
    qkv_numel: int = 0
    exact: float = 0.0
    trains: int = 1


class Tally:
    """What the rules of one counting pass add to: the layers in execution order and the residual stream.

    Parameters
    ----------
    spiking_model : bool
        A spiking network: spike-count inputs are SOPs (an ANN's layers are MACs whatever they read).
    """

    def __init__(self, spiking_model: bool):
        self.spiking_model = spiking_model
        self.layers: dict[str, LayerSums] = {}       # insertion order = execution order
        self.windows = 0                             # windows of the batch being run
        self.stream = ResidualStream()

    def layer(self, name: str, kind: str) -> LayerSums:
        """The sums of layer ``name`` (created at its first call, so rows follow execution order)."""
        if name not in self.layers:
            self.layers[name] = LayerSums(name, kind)
        return self.layers[name]

    def start_batch(self, xb: torch.Tensor) -> None:
        """Before the forward pass of the batch ``xb`` [B, N, C]: its size; no residual stream yet."""
        self.windows = len(xb)
        self.stream.reset()


def check_supported(model: nn.Module) -> None:
    """Refuse models with parametrized layers no rule counts (e.g. nn.LSTM)."""
    bad = sorted({type(m).__name__ for m in model.modules()
                  if any(True for _ in m.parameters(recurse=False))
                  and not isinstance(m, COUNTED + FREE + SPIKE_MODULES)})
    if bad:
        raise ValueError(f"bgfn.energy cannot count layers of type {', '.join(bad)} "
                         "(supported: Linear, Conv, BatchNorm, LayerNorm, LIF, SSA, the Transformer twin)")


# ----------------------------------------------------------------------------------------------- rules
def count_linear_or_conv(tally: Tally, name: str, layer: nn.Module) -> list:
    """Every Linear/Conv layer (the table above): MACs if it reads real values, SOPs if it reads spikes.

    A layer is spike-driven only if *every* batch's input holds spike counts (non-negative integers) and the
    model is spiking; it then does ``n * r * T * FLOPs`` SOPs, with ``r`` its measured input rate per merged
    train and ``n`` the trains of the residual stream it reads (1 otherwise). For a spike-fed convolution
    ``FLOPs`` includes the padded positions, an upper bound (BGFN's only convolution reads real values).
    """

    def fn(_m, inputs, out):
        x = inputs[0].detach()                                 # [T, B, N, D_in] spikes or [B, ...] real values
        s = tally.layer(name, "linear" if isinstance(layer, nn.Linear) else "conv")
        spk = tally.spiking_model and is_spike_count(x)
        s.spiking = spk if s.spiking is None else (s.spiking and spk)
        if spk:
            s.in_sum += float(x.double().sum())
            s.in_numel += x.numel()
            s.time_steps = int(x.shape[0]) if x.dim() >= 3 else 1
            n = tally.stream.trains_of(inputs[0])
            if n is not None:
                s.trains = n
        s.dense += linear_or_conv_ops(layer, x, out)
        s.preds += tally.windows

    return [layer.register_forward_hook(fn)]


def count_spiking_self_attention(tally: Tally, name: str, ssa: SSA) -> list:
    """The two products of a spiking self-attention (no softmax), one row ``<name>.qkv_matmul``.

    Keeps the spike totals of Q, K, V (their rates give :func:`ssa_sops`) and their SpikingJelly count
    (:func:`ssa_exact_sops`); the Q/K/V and projection Linear layers are counted by
    :func:`count_linear_or_conv`.
    """
    store: dict[str, torch.Tensor] = {}

    def keep(key):
        def fn(_m, _inp, out):
            store[key] = out.detach()
        return fn

    def products(_m, _inputs):                       # before the attention LIF: Q, K, V of this pass are known
        q, k, v = store.pop("q"), store.pop("k"), store.pop("v")               # [T, B, N, D] spikes
        T, B, N, D = q.shape
        H = int(ssa.heads)
        s = tally.layer(f"{name}.qkv_matmul", "ssa")
        s.spiking = True
        s.time_steps = T
        s.geometry = {"T": T, "H": H, "N": N, "dh": D // H}
        s.qkv += [float(q.double().sum()), float(k.double().sum()), float(v.double().sum())]
        s.qkv_numel += q.numel()
        s.preds += B
        s.exact += ssa_exact_sops(q, k, v, H)

    return [ssa.q.register_forward_hook(keep("q")), ssa.k.register_forward_hook(keep("k")),
            ssa.v.register_forward_hook(keep("v")), ssa.attn_lif.register_forward_pre_hook(products)]


def count_softmax_attention(tally: Tally, name: str, block: nn.Module) -> list:
    """The two attention products of a twin block (:func:`softmax_attention_macs`), one row
    ``<name>.attention``, placed before the block's output projection."""

    def fn(_m, inputs):
        B, N, D = inputs[0].shape                                                  # [B, N, D]
        s = tally.layer(f"{name}.attention", "attention")
        s.spiking = False
        s.dense += softmax_attention_macs(N, D, B)
        s.preds += B

    return [block.proj.register_forward_pre_hook(fn)]

"""Cross-check of the counts with SpikingJelly 2.0's operation counter (``MACCounter``, ``SynOpCounter``).

SpikingJelly's counters intercept every aten matmul/convolution of a forward pass (compute only: no memory
term; its ``ACCounter`` is not used because it also counts the additions of LIF updates and residuals, which
the convention of :mod:`bgfn.energy.rules` leaves out). Both models are counted with their BatchNorms folded
(:mod:`bgfn.energy.passes`) and the twin's attention on PyTorch's math kernel so that its matmuls are visible.
SpikingJelly counts an operand as spikes only when it is binary; :func:`_sj_rules` extends it to spike counts
(the residual stream) through its ``extra_rules``. Its count of the SSA products is exact (nonzero products)
where Spikformer's formula uses the sparser operand's rate: :func:`compare_with_spikingjelly` reports both
differences.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import pandas as pd
import torch
from spikingjelly.activation_based.op_counter import DispatchCounterMode, MACCounter, SynOpCounter
from torch import nn
from torch.nn.attention import SDPBackend, sdpa_kernel

from bgfn.energy.counts import layer_counts
from bgfn.energy.passes import fold_batchnorm, is_binary, is_spike_count, is_spiking_model, run_batches
from bgfn.energy.rules import E_AC_PJ, E_MAC_PJ, energy_uj
from bgfn.energy.tables import reduction_pct, table_from_counts, total_energy_uj


def _sj_rules():
    """SpikingJelly counter rules extended to spike *counts* (integers >= 0, e.g. residual sums of spikes).

    SpikingJelly 2.0 treats an operand as spikes only if it is binary; any other operand makes the product
    dense MACs (Spikingformer's stricter convention). These rules apply Spikformer/syops' convention instead:
    a binary operand drives the product (``nnz * fan-out``, both binary: the number of nonzero products, as
    SpikingJelly does); otherwise a spike-count operand drives it (``sum * fan-out``).
    """
    aten = torch.ops.aten

    def binary(x):
        return x.dtype == torch.bool or is_binary(x)

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
    convention (and :func:`bgfn.energy.tables.energy_table`) leaves out.

    Parameters
    ----------
    multispike : bool
        ``True``: spike-count operands (integers >= 0) drive accumulates, as in
        :func:`bgfn.energy.tables.energy_table` (rules :func:`_sj_rules`, passed through SpikingJelly's
        ``extra_rules``); ``False``: SpikingJelly's default rules (non-binary operands -> MACs).

    Returns
    -------
    dict
        ``macs``, ``synops``, ``energy_uj`` per prediction, ``per_scope`` (module path -> energy, µJ) and
        ``model`` (the folded copy, for counting it with :func:`bgfn.energy.counts.layer_counts` on the same
        spikes).
    """
    folded = fold_batchnorm(model)
    syn_rules, mac_rules = _sj_rules() if multispike else ({}, {})
    macc, sync = MACCounter(extra_rules=mac_rules), SynOpCounter(extra_rules=syn_rules)
    seen = {"windows": 0}

    def tally(xb):
        seen["windows"] += len(xb)

    with DispatchCounterMode([macc, sync]), sdpa_kernel(SDPBackend.MATH):
        run_batches(folded, windows, batch_size, [], reset=is_spiking_model(folded), before_batch=tally)
    n = seen["windows"]
    macs, synops = macc.get_total() / n, sync.get_total() / n
    scopes: dict[str, float] = {}
    for counter, e in ((macc, e_mac), (sync, e_ac)):
        for scope, ops in counter.get_counts().items():
            scopes[scope] = scopes.get(scope, 0.0) + e * sum(ops.values()) / n * 1e-6
    return {"macs": macs, "synops": synops, "energy_uj": energy_uj(macs, synops, e_mac, e_ac),
            "per_scope": scopes, "model": folded}


@dataclass
class Crosscheck:
    """Our counts beside SpikingJelly's, per model (:func:`compare_with_spikingjelly`).

    Attributes
    ----------
    table : DataFrame
        Index ``model``; MACs, SOPs and energy (µJ per prediction) of both counters, ``difference (%)``
        = ``100 * (E_ours / E_SJ - 1)`` and the same with our SSA term replaced by the exact count.
    worst_pct : float
        Largest ``|difference (%)|``.
    strict_uj : dict
        Model -> energy (µJ) under SpikingJelly's default rules (non-binary inputs -> MACs).
    strict_reduction_pct : float
        The reduction under those rules.
    """

    table: pd.DataFrame
    worst_pct: float
    strict_uj: dict
    strict_reduction_pct: float


def compare_with_spikingjelly(models: dict[str, nn.Module], windows: dict, n_windows: int,
                              e_mac: float = E_MAC_PJ, e_ac: float = E_AC_PJ, batch_size: int = 32,
                              snn: str = "bgfn", ann: str = "transformer") -> Crosscheck:
    """Count ``models`` with :func:`bgfn.energy.counts.layer_counts` and with SpikingJelly, on the same spikes.

    Parameters
    ----------
    models : dict
        Method -> network (``snn`` and ``ann`` among them).
    windows : dict
        Method -> its normalized windows [M, N, C]; the first ``n_windows`` are counted.
    n_windows : int
        Windows counted (``energy.crosscheck_windows``; SpikingJelly's dispatch is slow).
    e_mac, e_ac : float
        Energy per MAC and per accumulate, pJ.
    batch_size : int
    snn, ann : str
        The methods whose reduction under SpikingJelly's default rules is reported.
    """
    rows, strict = [], {}
    for m, model in models.items():
        xc = windows[m][:n_windows]
        sj = spikingjelly_counts(model, xc, e_mac, e_ac, batch_size=batch_size)
        ours = layer_counts(sj["model"], xc, batch_size)            # the folded copy: the same spikes
        e_ours = total_energy_uj(table_from_counts(ours, m, e_mac, e_ac))
        exact_sops = sum(c.geometry["exact_sops"] if c.kind == "ssa" else c.sops for c in ours)
        e_exact = energy_uj(sum(c.macs for c in ours), exact_sops, e_mac, e_ac)
        strict[m] = spikingjelly_counts(model, xc, e_mac, e_ac, multispike=False, batch_size=batch_size)["energy_uj"]
        rows.append({"model": m, "windows": len(xc), "MACs (ours)": sum(c.macs for c in ours), "MACs (SJ)": sj["macs"],
                     "SOPs (ours)": sum(c.sops for c in ours), "SynOps (SJ)": sj["synops"],
                     "energy ours (µJ)": e_ours, "energy SJ (µJ)": sj["energy_uj"],
                     "difference (%)": 100 * (e_ours / sj["energy_uj"] - 1),
                     "difference, exact SSA count (%)": 100 * (e_exact / sj["energy_uj"] - 1)})
    table = pd.DataFrame(rows).set_index("model")
    return Crosscheck(table, float(table["difference (%)"].abs().max()), strict,
                      reduction_pct(strict[snn], strict[ann]))

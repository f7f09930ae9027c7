"""Analytic sweeps around the trained model: the reduction against the twin as a function of the mean firing
rate and of ``T_s``.

Both hold the counting rule fixed and vary one input of it: every spike rate of BGFN scaled by a common
factor (the SNN's energy is linear in it; :func:`reduction_vs_rate` gives the break-even rate), or the
shapes of untrained models with other ``T_s`` with the trained per-layer rates held
(:func:`reduction_vs_time_steps`). The paper reports a single number; these curves show how far it depends on
the two quantities it does not give.
"""

from __future__ import annotations

from typing import Callable

import numpy as np
import pandas as pd
import torch
from torch import nn

from bgfn.energy.costs import E_AC_PJ, E_MAC_PJ
from bgfn.energy.counts import LayerCount, layer_counts, with_rates
from bgfn.models import build_model


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


def break_even_note(rate: float) -> str:
    """One sentence on the break-even mean firing rate of :func:`reduction_vs_rate`."""
    return (f"break-even mean firing rate: {rate:.3f} "
            + ("(above 1: BGFN stays cheaper at any firing rate)" if rate > 1
               else "(BGFN costs more than the twin above it)"))


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

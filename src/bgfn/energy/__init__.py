"""Theoretical inference energy of BGFN and of its ANN Transformer twin on 45 nm CMOS (paper Sec. 4.2).

The paper states that BGFN needs much less energy (its figure: `data/paper/claims.yaml`) than a conventional
Transformer "on a 45 nm neuromorphic hardware platform" (Horowitz 2014). It gives no counting rule; we use the
one of Spikformer (Zhou et al. 2023) and of the syops counter that SeqSNN (Lv et al. 2024, the code BGFN
builds on) uses. Per prediction (one window)::

    E = E_MAC * MACs + E_AC * SOPs            E_MAC = 4.6 pJ, E_AC = 0.9 pJ (45 nm, 32-bit float)

* a layer reading real values (the convolutional spike encoder, Eq. eq:spike_input; the readout ``head``;
  every layer of the twin) costs one MAC per multiply-accumulate;
* a Linear layer reading spikes does ``SOP = n * r * T * FLOPs`` accumulates, ``r`` its measured input spike
  rate, ``T = T_s``, ``FLOPs`` the multiply-accumulates of one step and ``n`` the binary spike trains merged
  into its input (1, or ``1 + 2 l`` / ``2 + 2 l`` for the layers reading block ``l``'s residual stream).
  ``r * T * FLOPs = (input spikes) * fan-out``: exactly the weight accumulations of an event-driven chip;
* spiking self-attention (no softmax): ``(min(r_k, r_v) + r_q) * T * H * N * d_h^2`` when ``d_h < N``
  (Spikformer's formula, in the order BGFN evaluates it); the twin's attention ``2 N^2 D`` MACs per block;
* BatchNorm is folded (free); biases, LIF updates, residual additions, LayerNorm, softmax, GELU and memory
  traffic are not counted, for either model.

Modules, one concept each (every public name is also importable from ``bgfn.energy``):

* :mod:`~bgfn.energy.passes` -- forward passes over the windows in inference form (BatchNorm folded); spikes vs
  real values;
* :mod:`~bgfn.energy.rules` -- the 45 nm costs (energy per MAC and per AC, Horowitz 2014), the residual stream of
  the spiking blocks, the counting rule of every block kind (encoder, embedding, SSA, MLP, head, twin);
* :mod:`~bgfn.energy.counts` -- counting operations: :class:`LayerCount` and :func:`layer_counts` (MACs/SOPs per
  layer), the firing rates of the LIF layers, the reduction vs firing rate and vs ``T_s``;
* :mod:`~bgfn.energy.checkpoint` -- the audit of what is measured: which trained networks, on which windows;
* :mod:`~bgfn.energy.crosscheck` -- SpikingJelly 2.0's operation counter on the same spikes;
* :mod:`~bgfn.energy.tables` -- energy per layer, totals, reduction against the twin, the measured CPU speed beside
  them;
* :mod:`~bgfn.energy.record` -- ``energy.json``, what notebook 05 hands to the results page;
* :mod:`~bgfn.energy.plots` -- notebook 05's figures.
"""

from bgfn.energy.checkpoint import (MEASURED, EvaluationWindows, MeasuredModels, energy_checkpoint, evaluation_windows,
                                    load_measured, window_indices)
from bgfn.energy.counts import (LayerCount, layer_counts, mean_rate, measure_firing_rates, rates_table,
                                reduction_vs_rate, reduction_vs_time_steps, same_size_builder, with_rates)
from bgfn.energy.crosscheck import Crosscheck, compare_with_spikingjelly, spikingjelly_counts
from bgfn.energy.passes import fold_batchnorm, is_spike_count
from bgfn.energy.plots import plot_energy_per_layer, plot_firing_rates, plot_sweeps
from bgfn.energy.record import energy_summary
from bgfn.energy.rules import E_AC_PJ, E_MAC_PJ, energy_uj, softmax_attention_macs, ssa_dense_ops, ssa_sops
from bgfn.energy.tables import (COLUMNS, EnergyTotals, attention_energy_uj, energy_table, energy_totals, model_name,
                                reduction_pct, speed_table, stack_tables, table_from_counts,
                                total_energy_uj, with_input_trains)

__all__ = [
    "E_AC_PJ", "E_MAC_PJ", "COLUMNS", "MEASURED",
    "Crosscheck", "EnergyTotals", "EvaluationWindows", "LayerCount", "MeasuredModels",
    "attention_energy_uj", "compare_with_spikingjelly", "energy_checkpoint", "energy_summary",
    "energy_table", "energy_totals", "energy_uj", "evaluation_windows", "fold_batchnorm", "is_spike_count",
    "layer_counts", "load_measured", "mean_rate", "measure_firing_rates", "model_name", "plot_energy_per_layer",
    "plot_firing_rates", "plot_sweeps", "rates_table", "reduction_pct", "reduction_vs_rate",
    "reduction_vs_time_steps", "same_size_builder", "softmax_attention_macs",
    "speed_table", "spikingjelly_counts", "ssa_dense_ops", "ssa_sops", "stack_tables", "table_from_counts",
    "total_energy_uj", "window_indices", "with_input_trains", "with_rates",
]

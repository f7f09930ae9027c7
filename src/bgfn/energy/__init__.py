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

* :mod:`~bgfn.energy.costs` -- energy per MAC and per SOP (Horowitz 2014), ``E`` from the counts;
* :mod:`~bgfn.energy.passes` -- forward passes over the windows with hooks; spikes vs real values;
* :mod:`~bgfn.energy.rates` -- firing rates of the LIF layers;
* :mod:`~bgfn.energy.rules` -- the counting rule of every block kind (encoder, embedding, SSA, MLP, head, twin);
* :mod:`~bgfn.energy.residual` -- the spike trains merged by the residual stream;
* :mod:`~bgfn.energy.counts` -- :class:`LayerCount` and :func:`layer_counts`, MACs/SOPs per layer;
* :mod:`~bgfn.energy.tables` -- energy per layer, totals, reduction against the twin;
* :mod:`~bgfn.energy.sweeps` -- reduction vs firing rate and vs ``T_s``;
* :mod:`~bgfn.energy.folding` -- BatchNorm folding;
* :mod:`~bgfn.energy.crosscheck` -- SpikingJelly 2.0's operation counter on the same spikes;
* :mod:`~bgfn.energy.checkpoint`, :mod:`~bgfn.energy.windows` -- which trained networks, on which windows;
* :mod:`~bgfn.energy.plots`, :mod:`~bgfn.energy.bench`, :mod:`~bgfn.energy.summary` -- notebook 05's
  figures, speed table and ``energy.json``.
"""

from bgfn.energy.bench import speed_notes, speed_table
from bgfn.energy.checkpoint import MEASURED, MeasuredModels, energy_checkpoint, load_measured
from bgfn.energy.costs import E_AC_PJ, E_MAC_PJ, energy_uj
from bgfn.energy.counts import LayerCount, layer_counts, mean_rate, with_rates
from bgfn.energy.crosscheck import Crosscheck, compare_with_spikingjelly, spikingjelly_counts
from bgfn.energy.folding import fold_batchnorm
from bgfn.energy.passes import is_spike_count
from bgfn.energy.plots import plot_energy_per_layer, plot_firing_rates, plot_sweeps
from bgfn.energy.rates import measure_firing_rates, rates_table
from bgfn.energy.rules import softmax_attention_macs, ssa_dense_ops, ssa_sops
from bgfn.energy.summary import energy_summary, result_markdown
from bgfn.energy.sweeps import break_even_note, reduction_vs_rate, reduction_vs_time_steps, same_size_builder
from bgfn.energy.tables import (COLUMNS, EnergyTotals, attention_energy_uj, energy_table, energy_totals,
                                model_name, reduction_pct, stack_tables, table_from_counts, total_energy_uj,
                                with_input_trains)
from bgfn.energy.windows import EvaluationWindows, evaluation_windows, window_indices

__all__ = [
    "E_AC_PJ", "E_MAC_PJ", "COLUMNS", "MEASURED",
    "Crosscheck", "EnergyTotals", "EvaluationWindows", "LayerCount", "MeasuredModels",
    "attention_energy_uj", "break_even_note", "compare_with_spikingjelly", "energy_checkpoint", "energy_summary",
    "energy_table", "energy_totals", "energy_uj", "evaluation_windows", "fold_batchnorm", "is_spike_count",
    "layer_counts", "load_measured", "mean_rate", "measure_firing_rates", "model_name", "plot_energy_per_layer",
    "plot_firing_rates", "plot_sweeps", "rates_table", "reduction_pct", "reduction_vs_rate",
    "reduction_vs_time_steps", "result_markdown", "same_size_builder", "softmax_attention_macs", "speed_notes",
    "speed_table", "spikingjelly_counts", "ssa_dense_ops", "ssa_sops", "stack_tables", "table_from_counts",
    "total_energy_uj", "window_indices", "with_input_trains", "with_rates",
]

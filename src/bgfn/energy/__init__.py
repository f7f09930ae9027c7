"""Theoretical inference energy of BGFN and of its ANN Transformer twin on 45 nm CMOS (paper Sec. 4.2).

The paper compares BGFN with a Transformer "on a 45 nm neuromorphic hardware platform" (Horowitz 2014) without a
counting rule; we use Spikformer's (Zhou et al. 2023), that of the syops counter SeqSNN uses. Per prediction::

    E = E_MAC * MACs + E_AC * SOPs            E_MAC = 4.6 pJ, E_AC = 0.9 pJ (45 nm, 32-bit float)

A layer reading real values costs one MAC per multiply-accumulate; a layer reading spikes one accumulate per input
spike and fan-out; spiking self-attention Spikformer's formula, the twin's ``2 N^2 D`` MACs per block; BatchNorm is
folded and neither model is charged for biases, LIF updates, normalizations or memory traffic. Modules:
:mod:`~bgfn.energy.passes`, :mod:`~bgfn.energy.rules`, :mod:`~bgfn.energy.counts`, :mod:`~bgfn.energy.checkpoint`,
:mod:`~bgfn.energy.crosscheck` (SpikingJelly's counter on the same spikes), :mod:`~bgfn.energy.tables`,
:mod:`~bgfn.energy.record`, :mod:`~bgfn.energy.plots`.
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

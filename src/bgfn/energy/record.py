"""``results/<profile>/energy.json``: what notebook 05 hands to the results page (its one-paragraph result:
:func:`bgfn.report.energy_words.result_markdown`)."""

from __future__ import annotations

import pandas as pd

from bgfn.energy.checkpoint import EvaluationWindows, MeasuredModels
from bgfn.energy.crosscheck import Crosscheck
from bgfn.energy.tables import EnergyTotals

#: Top-level keys of ``energy.json`` that the results page reads.
REPORTED_KEYS = ("energy_uj_per_prediction", "macs", "sops", "reduction_pct", "reduction_pct_without_attention",
                 "e_mac_pj", "e_ac_pj", "time_steps", "dataset", "seed", "checkpoints", "windows", "metadata")


def energy_summary(measured: MeasuredModels, windows: EvaluationWindows, tables: dict[str, pd.DataFrame],
                   totals: EnergyTotals, paper_reduction_pct: float, rates: dict[str, float],
                   sweep_t: pd.DataFrame, break_even_rate: float, cross: Crosscheck, tolerance_pct: float,
                   e_mac: float, e_ac: float, metadata: dict) -> dict:
    """The content of ``energy.json`` (energies in µJ per prediction, operations per prediction).

    Parameters
    ----------
    measured, windows
        The networks and windows measured (:func:`bgfn.energy.checkpoint.load_measured`,
        :func:`bgfn.energy.checkpoint.evaluation_windows`).
    tables : dict
        Method -> per-layer energy table with its ``total`` row.
    totals : EnergyTotals
    paper_reduction_pct : float
        The paper's claim (``bgfn.paper.claims()``).
    rates : dict
        LIF layer -> firing rate.
    sweep_t : DataFrame
        Reduction vs ``T_s``.
    break_even_rate : float
        Mean input rate at which BGFN costs as much as the twin.
    cross : Crosscheck
        The SpikingJelly cross-check and its ``tolerance_pct``.
    e_mac, e_ac : float
        Energy per MAC and per accumulate, pJ.
    metadata : dict
        :func:`bgfn.config.run_metadata` of the profile.
    """
    ws = windows.windows
    return {
        "profile": measured.profile, "dataset": measured.dataset, "seed": measured.seed,
        "checkpoints": measured.relative_paths(),
        "checkpoint_epochs": {m: measured.cards[m].get("best_epoch") for m in measured.cards},
        "improved": measured.improved,
        "windows": {"source": "validation windows of bgfn.learning (bgfn.train.prepare_learning_data)",
                    "n_windows": int(len(ws)), "n_validation_windows": int(windows.n_validation),
                    "window_samples": int(ws.x.shape[1])},
        "e_mac_pj": e_mac, "e_ac_pj": e_ac, "time_steps": measured.time_steps,
        "energy_uj_per_prediction": {"bgfn": totals.bgfn_uj, "transformer": totals.twin_uj},
        "macs": {m: float(tables[m].set_index("layer").loc["total", "macs"]) for m in tables},
        "sops": {m: float(tables[m].set_index("layer").loc["total", "sops"]) for m in tables},
        "reduction_pct": totals.reduction_pct, "paper_reduction_pct": paper_reduction_pct,
        "attention_energy_uj": totals.attention_uj,
        "reduction_pct_without_attention": totals.reduction_without_attention_pct,
        "mean_input_firing_rate": totals.mean_rate, "break_even_firing_rate": break_even_rate,
        "lif_firing_rates": rates,
        "sweep_time_steps": sweep_t.to_dict(orient="list"),
        "crosscheck_spikingjelly": {"tolerance_pct": tolerance_pct, "max_abs_difference_pct": cross.worst_pct,
                                    "table": cross.table.reset_index().to_dict(orient="records"),
                                    "default_rules_reduction_pct": cross.strict_reduction_pct},
        "metadata": metadata,
    }

"""Figures of notebook 05: BGFN's firing rates, the energy per layer of both models, and the analytic sweeps.

Each function returns the figure; the notebook saves it (``results/<profile>/figures/energy_*.png``).
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import pandas as pd

from bgfn.energy.tables import total_energy_uj


def plot_firing_rates(rates: dict[str, float], title: str = ""):
    """Horizontal bars: firing rate of every LIF layer (:func:`bgfn.energy.counts.measure_firing_rates`),
    in execution order from the top.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = plt.subplots(figsize=(8, 0.28 * len(rates) + 1.2))
    ax.barh(range(len(rates)), list(rates.values()), color="tab:blue")
    ax.set_yticks(range(len(rates)), list(rates.keys()), fontsize=8)
    ax.invert_yaxis()
    ax.set_xlabel("firing rate (spikes per neuron and SNN step)")
    ax.set_title(title)
    ax.grid(axis="x", alpha=0.3)
    return fig


def plot_energy_per_layer(tables: dict[str, pd.DataFrame], methods=("bgfn", "transformer")):
    """Energy per prediction (µJ) of every counted layer, one panel per model, the total in the title.

    Parameters
    ----------
    tables : dict
        Method -> :func:`bgfn.energy.tables.table_from_counts` table (with its ``total`` row).

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, axes = plt.subplots(1, len(methods), figsize=(12, 0.25 * len(tables[methods[0]]) + 1.5))
    for ax, m in zip(axes, methods):
        t = tables[m][tables[m]["layer"] != "total"]
        ax.barh(range(len(t)), t["energy_uj"], color="tab:blue" if m == "bgfn" else "tab:orange")
        ax.set_yticks(range(len(t)), t["layer"], fontsize=7)
        ax.invert_yaxis()
        ax.set_xlabel("energy per prediction (µJ)")
        ax.set_title(f"{m}: {total_energy_uj(tables[m]):.3g} µJ")
        ax.grid(axis="x", alpha=0.3)
    fig.tight_layout()
    return fig


def plot_sweeps(sweep_t: pd.DataFrame, sweep_r: pd.DataFrame, time_steps: int, reduction: float,
                mean_rate: float, paper_reduction: float):
    """Reduction against the twin vs ``T_s`` (left) and vs BGFN's mean input firing rate (right).

    Parameters
    ----------
    sweep_t, sweep_r : DataFrame
        :func:`bgfn.energy.counts.reduction_vs_time_steps` and :func:`~bgfn.energy.counts.reduction_vs_rate`.
    time_steps, reduction, mean_rate : int, float, float
        The trained model (a star on both panels): its ``T_s``, reduction (%) and mean input rate.
    paper_reduction : float
        The paper's reduction, % (dashed line).

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 3.8))
    a1.plot(sweep_t["time_steps"], sweep_t["reduction_pct"], "o-", label="this reproduction (rates fixed)")
    a1.plot([time_steps], [reduction], "k*", ms=12, label=f"trained model, T_s = {time_steps}")
    a1.set_xscale("log", base=2)
    a1.set_xlabel("SNN time steps T_s")
    a2.plot(sweep_r["mean_firing_rate"], sweep_r["reduction_pct"], "-", label="this reproduction")
    a2.plot([mean_rate], [reduction], "k*", ms=12, label=f"trained model (r = {mean_rate:.3f})")
    a2.axhline(0.0, color="gray", lw=0.8)
    a2.set_xlabel("mean input firing rate of BGFN")
    for ax in (a1, a2):
        ax.axhline(paper_reduction, color="tab:red", ls="--", label=f"paper ({paper_reduction} %)")
        ax.set_ylabel("energy reduction vs Transformer (%)")
        ax.legend(fontsize=8)
        ax.grid(alpha=0.3)
    fig.tight_layout()
    return fig

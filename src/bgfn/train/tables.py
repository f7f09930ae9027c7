"""The training tables of notebook 03: one row per run (:func:`cards_table`), the seed aggregate
(:func:`summary_table`), the windows of each dataset (:func:`windows_table`) and ``training.json``.

Wall-clock columns vary from run to run: the result tables are saved without them (:func:`without_timing`), so
the same profile run twice gives byte-identical tables, and the times go to a table of their own.
"""

from __future__ import annotations

import pandas as pd

from bgfn.config import run_metadata
from bgfn.learning import REFERENCES, split_summary


def cards_table(cards: list[dict]):
    """One row per run: dataset, method, seed, params, learning rate, epochs, wall time, validation RMSE and
    references (m), and the lowest training loss (:func:`lowest_train_loss`)."""
    cols = ["dataset", "method", "seed", "params", "lr", "epochs_run", "best_epoch", "wall_time_s", "n_train", "n_val",
            "val_rmse_m", "val_rmse_initial_m", *REFERENCES.values(), "train_loss_min", "device"]
    return pd.DataFrame([{**{c: card.get(c) for c in cols}, "val_rmse_initial_m": initial_val_rmse(card),
                          "train_loss_min": lowest_train_loss(card)} for card in cards], columns=cols)


def initial_val_rmse(card: dict) -> float | None:
    """Validation RMSE (m) of the run's initial network (epoch 0 of its history), None for an older card."""
    first = (card.get("history") or [{}])[0]
    return first.get("val_rmse_m") if first.get("epoch") == 0 else None


def lowest_train_loss(card: dict) -> float | None:
    """Lowest training loss over the run's training epochs (MSE of the normalized increments), None before any.

    The targets are standardized on all training windows, so predicting their mean scores 1.0 there (about 1 on
    an evenly spaced subsample, ``max_train_windows``): a value well below 1 says that the network fitted its
    training windows, whatever it does on the validation block.
    """
    losses = [h["train_loss"] for h in card.get("history") or [] if h.get("epoch", 0) >= 1
              and h.get("train_loss") is not None]
    return min(losses) if losses else None


#: Wall-clock columns of :func:`cards_table` / :func:`summary_table`: they vary from run to run, so the result
#: tables are saved without them (:func:`without_timing`) and the times go to a table of their own.
TIMING_COLUMNS = ("wall_time_s", "train_time_s_mean", "train_time_s_total")


def without_timing(table):
    """``table`` without :data:`TIMING_COLUMNS`: the same profile run twice gives byte-identical tables."""
    return table.drop(columns=[c for c in TIMING_COLUMNS if c in table.columns])


def timing_table(table):
    """The key columns of ``table`` and its :data:`TIMING_COLUMNS` (wall-clock seconds)."""
    keys = [c for c in ("dataset", "method", "seed") if c in table.columns]
    return table[keys + [c for c in TIMING_COLUMNS if c in table.columns]]


def summary_table(cards: list[dict]):
    """Per dataset and method: parameters, epochs, training time and validation RMSE over seeds (mean, std)."""
    runs = cards_table(cards)
    g = runs.groupby(["dataset", "method"], sort=False)
    out = g.agg(params=("params", "first"), lr=("lr", "first"), seeds=("seed", "count"),
                epochs_mean=("epochs_run", "mean"),
                train_time_s_mean=("wall_time_s", "mean"), train_time_s_total=("wall_time_s", "sum"),
                val_rmse_m_mean=("val_rmse_m", "mean"), val_rmse_m_std=("val_rmse_m", "std"),
                **{col: (col, "first") for col in REFERENCES.values()})
    return out.reset_index()


def windows_table(prepared: dict) -> pd.DataFrame:
    """One row per dataset: its GNSS rate (Hz) and :func:`bgfn.learning.split_summary` of its learning data
    (``prepared``: ``{dataset: TrainingDataset}`` of :func:`bgfn.train.profile.prepare_datasets`)."""
    return pd.DataFrame([{"dataset": name, "gnss_rate_hz": d.drive.meta.get("gnss_rate_hz"), **split_summary(d.data)}
                         for name, d in prepared.items()])


def training_metrics(plan, prepared: dict, runs: pd.DataFrame, summary: pd.DataFrame,
                     windows: pd.DataFrame) -> dict:
    """``training.json`` of notebook 03: the run and summary tables (with their wall-clock columns), the windows
    table, the learning options per dataset, the evaluation outages kept out of training per dataset and the run
    metadata (:func:`bgfn.config.run_metadata`).

    Parameters
    ----------
    plan : TrainingPlan
        Profile and outages (:class:`bgfn.train.profile.TrainingPlan`).
    prepared : dict
        ``{dataset: TrainingDataset}`` (:func:`bgfn.train.profile.prepare_datasets`).
    runs, summary, windows : DataFrame
        :func:`cards_table`, :func:`summary_table`, :func:`windows_table`.
    """
    return {
        "runs": runs.to_dict(orient="records"),
        "summary": summary.to_dict(orient="records"),
        "windows": windows.to_dict(orient="records"),
        "learning_options": {name: d.data.options for name, d in prepared.items()},
        # per dataset, the outages its learning data were built without (a rule's differ from drive to drive)
        "outage_windows": {name: d.data.info.get("outage_windows", plan.dataset_windows(name, d))
                           for name, d in prepared.items()},
        "meta": run_metadata(plan.profile),
    }

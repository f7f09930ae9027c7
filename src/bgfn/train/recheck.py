"""Were the runs that never learned short of data? Each one trained again on all its training windows.

A profile may cap the training windows of a run (``train.optimizer.max_train_windows``; quick: 1000, evenly
spaced in time, (deviations page), so a run whose validation loss never beats its initial network
(``best_epoch`` 0) might have learned from more. With ``train.recheck_all_windows: true``, every such run whose
cap left windows out is trained once more, the same method, seed, learning rate and budget, on all of them,
into ``results/<profile>/models/all_windows/<dataset>/`` (:func:`bgfn.train.checkpoints.all_windows_models_dir`; the
reported networks are not touched). ``train.recheck_runs: first`` trains again only the first such run (in seed
order) of each dataset and method: the question is whether the method learns from the windows the cap left out,
which one run answers; ``all`` (default) trains every such run. The table
(:func:`recheck_table`) and the lines of notebook 03 (:func:`bgfn.report.training_words.recheck_lines`) say
whether it then improved.
"""

from __future__ import annotations

import pandas as pd

from bgfn.parallel import Runner
from bgfn.train import checkpoints
from bgfn.train.options import optimizer_options, size_config
from bgfn.train.tables import initial_val_rmse, lowest_train_loss
from bgfn.train.tasks import TrainingRun, train_runs

#: Columns of :func:`recheck_table`: the run as reported (capped) and trained again on all windows.
RECHECK_COLUMNS = ("dataset", "method", "seed", "lr", "n_train", "best_epoch", "n_train_all", "best_epoch_all",
                   "epochs_run_all", "val_rmse_initial_m", "val_rmse_m_all", "train_loss_min_all")


#: ``train.recheck_runs``: which of the runs that never learned are trained again (module docstring).
RECHECK_RUNS = ("all", "first")


def enabled(train_cfg: dict) -> bool:
    """``train.recheck_all_windows`` of a ``train:`` section."""
    return bool(train_cfg["recheck_all_windows"])


def first_per_method(cards: list[dict]) -> list[dict]:
    """Of ``cards``, the one with the lowest seed of each (dataset, method), in the cards' order."""
    first: dict[tuple, dict] = {}
    for card in cards:
        key = (card["dataset"], card["method"])
        if key not in first or int(card["seed"]) < int(first[key]["seed"]):
            first[key] = card
    keep = {id(c) for c in first.values()}
    return [c for c in cards if id(c) in keep]


def capped_runs(cards: list[dict], prepared: dict, train_cfgs: dict[str, dict]) -> list[dict]:
    """The cards of the runs that never improved on their initial network (``best_epoch`` 0) and whose
    ``max_train_windows`` left some of their dataset's training windows out."""
    out = []
    for card in cards:
        if card.get("best_epoch") is None or int(card["best_epoch"]) >= 1:
            continue
        cap = optimizer_options(train_cfgs[card["dataset"]])["max_train_windows"]
        if cap is not None and len(prepared[card["dataset"]].data.train) > int(cap):
            out.append(card)
    return out


def recheck_all_windows(plan, cards: list[dict], prepared: dict, train_cfgs: dict[str, dict],
                        device: str | None = None, runner: Runner | None = None) -> list[dict]:
    """Train every run of :func:`capped_runs` again on all training windows when the plan's profile sets
    ``train.recheck_all_windows`` (else nothing), spread over ``runner``; return pairs ``{'capped': card, 'all':
    new card}`` (a completed network is not trained again).

    Parameters
    ----------
    plan : bgfn.train.TrainingPlan
    prepared : dict
        ``{dataset: TrainingDataset}`` (:func:`bgfn.train.profile.prepare_datasets`).
    train_cfgs : dict
        ``{dataset: train: section with the selected learning rates}``, as the reported runs had.
    """
    if not enabled(plan.train_cfg):
        return []
    which = plan.train_cfg["recheck_runs"]
    if which not in RECHECK_RUNS:
        raise ValueError(f"train.recheck_runs must be one of {RECHECK_RUNS}, got {which!r}")
    capped, runs = capped_runs(cards, prepared, train_cfgs), []
    if which == "first":
        capped = first_per_method(capped)
    for card in capped:
        dataset, method, seed = card["dataset"], card["method"], int(card["seed"])
        tc = dict(train_cfgs[dataset])
        tc["optimizer"] = {**(tc.get("optimizer") or {}), "max_train_windows": None}
        runs.append(TrainingRun(f"{dataset} {method} seed {seed} (all windows)", method, prepared[dataset].data,
                                size_config(tc, method), tc, seed, checkpoints.all_windows_models_dir(plan.profile,
                                                                                                        dataset),
                                device, {"dataset": dataset, "profile": plan.profile, "size": tc.get("size")}))
    new = train_runs(runs, runner, desc="recheck on all windows")
    return [{"capped": c, "all": n} for c, n in zip(capped, new)]


def recheck_table(pairs: list[dict]) -> pd.DataFrame:
    """One row per rechecked run (:data:`RECHECK_COLUMNS`)."""
    rows = [{"dataset": c["dataset"], "method": c["method"], "seed": c["seed"], "lr": c.get("lr"),
             "n_train": c.get("n_train"), "best_epoch": c.get("best_epoch"), "n_train_all": a.get("n_train"),
             "best_epoch_all": a.get("best_epoch"), "epochs_run_all": a.get("epochs_run"),
             "val_rmse_initial_m": initial_val_rmse(a), "val_rmse_m_all": a.get("val_rmse_m"),
             "train_loss_min_all": lowest_train_loss(a)}
            for c, a in ((p["capped"], p["all"]) for p in pairs)]
    return pd.DataFrame(rows, columns=list(RECHECK_COLUMNS))

"""The learning rate of every method, chosen the same way: one grid, one budget, one seed, on a tuning split
inside the training windows (:func:`bgfn.learning.inner_split`); the validation block is never used.

The budget of one tuning run is the profile's optimizer with ``train.lr_search.epochs``, ``patience``,
``max_train_windows`` and ``max_val_windows`` laid over its ``epochs``, early-stopping ``patience`` and window caps
(:func:`search_train_config`): the same smaller budget for every method and rate, so that the search costs less
than training every rate to the end on every window.

Notebook 03 runs the search per dataset (:func:`search_profile_learning_rates`) and saves it as
``tables/lr_search.csv``; the networks it trains, and those the outage evaluation trains later
(:func:`tuned_train_config`), use the selected rates.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Callable

import pandas as pd

from bgfn import settings
from bgfn.config import results_dir
from bgfn.errors import DataError
from bgfn.learning import LearningData, inner_split
from bgfn.parallel import Runner
from bgfn.train import checkpoints
from bgfn.train.options import method_lr, size_config, train_subsection
from bgfn.train.tasks import TrainingRun, train_runs

#: ``train.lr_search``: learning rates tried for every method on :func:`bgfn.learning.inner_split` (null: none).
#: ``extend``: when a method's best rate is the grid's smallest or largest, up to this many further rates are
#: tried beyond it, one grid step (the ratio of the two rates at that end) at a time, so no method's choice
#: is cut off by the grid's ends. ``epochs``, ``patience``, ``max_train_windows``, ``max_val_windows``: the budget of
#: one tuning run (null: the optimizer's), the same for every method and rate.
LR_SEARCH_DEFAULTS: dict[str, Any] = settings.defaults("train.lr_search")   # their home: bgfn.settings.LrSearch
#: The keys of ``train.lr_search`` that replace the optimizer's in a tuning run.
SEARCH_BUDGET_KEYS: tuple[str, ...] = ("epochs", "patience", "max_train_windows", "max_val_windows")
#: The saved search of notebook 03 (``results/<profile>/tables/``): one row per dataset, method and rate.
LR_SEARCH_FILE = "lr_search.csv"
LR_SEARCH_COLUMNS = ("dataset", "method", "lr", "tuning_rmse_m", "tuning_loss", "epochs_run", "selected")


def lr_search_options(train_cfg: dict | None) -> dict:
    """``train.lr_search`` with defaults filled in (unknown keys raise DataError)."""
    return train_subsection(train_cfg, "lr_search", LR_SEARCH_DEFAULTS)


def search_train_config(train_cfg: dict) -> dict:
    """The ``train:`` section one tuning run trains with: ``train.lr_search.epochs``, ``patience``,
    ``max_train_windows`` and ``max_val_windows`` (when set) replace the optimizer's ``epochs``, early-stopping
    ``patience`` and caps on the training and the tuning windows (evenly spaced subsamples,
    :func:`bgfn.train.even_subset`); everything else as the profile's."""
    ls = lr_search_options(train_cfg)
    budget = {k: int(ls[k]) for k in SEARCH_BUDGET_KEYS if ls[k] is not None}
    if not budget:
        return train_cfg
    return {**train_cfg, "optimizer": {**(train_cfg.get("optimizer") or {}), **budget}}


def search_learning_rates(data: LearningData, methods, train_cfg: dict, out_dir: str | Path | None = None,
                          runner: Runner | None = None) -> pd.DataFrame:
    """Train every method once per learning rate of ``train.lr_search.grid`` on a tuning split inside the
    training windows (:func:`bgfn.learning.inner_split`) and mark the rate with the lowest tuning loss.

    Every method gets the same grid, budget (the profile's optimizer, capped by ``train.lr_search.epochs`` and
    ``patience``: :func:`search_train_config`) and seed, so none is tuned more than another; the validation block
    of ``data`` is never used.

    Returns
    -------
    DataFrame
        ``method, lr, tuning_rmse_m, tuning_loss, epochs_run, selected`` (one row per method and rate).
    """
    table = search_profile_rates({None: (data, out_dir)}, methods, train_cfg, runner)
    return table.drop(columns="dataset").reset_index(drop=True)


def search_profile_rates(learning: dict, methods, train_cfg: dict, runner: Runner | None = None,
                         split: Callable = inner_split, extra_card: dict | None = None) -> pd.DataFrame:
    """The search of :func:`search_learning_rates` for several datasets at once (``{dataset: (LearningData,
    out_dir)}``), in rounds of independent runs spread over ``runner``: the grid, then each ``extend`` step (a
    rate beyond a grid's edge depends on the rates tried before it). Rows: dataset, method, rate (sorted).

    ``split(data, fraction)`` makes the tuning split (default :func:`bgfn.learning.inner_split`; a learned
    odometer's: :func:`bgfn.learning.odometry.inner_speed_split`); ``tuning_rmse_m`` holds the objective's error
    (m for increments, m/s for a speed); ``extra_card`` is added to every run's card."""
    ls = lr_search_options(train_cfg)
    grid = [float(v) for v in (ls["grid"] or [])]
    if not grid:
        raise DataError("train.lr_search", "grid", "a non-empty list of learning rates", repr(ls["grid"]))
    grid = sorted(set(grid))
    budget = search_train_config(train_cfg)
    inner = {name: split(data, float(ls["fraction"])) for name, (data, _) in learning.items()}
    tried: dict[tuple, list[dict]] = {(name, m): [] for name in learning for m in methods}

    def run(name, method: str, lr: float) -> TrainingRun:
        cfg = {**budget, "lr": {**(budget.get("lr") or {}), method: lr}}
        out_dir = learning[name][1]
        sub = Path(out_dir) / f"lr{lr:g}" if out_dir is not None else None
        label = f"{'' if name is None else name + ' '}{method} lr {lr:g}"
        return TrainingRun(label, method, inner[name], size_config(train_cfg, method), cfg, int(ls["seed"]), sub,
                           None, extra_card)

    pending = [(key, lr) for key in tried for lr in grid]
    for step in range(int(ls["extend"]) + 1):
        if not pending:
            break
        cards = train_runs([run(*key, lr) for key, lr in pending], runner, desc="lr search" + (f" +{step}" if step else ""))
        for (key, lr), card in zip(pending, cards):
            error = card["val_rmse_m"] if "val_rmse_m" in card else card["val_rmse_mps"]
            tried[key].append({"dataset": key[0], "method": key[1], "lr": lr, "tuning_rmse_m": error,
                               "tuning_loss": card["best_val_loss"], "epochs_run": card["epochs_run"]})
        pending = [(key, nxt) for key, rows in tried.items()
                   if (nxt := next_learning_rate([r["lr"] for r in rows],
                                                 min(rows, key=lambda r: r["tuning_loss"])["lr"])) is not None]
    rows = [r for key in tried for r in sorted(tried[key], key=lambda r: r["lr"])]
    table = pd.DataFrame(rows)
    best = table.groupby(["dataset", "method"], sort=False, dropna=False)["tuning_loss"].idxmin()
    table["selected"] = table.index.isin(best.to_numpy())
    return table


def next_learning_rate(tried, best: float) -> float | None:
    """The rate one grid step beyond ``best`` when ``best`` is the smallest or largest of ``tried``
    (geometric step: the ratio of the two rates at that end); None when ``best`` is inside, or the step is
    undefined (fewer than two positive rates at that end)."""
    rates = sorted(set(float(r) for r in tried))
    if len(rates) < 2:
        return None
    if best == rates[-1] and rates[-2] > 0:
        return rates[-1] * rates[-1] / rates[-2]
    if best == rates[0] and rates[0] > 0:
        return rates[0] * rates[0] / rates[1]
    return None


def with_selected_lr(train_cfg: dict, search: pd.DataFrame | None) -> dict:
    """``train_cfg`` with ``lr`` set to the selected rate of each method in ``search`` (unchanged if None)."""
    if search is None or len(search) == 0:
        return train_cfg
    chosen = search[search["selected"].astype(bool)]
    return {**train_cfg, "lr": {**(train_cfg.get("lr") or {}),
                                **{str(m): float(v) for m, v in zip(chosen["method"], chosen["lr"])}}}


def tuned_train_config(cfg: dict, profile: str, dataset: str) -> dict:
    """The profile's ``train:`` section with the learning rates notebook 03 selected for ``dataset``
    (``tables/lr_search.csv``); unchanged when the profile has no search or it has not run."""
    tc = cfg["train"]
    if not lr_search_options(tc)["grid"]:
        return tc
    path = results_dir(profile, create=False) / "tables" / LR_SEARCH_FILE
    if not path.exists():
        return tc
    return selected_train_configs(tc, pd.read_csv(path), [dataset])[dataset]


def search_profile_learning_rates(profile: str, learning: dict[str, LearningData], methods, train_cfg: dict,
                                  runner: Runner | None = None) -> pd.DataFrame | None:
    """:func:`search_learning_rates` for every dataset of ``learning`` (``{dataset: LearningData}``), all its runs
    spread over ``runner``; the runs go to ``results/<profile>/models/<dataset>/lr_search/``.

    Returns
    -------
    DataFrame or None
        :data:`LR_SEARCH_COLUMNS`, datasets in the order of ``learning``; None when ``train.lr_search.grid`` is
        empty (every method then uses ``train.lr``).
    """
    if not lr_search_options(train_cfg)["grid"]:
        return None
    table = search_profile_rates({name: (data, checkpoints.models_dir(profile, name) / "lr_search")
                                  for name, data in learning.items()}, methods, train_cfg, runner)
    return table[list(LR_SEARCH_COLUMNS)]


def selected_train_configs(train_cfg: dict, search: pd.DataFrame | None, datasets) -> dict[str, dict]:
    """``{dataset: train_cfg with the rates search selected for it}`` (:func:`with_selected_lr` of the rows of
    that dataset); ``train_cfg`` unchanged for every dataset when ``search`` is None."""
    if search is None:
        return {name: train_cfg for name in datasets}
    return {name: with_selected_lr(train_cfg, search[search["dataset"] == name]) for name in datasets}


def chosen_learning_rates(train_cfgs: dict[str, dict], methods) -> dict[str, dict[str, float]]:
    """``{dataset: {method: learning rate}}`` of the per-dataset ``train:`` sections ``train_cfgs``."""
    return {name: {m: method_lr(tc, m) for m in methods} for name, tc in train_cfgs.items()}

"""A profile's networks as independent runs: what one run trains (:class:`TrainingRun`) and all of them spread
over a :class:`bgfn.parallel.Runner` (:func:`train_runs`).

Every run seeds itself and sets its own thread count (:func:`bgfn.train.loop.train_model`), and the cards come
back in the order of the runs, so the tables built from them are the same with 1 job or many.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Sequence

from bgfn.learning import LearningData
from bgfn.parallel import Runner
from bgfn.train.loop import train_model
from bgfn.train.options import optimizer_options


@dataclass(frozen=True)
class TrainingRun:
    """One network to train: the arguments of :func:`bgfn.train.loop.train_model` and a label for its line.

    Attributes
    ----------
    label : str
        What the run is, for the progress line (``<dataset> <method> seed <k>``).
    method : str
    data : LearningData
    size_cfg : dict
        Model constructor keywords.
    train_cfg : dict
        The ``train:`` section it trains with (learning rates included).
    seed : int
    out_dir : Path or None
        Where its checkpoint and card go (None: nothing written).
    device : str or None
    extra_card : dict or None
        Added to its card.
    """

    label: str
    method: str
    data: LearningData
    size_cfg: dict
    train_cfg: dict
    seed: int
    out_dir: Path | None
    device: str | None = None
    extra_card: dict | None = None


def train_run(run: TrainingRun) -> dict:
    """Train one run (no per-epoch bar: the runner reports the run); return its card."""
    return train_model(run.method, run.data, run.size_cfg, run.train_cfg, seed=run.seed, out_dir=run.out_dir,
                       device=run.device, progress=False, extra_card=run.extra_card)


def run_summary(card: dict) -> str:
    """What a finished run reports on its progress line: epochs, best validation loss and where, RMSE."""
    error = (f"val RMSE {card['val_rmse_m']:.3f} m" if "val_rmse_m" in card else
             f"val RMSE {card['val_rmse_mps']:.3f} m/s" if "val_rmse_mps" in card else "")
    return (f"{card['epochs_run']} epochs, best val loss {card['best_val_loss']:.4g} (epoch {card['best_epoch']})"
            + (f", {error}" if error else ""))


def train_runs(runs: Sequence[TrainingRun], runner: Runner | None = None, desc: str = "training",
               echo: Callable[[str], Any] | None = None) -> list[dict]:
    """Train every run, spread over ``runner`` (default: one after the other), the costliest first
    (:func:`expected_cost`); the cards in the runs' order."""
    runs = list(runs)
    return (runner or Runner()).map(train_run, [(r,) for r in runs], labels=[r.label for r in runs],
                                    summary=run_summary, desc=desc, echo=echo, cost=[expected_cost(r) for r in runs])


#: Rough relative CPU time of one training window per method at one size block (the quick runs' progress lines,
#: 2026-11-27): the order in which a pool starts the runs (:func:`expected_cost`), never a result.
METHOD_COST: dict[str, float] = {"transformer": 1.2, "bgfn": 1.0, "at_lstm": 0.3, "mlp": 0.03}


def expected_cost(run: TrainingRun) -> float:
    """A run's expected cost for the pool's start order (:meth:`bgfn.parallel.Runner.map`): the method's
    :data:`METHOD_COST` x its training windows (at most the optimizer's ``max_train_windows``) x its epoch budget."""
    opt = optimizer_options(run.train_cfg)
    cap = opt["max_train_windows"]
    windows = len(run.data.train) if cap is None else min(len(run.data.train), int(cap))
    return METHOD_COST.get(run.method, 1.0) * windows * int(opt["epochs"])

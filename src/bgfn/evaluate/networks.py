"""The trained networks of the evaluation: loading notebook 03's checkpoints (:mod:`bgfn.train.checkpoints`), and
training the missing ones."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from bgfn import train
from bgfn.errors import DataError
from bgfn.evaluate.hybrid import NavContext
from bgfn.train.checkpoints import card_path, checkpoint_path


def load_model(path: str | Path):
    """A checkpoint of :mod:`bgfn.train` on the CPU, with ``val_rmse_m`` (validation RMSE of one increment,
    m, from its JSON card; NaN without a card) attached."""
    model = train.load_trained(path, device="cpu")
    card = card_path(path)
    model.val_rmse_m = float(json.loads(card.read_text()).get("val_rmse_m", np.nan)) if card.exists() else np.nan
    return model


def ensure_models(cfg: dict, profile: str, dataset: str, ctx: NavContext | None, methods, seeds, windows,
                  train_missing: bool = True, progress: bool = False) -> dict:
    """Load notebook 03's networks of ``dataset``; train the missing ones with the same code and settings
    (training excludes the evaluation outages ``windows``; ``ctx``, the drive's navigation context, is read only
    then).

    Returns
    -------
    dict
        ``{(method, seed): TrainedModel}``.
    """
    models, data = {}, None
    tc = train.tuned_train_config(cfg, profile, dataset)      # notebook 03's selected learning rates
    for method in methods:
        for seed in seeds:
            path = checkpoint_path(profile, dataset, method, seed)
            if not path.exists():
                if not train_missing:
                    raise DataError(path, "checkpoint", "a network trained by notebook 03 "
                                    "(run notebooks/03_bgfn_training.ipynb first)", "missing")
                if data is None:
                    data = train.prepare_learning_data(cfg, dataset, attitude=ctx.attitude_table(), drive=ctx.drive,
                                                       outage_windows=windows)
                train.train_model(method, data, train.size_config(tc, method), tc, seed=seed, out_dir=path.parent,
                                  progress=progress, extra_card={"dataset": dataset, "profile": profile,
                                                                 "size": tc.get("size"),
                                                                 "trained_by": "notebook 04 (missing)"})
            models[(method, seed)] = load_model(path)
    return models

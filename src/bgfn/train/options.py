"""The optimization settings of a profile's ``train:`` section: optimizer and schedule, per-method learning rate,
model size blocks, and the even subsample of windows a small budget trains on.

Every method gets the same budget (paper Sec. 4.1: batch 8, up to 1000 epochs): AdamW, the same epochs, batch
size, schedule and early stopping on the validation loss. Learning rates can differ per method (``lr`` mapping
of the ``train:`` section; :mod:`bgfn.train.lr_search` chooses them).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from bgfn import settings
from bgfn.errors import DataError

#: Defaults of the optimization keys (``train.optimizer``; their home: :class:`bgfn.settings.Optimizer`).
OPTIMIZER_DEFAULTS: dict[str, Any] = settings.defaults("train.optimizer")


def train_subsection(train_cfg: dict | None, key: str, defaults: dict) -> dict:
    """``train.<key>`` with ``defaults`` filled in; an unknown key raises DataError naming it."""
    opt = dict((train_cfg or {}).get(key) or {})
    unknown = set(opt) - set(defaults)
    if unknown:
        raise DataError(f"train.{key}", sorted(unknown)[0], f"one of {', '.join(defaults)}")
    return {**defaults, **opt}


def optimizer_options(train_cfg: dict | None) -> dict:
    """``train.optimizer`` keys with defaults filled in (unknown keys raise DataError)."""
    return train_subsection(train_cfg, "optimizer", OPTIMIZER_DEFAULTS)


def method_lr(train_cfg: dict | None, method: str) -> float:
    """Learning rate of ``method``: ``train.lr[method]`` if set, else ``train.optimizer.lr``."""
    per = (train_cfg or {}).get("lr") or {}
    return float(per.get(method, optimizer_options(train_cfg)["lr"]))


def size_config(train_cfg: dict, method: str, size: str | None = None) -> dict:
    """Constructor keywords of ``method`` for the named ``size`` (default ``train.size``) from ``train.sizes``."""
    size = size or train_cfg.get("size")
    try:
        return dict(train_cfg["sizes"][method][size] or {})
    except (KeyError, TypeError):
        raise DataError("train.sizes", f"{method}.{size}", "a size block for this method and size") from None


def even_subset(n: int, k: int | None) -> np.ndarray:
    """Indices of ``k`` evenly spaced items of ``n`` (all when ``k`` is None or >= n), sorted and unique."""
    if k is None or k >= n:
        return np.arange(n)
    return np.unique(np.linspace(0, n - 1, int(k)).round().astype(int))

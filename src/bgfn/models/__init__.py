"""BGFN (spiking Transformer) and the baselines, built by name with :func:`build_model`.

Method ids: ``bgfn`` (paper Sec. 3.2), ``transformer`` (ANN twin of BGFN), ``at_lstm`` (attention LSTM,
Chen et al. 2024), ``mlp`` (static MLP).
"""

from __future__ import annotations

import functools
from pathlib import Path

from torch import nn

from bgfn.io import sources_hash

from .baselines import ATLSTM, MLP, TransformerTwin
from .bgfn import BGFN

#: Method id -> model class.
MODELS: dict[str, type[nn.Module]] = {
    "bgfn": BGFN,
    "transformer": TransformerTwin,
    "at_lstm": ATLSTM,
    "mlp": MLP,
}

METHODS = tuple(MODELS)


def build_model(method: str, size_cfg: dict | None = None, in_channels: int = 9) -> nn.Module:
    """Build model ``method`` with the keyword arguments in ``size_cfg``.

    Parameters
    ----------
    method : str
        One of :data:`METHODS`.
    size_cfg : dict, optional
        Constructor keywords of the model class (e.g. ``{'dim': 64, 'depth': 2}`` for ``bgfn``); unknown keys
        raise ``TypeError``.
    in_channels : int
        Input channels per sample (9 for Eq. eq21; more with extra channels), unless ``size_cfg`` sets it.
    """
    if method not in MODELS:
        raise ValueError(f"unknown method {method!r}; expected one of {METHODS}")
    kwargs = {"in_channels": in_channels, **(size_cfg or {})}
    return MODELS[method](**kwargs)


@functools.cache
def definition_fingerprint() -> str:
    """Hash of this package's source files: the code that defines every network (layers, LIF, its kernels).

    A trained network is reused only when it was trained under the same definition (the configuration hash of
    :func:`bgfn.train.loop.train_model`), so that a changed layer (a removed bias, other LIF dynamics) trains it
    again instead of loading weights the code no longer matches, or silently reusing a network of other dynamics.
    Any edit of these files counts, a comment too: the safe side for results a reader must be able to trust.
    """
    return sources_hash(sorted(Path(__file__).parent.glob("*.py")))[:16]


def count_parameters(model: nn.Module) -> int:
    """Number of trainable parameters."""
    return sum(p.numel() for p in model.parameters() if p.requires_grad)


def is_spiking(model: nn.Module) -> bool:
    """True for models with LIF state that must be reset between batches."""
    return bool(getattr(model, "spiking", False))


__all__ = ["BGFN", "MLP", "ATLSTM", "TransformerTwin", "MODELS", "METHODS", "build_model", "count_parameters",
           "definition_fingerprint", "is_spiking"]

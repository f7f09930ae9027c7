"""A trained network in use: the device, the forward pass in normalized units, and :class:`TrainedModel`, which
predicts delta_p_gps in metres from raw drive tables (the pseudo-GNSS increments of an outage, Eq. pred-gps).

A best checkpoint ``<method>_seed<k>.pt`` (written by :func:`bgfn.train.loop.train_model`) holds the weights,
the normalization, the learning options and the model size: all :func:`load_trained` needs.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
import torch
from spikingjelly.activation_based import functional
from torch import nn

from bgfn.errors import DataError
from bgfn.learning import Normalizer, WindowSet, from_target_frame, prediction_windows
from bgfn.models import build_model, is_spiking
from bgfn.train import checkpoints


def pick_device(device: str | None = None) -> torch.device:
    """``device`` if given, else CUDA when available, else CPU."""
    if device:
        return torch.device(device)
    return torch.device("cuda" if torch.cuda.is_available() else "cpu")


@torch.no_grad()
def predict_normalized(model: nn.Module, x: np.ndarray | torch.Tensor, batch_size: int = 64,
                       device: torch.device | str = "cpu") -> np.ndarray:
    """Model outputs [M, 2] (normalized units) for normalized inputs ``x`` [M, N, C]; eval mode."""
    model.eval()
    xt = torch.as_tensor(x, dtype=torch.float32)
    out = []
    for i in range(0, len(xt), batch_size):
        out.append(model(xt[i:i + batch_size].to(device)).cpu())
        if is_spiking(model):
            functional.reset_net(model)
    return torch.cat(out).numpy() if out else np.zeros((0, 2), np.float32)


@dataclass
class TrainedModel:
    """A trained model with what it needs to predict delta_p_gps in metres from raw drive tables."""

    method: str
    model: nn.Module
    norm: Normalizer
    options: dict
    size_cfg: dict
    device: torch.device = torch.device("cpu")

    def predict_windows(self, ws: WindowSet, batch_size: int = 64) -> np.ndarray:
        """delta_p_gps (north, east), m, [M, 2], for the (raw) windows ``ws``."""
        z = self.norm.y_inverse(predict_normalized(self.model, self.norm.x(ws.x), batch_size, self.device))
        return from_target_frame(z, ws.yaw_ref, self.options.get("target_frame", "ned"))

    def predict_increments(self, imu, attitude, epochs) -> np.ndarray:
        """delta_p_gps [K, 2] (m) for the increments ``epochs[i] -> epochs[i+1]`` (pseudo-GNSS epochs of an
        outage, Eq. pred-gps); see :func:`bgfn.learning.prediction_windows`."""
        ws = prediction_windows(imu, attitude, epochs, window=int(self.options["window"]),
                                alignment=self.options["alignment"], yaw_encoding=self.options["yaw_encoding"],
                                extra_channels=tuple(self.options["extra_channels"]))
        return self.predict_windows(ws)

    def increment_table(self, imu, attitude, epochs):
        """:meth:`predict_increments` as the table :class:`bgfn.nav.outages.IncrementPseudoGps` reads:
        ``time`` (end of each increment, s), ``delta_p_n``, ``delta_p_e`` (m)."""
        d = self.predict_increments(imu, attitude, epochs)
        return pd.DataFrame({"time": np.asarray(epochs, float)[1:], "delta_p_n": d[:, 0], "delta_p_e": d[:, 1]})


def load_trained(path: str | Path, device: str | None = None) -> TrainedModel:
    """Load a best checkpoint ``<method>_seed<k>.pt`` written by :func:`bgfn.train.loop.train_model`.

    Raises
    ------
    bgfn.errors.DataError
        The file is not a checkpoint of ours, or its weights do not fit the network the code builds (written by
        another definition of its layers); the message names the file and the differing weights.
    """
    dev = pick_device(device)
    ck = checkpoints.read_checkpoint(path, dev)
    model = build_model(ck["method"], ck["size_cfg"], in_channels=ck["in_channels"]).to(dev)
    mismatch = _weights_mismatch(model, ck["state_dict"])
    if mismatch:
        raise DataError(path, "state_dict", f"the weights of the {ck['method']} network this code builds (delete the "
                        "checkpoint and its card to train it again)", mismatch)
    model.load_state_dict(ck["state_dict"])
    model.eval()
    return TrainedModel(ck["method"], model, Normalizer.from_dict(ck["norm"]), ck["options"], ck["size_cfg"], dev)


def _weights_mismatch(model: nn.Module, state: dict) -> str:
    """'' when ``state`` has exactly the weights of ``model`` (names and shapes), else what differs, briefly."""
    want = {k: tuple(v.shape) for k, v in model.state_dict().items()}
    have = {k: tuple(v.shape) for k, v in state.items()}
    parts = [f"{label} {', '.join(sorted(keys)[:3])}{' ...' if len(keys) > 3 else ''}"
             for label, keys in (("unexpected", have.keys() - want.keys()), ("missing", want.keys() - have.keys()),
                                 ("other shape", {k for k in want.keys() & have.keys() if want[k] != have[k]}))
             if keys]
    return "; ".join(parts)


def checkpoint_predictions(folder: str | Path, ws: WindowSet, methods, seed: int, device: str = "cpu") -> dict:
    """delta_p_gps (north, east), m, [M, 2] of the windows ``ws`` per method, from the best checkpoints
    ``<method>_seed<seed>.pt`` in ``folder`` (notebook 03's figure of the validation block)."""
    return {m: load_trained(Path(folder) / checkpoints.checkpoint_name(m, seed), device=device).predict_windows(ws)
            for m in methods}

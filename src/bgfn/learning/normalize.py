"""Standardization of the network inputs and targets, fitted on the training windows only."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bgfn.errors import DataError
from bgfn.learning.targets import to_target_frame
from bgfn.learning.windows import WindowSet


@dataclass
class Normalizer:
    """Per-channel input and per-component target standardization, fitted on training windows only."""

    x_mean: np.ndarray
    x_std: np.ndarray
    y_mean: np.ndarray
    y_std: np.ndarray

    @classmethod
    def fit(cls, ws: WindowSet, target_frame: str = "ned", eps: float = 1e-8) -> "Normalizer":
        """Statistics of all samples of the (training) windows ``ws`` (targets in ``target_frame``)."""
        if len(ws) == 0:
            raise DataError("train", "windows", "at least one training window")
        x = ws.x.reshape(-1, ws.x.shape[-1]).astype(np.float64)
        y = to_target_frame(ws.y, ws.yaw_ref, target_frame)
        return cls(x.mean(0), np.maximum(x.std(0), eps), y.mean(0), np.maximum(y.std(0), eps))

    def x(self, x: np.ndarray) -> np.ndarray:
        """Normalized inputs, float32."""
        return ((x - self.x_mean) / self.x_std).astype(np.float32)

    def y(self, y: np.ndarray) -> np.ndarray:
        """Normalized targets, float32."""
        return ((y - self.y_mean) / self.y_std).astype(np.float32)

    def y_inverse(self, yn: np.ndarray) -> np.ndarray:
        """Targets in metres from normalized model outputs."""
        return np.asarray(yn, dtype=np.float64) * self.y_std + self.y_mean

    def to_dict(self) -> dict:
        return {k: np.asarray(getattr(self, k)).tolist() for k in ("x_mean", "x_std", "y_mean", "y_std")}

    @classmethod
    def from_dict(cls, d: dict) -> "Normalizer":
        return cls(*(np.asarray(d[k], dtype=np.float64) for k in ("x_mean", "x_std", "y_mean", "y_std")))

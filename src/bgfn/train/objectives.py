"""What a training run fits: the paper's increments (MSE) or a learned odometer's speed and variance (beta-NLL).

:func:`bgfn.train.loop.train_model` runs the same loop (optimizer, schedule, early stopping, checkpoints) for both;
an objective says what the targets are, which loss the loop minimizes, how a prediction is read in physical
units, what its error is and which references need no training:

- :class:`IncrementObjective`: delta_p_gps (north, east) of :class:`bgfn.learning.LearningData`, MSE on the
  normalized increments (in ``options['target_frame']``), error in metres, the zero / last-increment / INS
  references (:func:`bgfn.learning.reference_rmse`);
- :class:`SpeedObjective`: the forward speed of :class:`bgfn.learning.odometry.SpeedData`, the two outputs read as
  the normalized mean and log-variance, beta-NLL (:func:`bgfn.learning.odometry.beta_nll`), error in m/s, the
  zero-speed and mean-speed references.
"""

from __future__ import annotations

import numpy as np
import torch

from bgfn.learning import (LearningData, from_target_frame, reference_columns, reference_rmse, rmse,
                           to_target_frame)
from bgfn.learning.odometry import SpeedData, beta_nll

#: beta of the speed objective's beta-NLL (Seitzer et al. 2022 recommend 0.5).
SPEED_BETA = 0.5


class IncrementObjective:
    """The paper's: delta_p_gps, MSE, metres (module docstring)."""

    name = "increment"
    metric_key = "val_rmse_m"

    def __init__(self, data: LearningData):
        self.data, self.frame = data, data.options["target_frame"]

    def targets(self, ws) -> torch.Tensor:
        """Normalized targets [M, 2] of the windows ``ws`` (in the target frame)."""
        return torch.as_tensor(self.data.norm.y(to_target_frame(ws.y, ws.yaw_ref, self.frame)))

    def loss(self, out: torch.Tensor, y: torch.Tensor) -> torch.Tensor:
        return torch.nn.functional.mse_loss(out, y)

    def to_units(self, pred: np.ndarray, ws) -> np.ndarray:
        """Model outputs -> (dN, dE), m."""
        return from_target_frame(self.data.norm.y_inverse(pred), ws.yaw_ref, self.frame)

    def error(self, pred: np.ndarray, ws) -> float:
        """RMSE (m) of normalized outputs ``pred`` on ``ws``."""
        return rmse(self.to_units(pred, ws), ws.y)

    def references(self, ws) -> dict:
        """The card's reference columns (:func:`bgfn.learning.reference_rmse`)."""
        return reference_columns(reference_rmse(ws))


class SpeedObjective:
    """A learned odometer's: the forward speed and its log-variance, beta-NLL, m/s (module docstring)."""

    name = "speed"
    metric_key = "val_rmse_mps"

    def __init__(self, data: SpeedData, beta: float = SPEED_BETA):
        self.data, self.beta = data, float(beta)

    def targets(self, ws) -> torch.Tensor:
        """Normalized speeds [M, 1]."""
        return torch.as_tensor(self.data.norm.y(ws.speed[:, None]))

    def loss(self, out: torch.Tensor, y: torch.Tensor) -> torch.Tensor:
        return beta_nll(out[:, 0], out[:, 1], y[:, 0], self.beta)

    def to_units(self, pred: np.ndarray, ws=None) -> tuple[np.ndarray, np.ndarray]:
        """Model outputs -> (speed, std), m/s."""
        pred = np.asarray(pred, dtype=np.float64)
        scale = float(self.data.norm.y_std[0])
        return pred[:, 0] * scale + float(self.data.norm.y_mean[0]), np.exp(0.5 * pred[:, 1]) * scale

    def error(self, pred: np.ndarray, ws) -> float:
        """RMSE (m/s) of the predicted speed on ``ws``."""
        return rmse(self.to_units(pred)[0][:, None], ws.y)

    def references(self, ws) -> dict:
        """RMSE (m/s) of a standing car and of the training windows' mean speed."""
        return {"val_rmse_zero_mps": rmse(np.zeros_like(ws.y), ws.y),
                "val_rmse_mean_mps": rmse(np.full_like(ws.y, float(self.data.norm.y_mean[0])), ws.y)}


def objective_of(data) -> IncrementObjective | SpeedObjective:
    """The objective of a learning data set: :class:`SpeedObjective` for speed data, else the paper's."""
    return SpeedObjective(data) if isinstance(data, SpeedData) else IncrementObjective(data)

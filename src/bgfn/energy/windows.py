"""The evaluation windows that give the firing rates: BGFN's validation windows, evenly subsampled.

They are the validation windows of :mod:`bgfn.learning` (the held-out block of GPS-available time, outside
the evaluation outages), rebuilt with the profile's ``train:`` options, evenly subsampled to
``energy.max_windows`` (:func:`bgfn.train.even_subset`, the rule notebook 03 uses) and normalized with each
checkpoint's own training-set normalization.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bgfn.energy.checkpoint import MeasuredModels
from bgfn.errors import DataError
from bgfn.learning import WindowSet
from bgfn.train import even_subset, prepare_learning_data


def window_indices(n_windows: int, max_windows: int | None) -> np.ndarray:
    """Indices of the evaluation windows among ``n_windows``: ``max_windows`` evenly spaced ones, all when
    ``max_windows`` is null or 0 (``energy.max_windows``)."""
    return even_subset(n_windows, int(max_windows) if max_windows else None)


@dataclass
class EvaluationWindows:
    """The windows measured, raw and as each network reads them.

    Attributes
    ----------
    windows : WindowSet
        The selected validation windows (raw units).
    x : dict
        Method -> normalized windows, float32 [M, N, C].
    n_validation : int
        Validation windows before the subsampling.
    """

    windows: WindowSet
    x: dict[str, np.ndarray]
    n_validation: int

    def line(self, dataset: str, time_steps: int) -> str:
        """How many windows, of what shape, from when."""
        ws = self.windows
        return (f"{dataset}: {len(ws)} of {self.n_validation} validation windows, {ws.x.shape[1]} IMU samples x "
                f"{ws.x.shape[2]} channels, t = {ws.t_end.min():.0f} .. {ws.t_end.max():.0f} s (GPS time of "
                f"week); T_s = {time_steps}")


def evaluation_windows(cfg: dict, measured: MeasuredModels) -> EvaluationWindows:
    """The validation windows of ``measured.dataset``, subsampled and normalized per network.

    Raises
    ------
    DataError
        A network was trained with other learning options than the profile's (retrain with notebook 03).
    """
    data = prepare_learning_data(cfg, measured.dataset)
    for m, tm in measured.trained.items():
        if dict(tm.options) != dict(data.options):
            raise DataError(measured.paths[m], "options",
                            f"the learning options of params/{measured.profile}.yaml {data.options}",
                            f"{tm.options} (retrain with notebook 03)")
    n_val = len(data.val)
    ws = data.val.subset(window_indices(n_val, (cfg.get("energy") or {}).get("max_windows")))
    x = {m: tm.norm.x(ws.x).astype(np.float32) for m, tm in measured.trained.items()}
    return EvaluationWindows(ws, x, n_val)

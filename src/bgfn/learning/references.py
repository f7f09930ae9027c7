"""The validation error of delta_p_gps and the three references every network is read against (none trained)."""

from __future__ import annotations

import numpy as np

from bgfn.learning.windows import WindowSet


def rmse(pred: np.ndarray, true: np.ndarray) -> float:
    """Root mean square of the horizontal error ``sqrt(mean(dN^2 + dE^2))``, m, over rows without NaN."""
    pred, true = np.asarray(pred, float), np.asarray(true, float)
    ok = ~(np.isnan(pred).any(axis=1) | np.isnan(true).any(axis=1))
    if not ok.any():
        return float("nan")
    return float(np.sqrt(np.mean(np.sum((pred[ok] - true[ok]) ** 2, axis=1))))


#: The references every network's validation RMSE is read against, and their column names in cards and tables.
REFERENCES: dict[str, str] = {"zero": "val_rmse_zero_m", "last": "val_rmse_last_m", "ins": "val_rmse_ins_m"}


def reference_rmse(ws: WindowSet) -> dict:
    """RMSE (m) of three predictors that need no training, on the windows ``ws``.

    - ``zero``: no motion;
    - ``last``: the GNSS increment of the interval before (uses GNSS, which the networks do not see);
    - ``ins``: the GPS-aided INS's own distance over the same interval (``ws.y_ins``; its velocity, which the
      inputs of Eq. eq21 do not carry, corrected by every fix up to the one closing the interval). NaN when
      ``ws`` has no ``y_ins``.

    A network that only sees attitude, specific force and angular rate cannot know the speed, the main part of
    an increment; ``ins`` shows how far the GNSS increment can be predicted when the speed is known.
    """
    ins = ws.y_ins if ws.y_ins is not None else np.full_like(ws.y, np.nan)
    return {"zero": rmse(np.zeros_like(ws.y), ws.y), "last": rmse(ws.y_last, ws.y), "ins": rmse(ins, ws.y)}


def reference_columns(refs: dict) -> dict:
    """:func:`reference_rmse` keyed by the column names of :data:`REFERENCES`."""
    return {col: refs[key] for key, col in REFERENCES.items()}

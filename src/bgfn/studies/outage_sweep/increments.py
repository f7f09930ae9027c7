"""The true GPS position increments of a drive and how far a run's predicted increments are from them.

``delta_p_gps`` (Eq. eq8-1) is the north/east change of the *antenna* position over one GNSS interval. Its true
value comes from the reference trajectory: the antenna sits at ``p_imu + C_bn @ lever_arm``
(:func:`bgfn.data.gnss.antenna_position`), and the increment between two epochs is
:func:`bgfn.learning.position_increment` of the two antenna positions, exactly as the training targets are formed
from the GNSS fixes. Two users:

- the oracle rows (:mod:`bgfn.studies.outage_sweep.oracle`) feed the filter these true increments plus noise;
- every network run in the outages gets its *increment error*: the RMSE of its predicted ``delta_p_gps`` against
  the true ones inside the outage, per horizontal axis, so that it reads on the same scale as the oracle's
  per-axis noise ``sigma`` (:func:`increment_rmse`; the ``increment_rmse_m`` column of the outage sweep).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from bgfn.data.gnss import antenna_position
from bgfn.errors import DataError
from bgfn.learning.targets import position_increment

#: Increments whose interval ends this close past a window end still belong to it, s (float times of week).
_TIME_TOL = 1e-6


class AntennaTruth:
    """The reference's antenna position, interpolated in time.

    Parameters
    ----------
    reference : DataFrame
        Reference table (``time, lat, lon, h, roll, pitch, yaw``; CONTRIBUTING.md schema).
    lever_arm_m : array_like, shape (3,)
        GNSS antenna position in the body frame, m.
    source : str
        Name used in error messages (the drive).
    """

    def __init__(self, reference: pd.DataFrame, lever_arm_m, source: str = "reference"):
        self.source = source
        self.time = reference["time"].to_numpy(float)
        self.lat, self.lon, self.h = antenna_position(reference, lever_arm_m)   # [n] each: rad, rad, m

    @classmethod
    def of(cls, ctx) -> "AntennaTruth":
        """The antenna truth of a :class:`bgfn.evaluate.NavContext` (its drive's reference and lever arm)."""
        return cls(ctx.drive.reference, ctx.lever, ctx.drive.name)

    def positions(self, t) -> np.ndarray:
        """``[lat, lon, h]`` (rad, rad, m) of the antenna at times ``t`` (s), [M, 3]; linear in time."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        if t.size and (t.min() < self.time[0] - _TIME_TOL or t.max() > self.time[-1] + _TIME_TOL):
            raise DataError(self.source, "time", f"times inside the reference [{self.time[0]}, {self.time[-1]}] s",
                            f"[{t.min()}, {t.max()}] s")
        return np.column_stack([np.interp(t, self.time, x) for x in (self.lat, self.lon, self.h)])

    def increments(self, t_from, t_to) -> np.ndarray:
        """True ``delta_p_gps`` (Eq. eq8-1) of the antenna over each ``[t_from, t_to]``: (dN, dE), m, [M, 2]."""
        a, b = self.positions(t_from), self.positions(t_to)
        return position_increment(a[:, 0], a[:, 1], a[:, 2], b[:, 0], b[:, 1], b[:, 2])


def increment_errors(run, truth: AntennaTruth, interval_s: float, duration: float | None = None) -> np.ndarray:
    """Predicted minus true ``delta_p_gps`` of one outage run, m, [K, 2] (north, east).

    Parameters
    ----------
    run : bgfn.evaluate.OutageRun
        Its ``increments`` table: ``time`` (end of each GNSS interval, s), ``dn``, ``de`` (m).
    truth : AntennaTruth
    interval_s : float
        Length of one increment (the drive's GNSS interval, ``NavContext.gnss_interval_s``), s.
    duration : float, optional
        Only the increments ending within ``duration`` s of the start (a prefix of the run, as the sweep's
        shorter outages are); None: all. Increments ending after the reference's last row (a window at the end
        of a drive: its last GNSS epoch may lie a sample past the reference) are left out.
    """
    inc = run.increments
    t_to = inc["time"].to_numpy(float)
    keep = t_to <= truth.time[-1] + _TIME_TOL          # an increment ending after the reference cannot be scored
    if duration is not None:
        keep &= t_to <= run.start + float(duration) + _TIME_TOL
    inc, t_to = inc.loc[keep], t_to[keep]
    pred = inc[["dn", "de"]].to_numpy(float).reshape(-1, 2)
    return pred - truth.increments(t_to - float(interval_s), t_to)


def increment_rmse(run, truth: AntennaTruth, interval_s: float, duration: float | None = None) -> float:
    """RMSE of a run's predicted increments against the true ones, **per horizontal axis**, m.

    ``sqrt(mean(e_N^2 + e_E^2) / 2)`` over the increments of :func:`increment_errors`: for white errors of std
    ``sigma`` on each axis it tends to ``sigma`` (the oracle's noise scale). NaN for a run without increments
    (INS, GPS).
    """
    e = increment_errors(run, truth, interval_s, duration)
    return float(np.sqrt(np.mean(e ** 2))) if len(e) else float("nan")

"""An odometer as an aid of the filter engine: the forward speed in the vehicle frame, with its uncertainty.

Beyond the paper (the design of OdoNet, TLIO and AI-IMU: the network predicts a quantity that does not accumulate,
with its own uncertainty, and the filter owns the fusion). At every NHC epoch of the vehicle
(:mod:`bgfn.nav.constraints`) it measures ``z = v^v_x = speed + w``, ``w ~ N(0, kappa std^2)`` (``kappa``: the
track's error correlation, 1 for white errors), linearized as the NHC rows are. Put after the vehicle constraints
in the aid list its row joins their NHC rows as one update; at a ZUPT epoch no speed row is added. The speed comes
from a :class:`SpeedTrack` (a learned odometer, a held speed, an oracle); a row beyond the ``gate_probability``
quantile of chi-square is left out. :func:`speed_errors` scores a track against the true speed in an outage.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from bgfn.stats import chi2_quantile

from ..errors import DataError
from . import error_model as em
from .constraints import AID_NHC, TIME_TOL, Constraints, VehicleSchedule, vehicle_velocity_rows
from .engine import Measurement

#: Default chi-square probability of the forward-speed row's gate (one degree of freedom).
DEFAULT_GATE_PROBABILITY = 0.999
#: Default oldest a speed may be when an aid epoch uses it, s.
DEFAULT_MAX_AGE_S = 1.5


@dataclass(frozen=True)
class SpeedTrack:
    """Forward speeds in the vehicle frame with their std: ``time`` [K] (s, increasing), ``speed`` [K] (m/s),
    ``std`` [K] (m/s, > 0; NaN or a non-positive std: no measurement then).

    ``correlation`` (>= 1, 1: white errors) is the integrated autocorrelation ``kappa`` of the track's errors from
    one aid epoch to the next (:func:`bgfn.learning.odometry.error_correlation`). ``std`` stays each speed's own
    uncertainty (what its 2-sigma coverage is scored against); the filter fuses it with ``R = kappa std^2``, the
    textbook inflation for time-correlated measurement noise: ``kappa`` consecutive speeds then carry the
    information of one independent speed, not ``kappa`` times as much (:meth:`fused_std`)."""

    time: np.ndarray
    speed: np.ndarray
    std: np.ndarray
    correlation: float = 1.0

    def __post_init__(self):
        t, s, d = (np.asarray(a, dtype=float).ravel() for a in (self.time, self.speed, self.std))
        if not (t.size == s.size == d.size):
            raise DataError("speed track", "time/speed/std", "three arrays of one length",
                            f"{t.size}, {s.size}, {d.size}")
        if t.size > 1 and np.any(np.diff(t) <= 0):
            raise DataError("speed track", "time", "strictly increasing times", "a repeated or earlier time")
        if not (np.isfinite(self.correlation) and self.correlation >= 1.0):
            raise DataError("speed track", "correlation", "an integrated autocorrelation >= 1 (1: white errors)",
                            repr(self.correlation))
        object.__setattr__(self, "time", t)
        object.__setattr__(self, "speed", s)
        object.__setattr__(self, "std", d)
        object.__setattr__(self, "correlation", float(self.correlation))

    def at(self, time, max_age_s: float = DEFAULT_MAX_AGE_S) -> tuple[np.ndarray, np.ndarray]:
        """``(speed, std)`` in force at each of ``time`` (s): the last value at or before it, NaN when there is
        none or it is older than ``max_age_s``."""
        time = np.atleast_1d(np.asarray(time, dtype=float))
        i = np.searchsorted(self.time, time + TIME_TOL, side="right") - 1
        ok = (i >= 0) & (time - self.time[np.clip(i, 0, None)] <= max_age_s + TIME_TOL) if self.time.size else \
            np.zeros(time.size, bool)
        j = np.clip(i, 0, None)
        speed = np.where(ok, self.speed[j] if self.time.size else np.nan, np.nan)
        std = np.where(ok, self.std[j] if self.time.size else np.nan, np.nan)
        return speed, std

    def scaled(self, factor: float) -> "SpeedTrack":
        """The same speeds with every std times ``factor`` (a calibration fitted so that the NIS is 1)."""
        if not (np.isfinite(factor) and factor > 0):
            raise DataError("speed track", "calibration", "a positive factor", repr(factor))
        return SpeedTrack(self.time, self.speed, self.std * float(factor), self.correlation)

    def correlated(self, correlation: float) -> "SpeedTrack":
        """The same speeds and stds with the integrated autocorrelation ``correlation`` (1: fused as white)."""
        return SpeedTrack(self.time, self.speed, self.std, correlation)

    def fused_std(self, std) -> np.ndarray:
        """The std the filter fuses a speed of std ``std`` with: ``sqrt(correlation) std`` (class docstring)."""
        return np.sqrt(self.correlation) * np.asarray(std, dtype=float)


def speed_errors(track: SpeedTrack | None, t: np.ndarray, truth: np.ndarray, start: float,
                 duration: float) -> dict:
    """``speed_rmse_mps`` and ``coverage_2sigma`` of a track against the true speed ``truth`` at epochs ``t`` (s)
    inside the outage ``(start, start + duration]`` (NaN without a track)."""
    if track is None:
        return {"speed_rmse_mps": np.nan, "coverage_2sigma": np.nan}
    m = (t > start) & (t <= start + duration + 1e-6)
    speed, std = track.at(t[m])
    ok = np.isfinite(speed)
    if not ok.any():
        return {"speed_rmse_mps": np.nan, "coverage_2sigma": np.nan}
    err = speed[ok] - truth[m][ok]
    return {"speed_rmse_mps": float(np.sqrt(np.mean(err ** 2))),
            "coverage_2sigma": float(np.mean(np.abs(err) <= 2 * std[ok]))}


#: The vehicle frame's forward axis (the row of :func:`bgfn.nav.constraints.vehicle_velocity_rows` it measures).
FORWARD_AXIS = np.array([0], dtype=np.int64)


def forward_speed_row(v: np.ndarray, c: np.ndarray, r_vb: np.ndarray) -> tuple[float, np.ndarray]:
    """The computed forward speed ``(M v)_x`` (m/s) and its row of ``H`` [15] (module docstring; the NHC's rows
    for the other two axes)."""
    dz, H = np.empty(1), np.empty((1, em.N_STATES))
    vehicle_velocity_rows(np.ascontiguousarray(v, dtype=float), np.ascontiguousarray(c, dtype=float),
                          np.ascontiguousarray(r_vb, dtype=float), FORWARD_AXIS, dz, H)
    return float(dz[0]), H[0]


@dataclass(frozen=True)
class Odometer:
    """A forward speed in the vehicle frame (module docstring): an :class:`~bgfn.nav.engine.Aid`.

    Attributes
    ----------
    vehicle : Constraints
        The vehicle the speed is measured in: its aid epochs and frame (:func:`bgfn.nav.constraints.build_constraints`).
        Its NHC/ZUPT rows are the constraints' own aid: ``aids=[vehicle, odometer]`` fuses both.
    track : SpeedTrack
    gate_probability : float or None
        Chi-square probability of the speed row's gate (None: no gate).
    max_age_s : float
        Oldest speed an epoch uses, s.
    """

    vehicle: Constraints
    track: SpeedTrack
    gate_probability: float | None = DEFAULT_GATE_PROBABILITY
    max_age_s: float = DEFAULT_MAX_AGE_S

    def schedule(self, times, source: str = "imu", hold_at: float | None = None) -> "OdometerSchedule":
        """The vehicle's aid epochs (:meth:`Constraints.schedule`) with the speed in force after each IMU step."""
        vehicle = self.vehicle.schedule(times, source, hold_at)
        speed, std = self.track.at(np.asarray(times, dtype=float)[1:], self.max_age_s)
        std = self.track.fused_std(std)                       # R = kappa std^2 (SpeedTrack's docstring)
        p = self.gate_probability
        if p is not None and not 0.0 < p < 1.0:
            raise DataError(source, "gate_probability", "a probability in (0, 1), or None for no gate", repr(p))
        return OdometerSchedule(vehicle.rows, vehicle, speed, std, float(chi2_quantile(p, 1)) if p else 0.0)

    def summary(self) -> dict:
        """The vehicle constraints' summary and how many epochs have a speed."""
        return {**self.vehicle.summary(), "speed_epochs": int(np.count_nonzero(np.isfinite(self.track.speed)))}


@dataclass(frozen=True)
class OdometerSchedule:
    """The odometer bound to one run's IMU steps: the speed row at the vehicle's NHC epochs, joint with the
    constraints' rows (:class:`~bgfn.nav.engine.AidSchedule`)."""

    rows: np.ndarray
    vehicle: VehicleSchedule
    speed: np.ndarray
    std: np.ndarray
    gate: float
    joint = True

    def measurement(self, i: int, nav) -> Measurement | None:
        """The forward speed at the ``i``-th aid epoch when one is in force and the vehicle takes NHC there (no
        speed row at a ZUPT epoch or where neither applies)."""
        k = int(self.rows[i]) - 1
        if self.vehicle.kind(k, nav.v) != AID_NHC or not np.isfinite(self.speed[k]):
            return None
        computed, row = forward_speed_row(np.asarray(nav.v, float), np.asarray(nav.c, float),
                                          self.vehicle.vehicle_rotation(k))
        return Measurement(np.array([computed - self.speed[k]]), row[None, :], np.array([self.std[k]]),
                           np.array([self.gate]))


def aid_list(aid) -> list:
    """The aid list that fuses ``aid`` as it is meant: an :class:`Odometer` after its vehicle's constraints (the
    speed row joins their NHC rows), any other aid alone."""
    return [aid.vehicle, aid] if isinstance(aid, Odometer) else [aid]

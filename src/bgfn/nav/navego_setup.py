"""The 15-state filter set up as NaveGo v1.4's ``ins_gnss.m`` sets it up (profile key ``nav.ins_tuning``).

The paper's data come from NaveGo (R. Gonzalez, LGPL-3.0, ``rodralez/NaveGo``) and its INS row is larger than ours:
how far a standalone INS drifts in an outage depends on how the filter modelled the IMU biases before it. This
module reproduces NaveGo's setup in our filter, as read from v1.4's source (``ins-gnss/ins_gnss.m`` Version 011,
``F_update.m``, ``kf_prediction.m``, ``conversions/imu_si_errors.m``): the static biases removed as known
constants; bias states for the dynamic biases only, started at their one-sigma value; a Gauss-Markov bias model
driven with ``instability^2 / corr_time`` (half the PSD that keeps it stationary); the estimates held between
updates (``FilterNoise.hold_bias_estimates``). NaveGo's GNSS-velocity fusion, its ZUPT heuristic and its bias
feedback (which integrates the accelerometer bias without bound, ``tools/navego_check.py``) are not reproduced:
our filter stays the paper's (Eqs. eq3/eq4). ``nav.ins_tuning: shipped``, the default, leaves every result as is.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from ..errors import DataError
from .state import FilterNoise, _vec3

#: Values of the profile key ``nav.ins_tuning``: the shipped bias modelling, or NaveGo v1.4's setup.
INS_TUNINGS: tuple[str, ...] = ("shipped", "navego")
_SENSORS = ("gyro", "accel")
_AXES = ("x", "y", "z")


def check_tuning(value, source: str = "params nav") -> str:
    """``value`` if it is one of :data:`INS_TUNINGS`; otherwise a :class:`~bgfn.errors.DataError`."""
    if value not in INS_TUNINGS:
        raise DataError(source, "ins_tuning", f"one of {list(INS_TUNINGS)}", repr(value))
    return value


def navego_noise(imu_errors: dict, noise_scale: float = 1.0, source: str = "meta['imu_errors']") -> FilterNoise:
    """Filter noise and bias priors as NaveGo v1.4 sets them up (its bias states: module docstring).

    Parameters
    ----------
    imu_errors : dict
        ``Drive.meta['imu_errors']`` (:mod:`bgfn.data.imu_errors`): ``*_noise_density``,
        ``*_bias_instability`` (NaveGo's ``gb_dyn``/``ab_dyn``) and ``*_bias_corr_time`` (``gb_corr``/``ab_corr``).
    noise_scale : float
        Factor on the white-noise densities (``nav.noise_scale``; 1 = NaveGo's ``arw``/``vrw``).
    source : str
        Name used in error messages.

    Returns
    -------
    FilterNoise
        ``*_noise`` = noise density (rad/sqrt(s), m/s/sqrt(s)); ``*_bias_walk`` = ``sigma / sqrt(tau)``
        (rad/s/sqrt(s), m/s^2/sqrt(s)), i.e. a driving PSD ``sigma^2 / tau``; ``*_bias_tau`` = ``tau`` (s);
        ``*_bias_std`` = ``sigma`` (P0 of the bias states).
    """
    out = {}
    for s in _SENSORS:
        sigma = _vec3(imu_errors, f"{s}_bias_instability", source)
        tau = _vec3(imu_errors, f"{s}_bias_corr_time", source)
        if np.any(tau <= 0):
            raise DataError(source, f"{s}_bias_corr_time", "positive correlation times, s", str(tau.tolist()))
        out[f"{s}_noise"] = noise_scale * _vec3(imu_errors, f"{s}_noise_density", source)
        out[f"{s}_bias_walk"] = sigma / np.sqrt(tau)          # imu_si_errors.m lines 95, 101: gb_dyn/sqrt(gb_corr)
        out[f"{s}_bias_tau"] = tau                            # F_update.m lines 164, 171: -1/gb_corr
        out[f"{s}_bias_std"] = sigma                          # ins_gnss.m line 200: P0 = gb_dyn^2
    # item 7: the estimates are held between updates (lines 251-252 correct every sample with the last gb_dyn)
    return FilterNoise(**out, hold_bias_estimates=True)


def static_biases(imu_errors: dict, source: str = "meta['imu_errors']") -> tuple[np.ndarray, np.ndarray]:
    """The profile's static biases NaveGo removes as known constants (item 1): ``gyro_bias_fixed`` (rad/s) and
    ``accel_bias_fixed`` (m/s^2), zeros where the profile has none (e.g. a CSV drive's)."""
    out = []
    for s in _SENSORS:
        key = f"{s}_bias_fixed"
        v = np.asarray(imu_errors.get(key, [0.0] * 3), dtype=float).ravel()
        if v.size == 1:
            v = np.repeat(v, 3)
        if v.size != 3 or not np.all(np.isfinite(v)):
            raise DataError(source, key, "3 finite numbers (x, y, z)", str(v.tolist()))
        out.append(v)
    return out[0], out[1]


def initial_bias_estimates(imu_errors: dict, source: str = "meta['imu_errors']") -> tuple[np.ndarray, np.ndarray]:
    """NaveGo's initial dynamic-bias estimates (item 3): the profile's ``gyro_bias_instability`` (rad/s) and
    ``accel_bias_instability`` (m/s^2), subtracted from the readings like any bias estimate."""
    return (_vec3(imu_errors, "gyro_bias_instability", source),
            _vec3(imu_errors, "accel_bias_instability", source))


def remove_static_biases(imu: pd.DataFrame, gyro_static, accel_static) -> pd.DataFrame:
    """The IMU table with the static biases subtracted (a copy; ``ins_gnss.m`` lines 251-252).

    Parameters
    ----------
    imu : DataFrame
        IMU table (CONTRIBUTING.md schema).
    gyro_static : array_like, shape (3,)
        rad/s, per body axis.
    accel_static : array_like, shape (3,)
        m/s^2, per body axis.

    Returns
    -------
    DataFrame
        ``imu`` itself when both are zero (nothing to remove), else a corrected copy.
    """
    gyro_static, accel_static = np.asarray(gyro_static, float), np.asarray(accel_static, float)
    if not (gyro_static.any() or accel_static.any()):
        return imu
    out = imu.copy()
    for s, b in zip(_SENSORS, (gyro_static, accel_static)):
        for i, a in enumerate(_AXES):
            out[f"{s}_{a}"] = out[f"{s}_{a}"].to_numpy(float) - b[i]
    return out


__all__ = ["INS_TUNINGS", "check_tuning", "navego_noise", "static_biases",
           "initial_bias_estimates", "remove_static_biases"]

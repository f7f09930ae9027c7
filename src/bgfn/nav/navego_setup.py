"""The 15-state filter set up as NaveGo v1.4's ``ins_gnss.m`` sets it up (profile key ``nav.ins_tuning``).

The paper's data come from NaveGo (R. Gonzalez, LGPL-3.0, ``rodralez/NaveGo``) and its INS row is larger than
ours. How large a standalone INS drifts in an outage depends on how the filter modelled the IMU biases before
it, and NaveGo models them differently from our shipped filter (:func:`bgfn.nav.state.noise_from_imu_errors`).
This module reproduces NaveGo's *setup* in our filter; ``nav.ins_tuning: shipped`` (the default) leaves every
result as it was, ``navego`` selects this one.

What NaveGo v1.4 does, read from its source as mirrored in ``../shared/navego-v1.4/`` (``ins-gnss/ins_gnss.m``
Version 011 of 2022-04, ``ins-gnss/F_update.m`` Version 010, ``ins-gnss/kf_prediction.m`` Version 001,
``conversions/imu_si_errors.m`` Version 011; line numbers of those files):

1. *Static biases removed, as known constants.* Every IMU sample is corrected before the strapdown with the
   profile's static biases ``gb_sta``/``ab_sta`` (``ins-gnss/ins_gnss.m`` lines 251-252,
   ``wb_corrected = imu.wb(i,:)' - gb_dyn - imu.gb_sta'``); they are never estimated.
2. *Bias states = dynamic biases only.* The bias block of P0 is ``diag(gb_dyn, ab_dyn)^2`` (``ins_gnss.m``
   line 193): the static part's uncertainty is not in the filter.
3. *The bias estimate starts at the dynamic-bias value.* ``gb_dyn = imu.gb_dyn'`` (lines 186-187) is
   subtracted from the first samples, and the prior error state is ``[0, gb_dyn, ab_dyn]`` (line 192): the
   one-sigma values of the profile are used as an initial estimate.
4. *Gauss-Markov bias model.* ``F`` has ``-1/gb_corr`` and ``-1/ab_corr`` on the bias block
   (``ins-gnss/F_update.m`` Version 010, lines 164 and 171) and ``G`` an identity for the bias driving noise
   (line 158).
5. *Driving noise ``gb_dyn^2 / gb_corr``.* ``Q = diag(arw, vrw, gb_psd, ab_psd)^2`` (``ins_gnss.m`` line 195)
   with the root PSD ``gb_psd = gb_dyn / sqrt(gb_corr)`` (``conversions/imu_si_errors.m`` Version 011,
   lines 95 and 101). That is half the PSD ``2 sigma^2 / tau`` that keeps a first-order Gauss-Markov process
   at its stationary std ``sigma`` (the shipped filter's choice): NaveGo's bias states settle at
   ``sigma / sqrt(2)``.
6. Discretization ``A = expm(F dt)``, ``Q_d = G Q G^T dt`` at the GNSS epochs (``ins-gnss/kf_prediction.m``
   Version 001, lines 49 and 51).
7. *Bias estimates held between updates.* Every IMU sample is corrected with the last update's ``gb_dyn`` and
   ``ab_dyn`` (lines 251-252); nothing relaxes them between fixes or through an outage, although ``F`` models
   the biases as Gauss-Markov. (Our shipped filter lets a Gauss-Markov estimate relax as ``exp(-dt/tau)``; with
   the MPU-6000's ``tau`` of 100 s that took a quarter of the bias correction away within a 30 s outage and made
   this setup's INS row many times NaveGo's: found by running the two side by side, ``make navego-check``.)

How this module maps it onto our filter, per sensor (our keys of :mod:`bgfn.data.imu_errors`; for NaveGo's
own files :mod:`bgfn.data.drives` maps ``gb_sta -> gyro_bias_fixed``, ``gb_dyn -> gyro_bias_instability``,
``gb_corr -> gyro_bias_corr_time``, ``arw -> gyro_noise_density``, the same for the accelerometer):

==========================  ==============================================  ======================
NaveGo                      here                                            shipped filter
==========================  ==============================================  ======================
static bias removed (1)     ``*_bias_fixed`` subtracted from the IMU table  estimated (in P0)
P0 of the bias states (2)   ``*_bias_instability``                          ``p0_*_bias_std``
initial estimate (3)        ``*_bias_instability``                          0
bias model (4)              Gauss-Markov, ``tau = *_bias_corr_time``        random walk
driving PSD (5)             ``instability^2 / corr_time``                   ``2 instability^2 / tau``
white noise                 ``*_noise_density`` (``arw``, ``vrw``) x        the same
                            ``nav.noise_scale``
estimates between updates   held (7; ``FilterNoise.hold_bias_estimates``)   relax with the model
==========================  ==============================================  ======================

Not reproduced (our filter stays the paper's, Eqs. eq3/eq4): NaveGo also fuses the GNSS velocity, propagates
P only at the GNSS epochs, starts from the first fix and ``ini_align``, and corrects with a ZUPT heuristic
(lines 280-315). Before each update it zeroes the error states 1-9 only (``kf.xp(1:9) = 0.0``, line 363): the
bias states 10-15 are carried from update to update (``xi = A xp``, ``kf_prediction.m`` line 54), and
``gb_dyn = -kf.xp(10:12)`` (lines 408-409) is the accumulated estimate. That feedback is not reproduced: its
prediction ``xi = A xp`` counts the carried bias states once more, and with the negative sign its accelerometer-bias
states integrate the true bias without bound (``tools/navego_check.py`` explains it and runs NaveGo a second time
with the feedback made consistent, all 15 states zeroed and the estimates corrected by them: our closed-loop
filter's scheme, and the run this setup is compared with on a rough IMU). (An earlier
reading of a later ``ins_gnss.m``, Version 012, which zeroes the whole state and so does not accumulate them, is
why :func:`bgfn.studies.ins_fidelity.ins_setups.ins_tuning_table` also shows a run whose bias estimates are cleared at the outage
start; v1.4 as mirrored here is Version 011.)
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
    """Filter noise and bias priors as NaveGo v1.4 sets them up (items 2, 4, 5 of the module docstring).

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

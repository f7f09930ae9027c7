"""Filter state (navigation solution + bias estimates + covariance), noise settings, saving/loading.

A :class:`FilterState` is everything the loosely coupled filter needs to continue from an epoch: it is
saved at the outage starts by the full-drive run so that an outage run costs only its own IMU data.

Saved-state file format (``.npz``, written atomically, read by :func:`load_states`): for each state
``name`` (e.g. ``"outage_1"``) the arrays ``<name>/time`` (s, scalar), ``<name>/pos`` (lat, lon rad, h m),
``<name>/v`` (NED m/s), ``<name>/c_bn`` (3 x 3), ``<name>/accel_bias`` (m/s^2), ``<name>/gyro_bias``
(rad/s), ``<name>/P`` (15 x 15, state order of :mod:`bgfn.nav.error_model`), plus ``names`` (the list of
names) and ``format`` (``"bgfn.nav.state/1"``).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import DataError
from ..io import atomic_path
from . import earth, error_model as em, transform
from .strapdown import state_from_row

FORMAT = "bgfn.nav.state/1"


@dataclass
class FilterState:
    """Navigation state of the closed-loop filter at one epoch.

    Attributes
    ----------
    time : float
        s.
    pos : ndarray, shape (3,)
        ``[lat, lon, h]`` of the IMU (rad, rad, m).
    v : ndarray, shape (3,)
        NED velocity, m/s.
    c_bn : ndarray, shape (3, 3)
        Body-to-NED DCM.
    accel_bias, gyro_bias : ndarray, shape (3,)
        Estimated sensor biases (body), m/s^2 and rad/s; subtracted from the IMU readings.
    P : ndarray, shape (15, 15)
        Error covariance, state order of Eq. (eq13).
    """

    time: float
    pos: np.ndarray
    v: np.ndarray
    c_bn: np.ndarray
    accel_bias: np.ndarray = field(default_factory=lambda: np.zeros(3))
    gyro_bias: np.ndarray = field(default_factory=lambda: np.zeros(3))
    P: np.ndarray = field(default_factory=lambda: np.zeros((em.N_STATES, em.N_STATES)))

    def copy(self) -> "FilterState":
        """Deep copy."""
        return FilterState(float(self.time), *(np.array(getattr(self, f.name), dtype=float)
                                                for f in dataclasses.fields(self)[1:]))

    def as_row(self) -> dict:
        """The navigation solution as a reference-schema row (dict)."""
        roll, pitch, yaw = transform.euler_from_dcm(self.c_bn)
        return {"time": self.time, "lat": self.pos[0], "lon": self.pos[1], "h": self.pos[2],
                "v_n": self.v[0], "v_e": self.v[1], "v_d": self.v[2],
                "roll": float(roll), "pitch": float(pitch), "yaw": float(yaw)}

    def antenna_position(self, lever_arm) -> np.ndarray:
        """``[lat, lon, h]`` of a point at ``lever_arm`` (body frame, m) from the IMU."""
        d = self.c_bn @ np.asarray(lever_arm, dtype=float)
        lat, lon, h = earth.ned_to_lla(d, *self.pos)
        return np.array([lat, lon, h])


@dataclass(frozen=True)
class FilterNoise:
    """Process noise and bias priors of the filter (per body axis x, y, z).

    Attributes
    ----------
    gyro_noise : ndarray
        Gyro white noise density (angle random walk), rad/sqrt(s).
    accel_noise : ndarray
        Accelerometer white noise density (velocity random walk), m/s/sqrt(s).
    gyro_bias_walk : ndarray
        Gyro bias driving noise density, rad/s/sqrt(s).
    accel_bias_walk : ndarray
        Accelerometer bias driving noise density, m/s^2/sqrt(s).
    gyro_bias_tau, accel_bias_tau : ndarray
        Bias correlation times of the filter's model, s (``inf``: random walk).
    gyro_bias_std : ndarray
        Prior std of the gyro bias (P0), rad/s.
    accel_bias_std : ndarray
        Prior std of the accelerometer bias (P0), m/s^2.
    hold_bias_estimates : bool
        False (default): between updates the bias *estimates* follow their model's mean, ``b <- exp(-dt/tau) b``
        (a Gauss-Markov estimate relaxes toward zero); True: they are held until the next update, as NaveGo v1.4
        does (it corrects the IMU with its estimate unchanged between fixes and through an outage;
        :mod:`bgfn.nav.navego_setup`). The covariance follows the model either way.
    """

    gyro_noise: np.ndarray
    accel_noise: np.ndarray
    gyro_bias_walk: np.ndarray
    accel_bias_walk: np.ndarray
    gyro_bias_tau: np.ndarray
    accel_bias_tau: np.ndarray
    gyro_bias_std: np.ndarray
    accel_bias_std: np.ndarray
    hold_bias_estimates: bool = False


def _vec3(d, key, source):
    if key not in d:
        raise DataError(source, key, "a per-axis list of 3 numbers", "missing")
    v = np.asarray(d[key], dtype=float).ravel()
    if v.size == 1:
        v = np.repeat(v, 3)
    if v.size != 3 or not np.all(np.isfinite(v)) or np.any(v < 0):
        raise DataError(source, key, "3 finite non-negative numbers", str(v.tolist()))
    return v


def noise_from_imu_errors(imu_errors: dict, bias_model: str = "random_walk", noise_scale: float = 1.0,
                          source: str = "meta['imu_errors']", bias_walk_scale: float = 1.0) -> FilterNoise:
    """Filter noise from a drive's IMU error parameters (``Drive.meta['imu_errors']``).

    Keys read (see :mod:`bgfn.data.imu_errors`): ``gyro_noise_density``, ``accel_noise_density``,
    ``gyro_bias_instability``, ``accel_bias_instability``, ``gyro_bias_corr_time``,
    ``accel_bias_corr_time`` and, when present, ``p0_gyro_bias_std`` / ``p0_accel_bias_std``
    (otherwise ``sqrt(bias_fixed^2 + turn_on_bias_std^2 + bias_instability^2)``).
    Scale factor, misalignment and vibration are not modelled by the 15-state filter.

    Parameters
    ----------
    imu_errors : dict
    bias_model : {"random_walk", "gauss_markov"}
        ``random_walk``: bias = constant + random walk with the Gauss-Markov driving PSD
        ``2 sigma^2 / tau`` (no decay; keeps the constant part observable). ``gauss_markov``: first-order
        Gauss-Markov with the given ``tau``.
    noise_scale : float
        Factor on the white-noise densities (tuning; 1 = as simulated).
    source : str
        Name used in error messages.
    bias_walk_scale : float
        Factor on the bias driving-noise densities (1 = as given; :mod:`bgfn.nav.tuning` may scale both).

    Returns
    -------
    FilterNoise
    """
    if bias_model not in ("random_walk", "gauss_markov"):
        raise DataError(source, "bias_model", "'random_walk' or 'gauss_markov'", repr(bias_model))
    out = {}
    for s in ("gyro", "accel"):
        sigma = _vec3(imu_errors, f"{s}_bias_instability", source)
        tau = _vec3(imu_errors, f"{s}_bias_corr_time", source)
        if np.any(tau <= 0):
            raise DataError(source, f"{s}_bias_corr_time", "positive correlation times, s", str(tau.tolist()))
        out[f"{s}_noise"] = noise_scale * _vec3(imu_errors, f"{s}_noise_density", source)
        out[f"{s}_bias_walk"] = bias_walk_scale * np.sqrt(2.0 * sigma ** 2 / tau)
        out[f"{s}_bias_tau"] = np.full(3, np.inf) if bias_model == "random_walk" else tau
        if f"p0_{s}_bias_std" in imu_errors:
            out[f"{s}_bias_std"] = _vec3(imu_errors, f"p0_{s}_bias_std", source)
        else:
            fixed = np.abs(np.asarray(imu_errors.get(f"{s}_bias_fixed", [0.0] * 3), dtype=float))
            turn_on = np.asarray(imu_errors.get(f"{s}_turn_on_bias_std", [0.0] * 3), dtype=float)
            out[f"{s}_bias_std"] = np.sqrt(fixed ** 2 + turn_on ** 2 + sigma ** 2)
    return FilterNoise(**out)


def initial_covariance(pos, noise: FilterNoise, position_std, height_std, velocity_std, level_std,
                       azimuth_std) -> np.ndarray:
    """Diagonal P0 in the state order of Eq. (eq13).

    Parameters
    ----------
    pos : array_like, shape (3,)
        ``[lat, lon, h]`` (rad, rad, m), to convert metres to latitude/longitude.
    noise : FilterNoise
        Bias priors.
    position_std, height_std : float
        Horizontal (per axis) and vertical position std, m.
    velocity_std : float
        Per axis, m/s.
    level_std, azimuth_std : float
        Roll/pitch-like (phi_E, phi_N) and heading (phi_D) std, rad.

    Returns
    -------
    ndarray, shape (15, 15)
    """
    r_m, r_n = earth.curvature_radii(pos[0])
    d = np.zeros(em.N_STATES)
    d[[em.PHI_E, em.PHI_N]] = level_std
    d[em.PHI_D] = azimuth_std
    d[[em.DV_E, em.DV_N, em.DV_D]] = velocity_std
    d[em.DLAT] = position_std / (r_m + pos[2])
    d[em.DLON] = position_std / ((r_n + pos[2]) * np.cos(pos[0]))
    d[em.DH] = height_std
    d[em.BA] = noise.accel_bias_std
    d[em.BG] = noise.gyro_bias_std
    return np.diag(d ** 2)


def initial_state(row, P0, rng: np.random.Generator | None = None) -> FilterState:
    """Filter state from a reference-schema row; with ``rng``, navigation errors are drawn from ``P0``.

    Parameters
    ----------
    row : Series or mapping
        Reference-schema row (true or approximate initial state).
    P0 : ndarray, shape (15, 15)
        Initial covariance.
    rng : numpy.random.Generator, optional
        When given, attitude, velocity and position errors ~ N(0, P0) are applied (bias estimates stay 0;
        the true biases are what the filter has to find).

    Returns
    -------
    FilterState
    """
    pos, v, c = state_from_row(row)
    if rng is not None:
        x = rng.multivariate_normal(np.zeros(em.N_STATES), P0)
        pos = pos + x[em.POS]
        v = v + x[em.DV_NED]
        c = transform.dcm_from_rotvec(-x[em.PHI_NED]) @ c  # C_computed = (I - [phi]) C_true
    return FilterState(float(row["time"]), pos, v, np.ascontiguousarray(c), np.zeros(3), np.zeros(3),
                       np.array(P0, dtype=float))


def save_states(path, states: dict) -> Path:
    """Save named :class:`FilterState` objects to an ``.npz`` file (format in the module docstring)."""
    arrays = {"format": np.array(FORMAT), "names": np.array(list(states))}
    for name, s in states.items():
        if "/" in name:
            raise DataError(str(path), "name", "state names without '/'", repr(name))
        for f in dataclasses.fields(FilterState):
            arrays[f"{name}/{f.name}"] = np.asarray(getattr(s, f.name), dtype=float)
    path = Path(path)
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as fh:
            np.savez(fh, **arrays)
    return path


def load_states(path) -> dict:
    """Read a file written by :func:`save_states`; returns ``{name: FilterState}`` in saved order."""
    with np.load(path, allow_pickle=False) as z:
        if "format" not in z or str(z["format"]) != FORMAT:
            raise DataError(str(path), "format", FORMAT, str(z["format"]) if "format" in z else "missing")
        out = {}
        for name in z["names"].tolist():
            kw = {f.name: z[f"{name}/{f.name}"] for f in dataclasses.fields(FilterState)}
            kw["time"] = float(kw["time"])
            out[name] = FilterState(**kw)
    return out

"""Learning-free outage aids of a road vehicle: non-holonomic constraints (NHC) and zero-velocity updates (ZUPT).

Beyond the paper: the classic aids a learned one must beat or add to. Both are velocity measurements of the
15-state filter, one :class:`~bgfn.nav.engine.Aid` (:class:`Constraints`) fused at the *aid epochs* (the first IMU
row at or after each multiple of ``1 / nhc_rate_hz``). NHC: the velocity in the vehicle frame has no lateral and no
vertical part (``H``: ``M`` on ``dV`` and ``-M [v x]`` on ``phi``, ``M = R_vb C_bn^T``, the error conventions of
:mod:`bgfn.nav.error_model`). ZUPT: at rest it is zero; it replaces that epoch's NHC update and is refused above
``max_speed_mps``. Stillness (:func:`stillness`) is a causal moving-variance test of the specific-force and
angular-rate vectors against the drive's at-rest sensor noise (:func:`rest_noise`). The vehicle frame
(:func:`mounting_track`) is estimated causally from the GPS-aided velocity and held through an outage. Which
platform takes which aid: :data:`PLATFORM_AIDS`.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, replace

import numba
import numpy as np
import pandas as pd

from ..errors import DataError
from ..schema import ACCEL_COLUMNS, GYRO_COLUMNS
from . import error_model as em
from .engine import Measurement
from .transform import dcm_from_euler

#: What happens at an IMU step (the aid schedule, one code per step).
AID_NONE, AID_NHC, AID_ZUPT = 0, 1, 2
#: Rows of the NHC measurement: vehicle-frame lateral (y) and vertical (z) velocity.
NHC_AXES = (1, 2)
#: Two IMU epochs closer than this are the same epoch, s.
TIME_TOL = 1e-6

#: Defaults of the ``nav.nhc`` and ``nav.zupt`` profile sections (keys of :class:`ConstraintConfig`).
NHC_DEFAULTS: dict = {"std_mps": 0.1, "rate_hz": 1.0, "mounting": "estimate", "mounting_min_speed_mps": 5.0,
                     "mounting_weight": "heading"}
ZUPT_DEFAULTS: dict = {"std_mps": 0.05, "window_s": 2.0, "accel_ratio": 1.5, "gyro_ratio": 1.5,
                       "max_speed_mps": 2.0}
#: Mounting choices: the vehicle frame estimated from the GPS-aided solution, or the IMU body frame.
MOUNTINGS = ("estimate", "none")
#: Weights of the epochs in the mounting estimate (:func:`mounting_track`): the inverse variance of the GPS-aided
#: solution's heading, or equal.
MOUNTING_WEIGHTS = ("heading", "equal")
#: What moves the IMU (a drive's ``meta["platform"]``, ``meta.yaml``'s ``platform``) -> (NHC, ZUPT): a car rolls
#: without slipping sideways or leaving the road, so both; a walker stops and stands but steps sideways, so ZUPT
#: alone; anything else (a drone, a cart of unknown kind) neither.
PLATFORM_AIDS: dict[str, tuple[bool, bool]] = {"car": (True, True), "walker": (False, True), "other": (False, False)}
#: The platform of a drive that does not say (every shipped drive is a car).
DEFAULT_PLATFORM = "car"


#: Why a platform goes without an aid (the words: :func:`bgfn.report.aid_words.constraint_words`).
PLATFORM_NOTES: dict[str, str] = {"car": "", "walker": " (no NHC: a walker steps sideways)",
                                  "other": " (neither: no motion model is known)"}


def platform_aids(platform: str) -> tuple[str, ...]:
    """The names of the aids ``platform`` takes, in order (``("NHC", "ZUPT")`` for a car; :data:`PLATFORM_AIDS`)."""
    return tuple(a for a, on in zip(("NHC", "ZUPT"), PLATFORM_AIDS[platform]) if on)


@dataclass(frozen=True)
class ConstraintConfig:
    """Settings of the vehicle constraints (a profile's ``nav.nhc`` and ``nav.zupt``).

    Attributes
    ----------
    nhc_std_mps : float
        Std of the lateral and vertical vehicle-frame velocity (the NHC's measurement noise), m/s.
    nhc_rate_hz : float
        Aid epochs per second (NHC, or ZUPT when still), Hz.
    mounting : {"estimate", "none"}
        Vehicle frame from the GPS-aided solution (module docstring), or the IMU body frame.
    mounting_min_speed_mps : float
        Forward speed above which an epoch enters the mounting estimate, m/s.
    mounting_weight : {"heading", "equal"}
        Each epoch of the mounting estimate weighted by the inverse variance of the solution's heading, or equally
        (:func:`mounting_track`).
    zupt_std_mps : float
        Std of the zero-velocity measurement per NED axis, m/s.
    window_s : float
        Length of the detector's trailing window, s.
    accel_ratio, gyro_ratio : float
        Detector thresholds on ``T_f`` and ``T_w`` (multiples of the at-rest std; 0: ZUPT never fires).
    zupt_max_speed_mps : float
        No ZUPT while the filter's speed exceeds this, m/s (module docstring).
    """

    nhc_std_mps: float = NHC_DEFAULTS["std_mps"]
    nhc_rate_hz: float = NHC_DEFAULTS["rate_hz"]
    mounting: str = NHC_DEFAULTS["mounting"]
    mounting_min_speed_mps: float = NHC_DEFAULTS["mounting_min_speed_mps"]
    zupt_std_mps: float = ZUPT_DEFAULTS["std_mps"]
    window_s: float = ZUPT_DEFAULTS["window_s"]
    accel_ratio: float = ZUPT_DEFAULTS["accel_ratio"]
    gyro_ratio: float = ZUPT_DEFAULTS["gyro_ratio"]
    zupt_max_speed_mps: float = ZUPT_DEFAULTS["max_speed_mps"]
    platform: str = DEFAULT_PLATFORM
    mounting_weight: str = NHC_DEFAULTS["mounting_weight"]

    @property
    def nhc(self) -> bool:
        """Whether the platform takes the non-holonomic constraints (:data:`PLATFORM_AIDS`)."""
        return PLATFORM_AIDS[self.platform][0]

    @property
    def zupt(self) -> bool:
        """Whether the platform takes zero-velocity updates (:data:`PLATFORM_AIDS`)."""
        return PLATFORM_AIDS[self.platform][1]

    def __post_init__(self):
        for name in ("nhc_std_mps", "nhc_rate_hz", "zupt_std_mps", "window_s"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value > 0):
                raise DataError("params nav.nhc/nav.zupt", name, "a positive number", repr(value))
        for name in ("mounting_min_speed_mps", "accel_ratio", "gyro_ratio", "zupt_max_speed_mps"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value >= 0):
                raise DataError("params nav.nhc/nav.zupt", name, "a number >= 0", repr(value))
        if self.mounting not in MOUNTINGS:
            raise DataError("params nav.nhc", "mounting", f"one of {MOUNTINGS}", repr(self.mounting))
        if self.platform not in PLATFORM_AIDS:
            raise DataError("drive meta", "platform", f"one of {', '.join(PLATFORM_AIDS)}", repr(self.platform))


def constraint_config(nav_cfg: dict) -> ConstraintConfig:
    """:class:`ConstraintConfig` of a ``nav:`` section (:func:`bgfn.nav.baseline.nav_config`, defaults filled)."""
    nhc = {**NHC_DEFAULTS, **(nav_cfg.get("nhc") or {})}
    zupt = {**ZUPT_DEFAULTS, **(nav_cfg.get("zupt") or {})}
    if nhc["mounting_weight"] not in MOUNTING_WEIGHTS:
        raise DataError("params nav.nhc", "mounting_weight", f"one of {MOUNTING_WEIGHTS}", repr(nhc["mounting_weight"]))
    return ConstraintConfig(float(nhc["std_mps"]), float(nhc["rate_hz"]), str(nhc["mounting"]),
                            float(nhc["mounting_min_speed_mps"]), float(zupt["std_mps"]), float(zupt["window_s"]),
                            float(zupt["accel_ratio"]), float(zupt["gyro_ratio"]), float(zupt["max_speed_mps"]),
                            mounting_weight=str(nhc["mounting_weight"]))


# ---------------------------------------------------------------------------------------------------
# stillness detector, aid epochs, vehicle frame (numpy, once per drive)
# ---------------------------------------------------------------------------------------------------
def rest_noise(imu_errors: dict, rate_hz: float, source: str = "meta['imu_errors']") -> tuple[np.ndarray, np.ndarray]:
    """At-rest std of one IMU sample per axis: white noise at ``rate_hz`` and the idle engine vibration.

    Parameters
    ----------
    imu_errors : dict
        The drive's sensor description (:mod:`bgfn.data.imu_errors` keys): ``accel_noise_density``
        (m/s/sqrt(s)), ``gyro_noise_density`` (rad/sqrt(s)) and, when present, ``vibration_accel_std``,
        ``vibration_gyro_std`` and ``vibration_idle_fraction`` (zero vibration when absent).
    rate_hz : float
        IMU rate, Hz.

    Returns
    -------
    sigma_f : ndarray (3,)
        m/s^2.
    sigma_w : ndarray (3,)
        rad/s.
    """
    idle = float(imu_errors.get("vibration_idle_fraction", 0.0) or 0.0)
    out = []
    for s in ("accel", "gyro"):
        dens = np.broadcast_to(np.asarray(imu_errors.get(f"{s}_noise_density", np.nan), dtype=float), (3,))
        vib = np.broadcast_to(np.asarray(imu_errors.get(f"vibration_{s}_std", 0.0) or 0.0, dtype=float), (3,))
        sigma = np.sqrt(dens ** 2 * rate_hz + (idle * vib) ** 2)
        if not np.all(np.isfinite(sigma) & (sigma > 0)):
            raise DataError(source, f"{s}_noise_density", "3 positive noise densities (the at-rest noise of the "
                            "stillness detector)", repr(imu_errors.get(f"{s}_noise_density")))
        out.append(sigma)
    return out[0], out[1]


def stillness(imu: pd.DataFrame, imu_errors: dict, config: ConstraintConfig,
              source: str = "imu") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The moving-variance stillness detector of the module docstring, at every IMU row.

    Parameters
    ----------
    imu : DataFrame
        IMU table (CONTRIBUTING.md schema).
    imu_errors : dict
        Sensor description (:func:`rest_noise`).
    config : ConstraintConfig

    Returns
    -------
    still : ndarray of bool [M]
        True where the trailing window ending at the row is still (False in the first ``window - 1`` rows).
    t_f, t_w : ndarray [M]
        The test statistics (dimensionless; NaN in the first rows).
    """
    t = imu["time"].to_numpy(float)
    if t.size < 2:
        raise DataError(source, "time", "at least two IMU rows", str(t.size))
    rate = 1.0 / float(np.median(np.diff(t)))
    n_win = max(2, int(round(config.window_s * rate)))
    sigma_f, sigma_w = rest_noise(imu_errors, rate, source + " meta['imu_errors']")
    stats = []
    for cols, sigma in ((ACCEL_COLUMNS, sigma_f), (GYRO_COLUMNS, sigma_w)):
        # the trailing window's variance per axis (pandas' rolling variance: no cancellation on g)
        var = imu[list(cols)].rolling(n_win).var(ddof=0).to_numpy(float).sum(axis=1)       # [M]
        stats.append(np.sqrt(np.maximum(var, 0.0) / np.sum(sigma ** 2)))   # (rounding can leave -0)
    t_f, t_w = stats
    with np.errstate(invalid="ignore"):
        still = (t_f < config.accel_ratio) & (t_w < config.gyro_ratio)
    return still, t_f, t_w


def aid_epochs(time: np.ndarray, rate_hz: float) -> np.ndarray:
    """Whether each IMU row is an aid epoch: the first row at or after a multiple of ``1 / rate_hz`` (bool [M])."""
    k = np.floor(np.asarray(time, dtype=float) * rate_hz + 1e-9)
    out = np.zeros(k.size, dtype=bool)
    out[1:] = k[1:] > k[:-1]
    return out


def vehicle_velocity_ratios(trajectory: pd.DataFrame) -> tuple[np.ndarray, np.ndarray]:
    """Body-frame velocity ``v^b = C_bn^T v^n`` of a solution (reference schema) and its forward component.

    Returns
    -------
    ratios : ndarray [T, 2]
        ``v^b_y / v^b_x`` and ``v^b_z / v^b_x`` (tangents of the yaw and pitch of the velocity in the body frame).
    forward : ndarray [T]
        ``v^b_x``, m/s.
    """
    c = dcm_from_euler(trajectory["roll"].to_numpy(float), trajectory["pitch"].to_numpy(float),
                       trajectory["yaw"].to_numpy(float))                                    # [T, 3, 3]
    vb = np.einsum("tji,tj->ti", c, trajectory[["v_n", "v_e", "v_d"]].to_numpy(float))      # C^T v, [T, 3]
    with np.errstate(divide="ignore", invalid="ignore"):
        ratios = vb[:, 1:] / vb[:, :1]
    return ratios, vb[:, 0]


def mounting_track(trajectory: pd.DataFrame | None, config: ConstraintConfig,
                   heading_std: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The causal estimate of the vehicle x axis in the body frame after each epoch of a GPS-aided solution.

    Parameters
    ----------
    trajectory : DataFrame or None
        The GPS-aided solution (reference schema).
    config : ConstraintConfig
    heading_std : ndarray [T], optional
        The solution's heading std at each of its epochs, rad (the filter's ``phi_D``). With ``mounting_weight:
        heading`` each epoch weighs ``1 / heading_std^2``: a heading error of the solution turns ``v^b`` by the same
        angle, so ``v^b_y / v^b_x`` holds it one for one, and while the filter is still finding its heading (a
        self-aligned start: tens of degrees of std for the first minute of the real drive) those epochs would
        otherwise pull the estimate by as much. None (or ``equal``): every epoch weighs the same.

    Returns
    -------
    time : ndarray [T]
        Epochs of ``trajectory``, s (empty without a trajectory or with ``mounting: none``).
    tangents : ndarray [T, 2]
        Weighted running mean of ``v^b_y / v^b_x`` and ``v^b_z / v^b_x`` over the epochs up to each one with
        forward speed above ``mounting_min_speed_mps`` (0 before the first: the body frame).
    """
    if trajectory is None or config.mounting == "none" or len(trajectory) == 0:
        return np.empty(0), np.empty((0, 2))
    ratios, forward = vehicle_velocity_ratios(trajectory)
    weight = (forward > config.mounting_min_speed_mps).astype(float)
    if heading_std is not None and config.mounting_weight == "heading":
        std = np.asarray(heading_std, dtype=float)
        if std.shape != weight.shape or not np.all(np.isfinite(std) & (std > 0)):
            raise DataError("mounting estimate", "heading_std", f"{weight.size} positive heading stds, rad",
                            f"shape {std.shape}, min {np.nanmin(std) if std.size else 'none'}")
        weight /= std ** 2
    sums = np.cumsum(weight[:, None] * ratios, axis=0)
    total = np.cumsum(weight)[:, None]
    tangents = np.divide(sums, total, out=np.zeros_like(sums), where=total > 0)
    return trajectory["time"].to_numpy(float), tangents


def vehicle_rotation(tangents) -> np.ndarray:
    """``R_vb`` (body to vehicle frame) whose x axis points along ``[1, tan_yaw, tan_pitch]`` of the body frame,
    y axis level in the body's x-y plane (right), z completing the right-handed frame (down)."""
    u = np.array([1.0, float(tangents[0]), float(tangents[1])])
    u /= np.linalg.norm(u)
    y = np.cross([0.0, 0.0, 1.0], u)
    y /= np.linalg.norm(y)
    return np.vstack([u, y, np.cross(u, y)])


@dataclass
class Constraints:
    """The vehicle constraints of one drive, an aid of :func:`bgfn.nav.filter.run_filter`.

    Attributes
    ----------
    config : ConstraintConfig
    imu_time : ndarray [M]
        The drive's IMU epochs, s.
    aid : ndarray of int8 [M]
        ``AID_NONE`` / ``AID_NHC`` / ``AID_ZUPT`` after each IMU row (:func:`build_constraints`).
    still : ndarray of bool [M]
        The detector's output (:func:`stillness`).
    mount_time : ndarray [T]
    mount : ndarray [T, 2]
        :func:`mounting_track`.
    freeze_at : float or None
        When set, the mounting estimate after this time is the one at it (an outage: no fix updates it).
    """

    config: ConstraintConfig
    imu_time: np.ndarray
    aid: np.ndarray
    still: np.ndarray
    mount_time: np.ndarray
    mount: np.ndarray
    freeze_at: float | None = None

    def frozen(self, t: float) -> "Constraints":
        """The same constraints with the mounting estimate held at its value at ``t`` (s)."""
        return dataclasses.replace(self, freeze_at=float(t))

    def mounting_at(self, time) -> np.ndarray:
        """Mounting tangents [n, 2] in force at each of ``time`` (s): the track's last value at or before it."""
        time = np.asarray(time, dtype=float)
        if self.freeze_at is not None:
            time = np.minimum(time, self.freeze_at)
        out = np.zeros((time.size, 2))
        if self.mount_time.size:
            i = np.searchsorted(self.mount_time, time + TIME_TOL, side="right") - 1
            ok = i >= 0
            out[ok] = self.mount[i[ok]]
        return out

    def steps(self, time, source: str = "imu") -> tuple[np.ndarray, np.ndarray]:
        """The aid code and mounting tangents of the IMU steps ending at ``time`` (s; rows of ``imu_time``).

        Returns
        -------
        aid : ndarray of int8 [n]
        mount : ndarray [n, 2]
        """
        time = np.asarray(time, dtype=float)
        i = np.clip(np.searchsorted(self.imu_time, time - TIME_TOL), 0, max(self.imu_time.size - 1, 0))
        if self.imu_time.size == 0 or np.any(np.abs(self.imu_time[i] - time) > TIME_TOL):
            raise DataError(source, "time", "IMU epochs of the drive the constraints were built for",
                            "an epoch it does not have")
        return np.ascontiguousarray(self.aid[i]), np.ascontiguousarray(self.mounting_at(time))

    def schedule(self, times, source: str = "imu", hold_at: float | None = None) -> "VehicleSchedule":
        """The :class:`~bgfn.nav.engine.AidSchedule` of a run with epochs ``times`` (s; row 0 the initial state):
        NHC or ZUPT at each aid epoch, the vehicle frame held at its value at ``hold_at`` (an outage) when given."""
        con = self if hold_at is None else self.frozen(hold_at if self.freeze_at is None
                                                       else min(hold_at, self.freeze_at))
        aid, mount = con.steps(np.asarray(times, dtype=float)[1:], source)      # after each IMU step
        return VehicleSchedule(np.flatnonzero(aid != AID_NONE) + 1, aid, mount, self.config)

    def summary(self) -> dict:
        """JSON-ready facts: aid epochs, ZUPT epochs, the share of still IMU rows, the final mounting angles (deg)."""
        yaw, pitch = np.degrees(np.arctan(self.mount[-1])) if self.mount.size else (0.0, 0.0)
        return {"platform": self.config.platform, "aid_epochs": int(np.count_nonzero(self.aid)),
                "zupt_epochs": int(np.count_nonzero(self.aid == AID_ZUPT)),
                "still_fraction": float(np.mean(self.still)) if self.still.size else 0.0,
                "mounting_yaw_deg": float(yaw), "mounting_pitch_deg": float(pitch)}


def build_constraints(imu: pd.DataFrame, imu_errors: dict, config: ConstraintConfig,
                      trajectory: pd.DataFrame | None = None, source: str = "drive",
                      platform: str = DEFAULT_PLATFORM, heading_std: np.ndarray | None = None) -> Constraints:
    """Detector, aid schedule and vehicle frame of a drive.

    Parameters
    ----------
    imu : DataFrame
        The drive's IMU table.
    imu_errors : dict
        Its sensor description (``Drive.meta['imu_errors']``).
    config : ConstraintConfig
    trajectory : DataFrame, optional
        A GPS-aided solution (reference schema) for the vehicle frame; None: the body frame.
    source : str
        Name used in error messages.
    platform : str
        What moves the IMU (:data:`PLATFORM_AIDS`): which aids apply; the vehicle frame is estimated for a car only.
    heading_std : ndarray, optional
        ``trajectory``'s heading std at each of its rows, rad (:func:`mounting_track`).
    """
    config = replace(config, platform=platform)
    t = imu["time"].to_numpy(float)
    still, _, _ = stillness(imu, imu_errors, config, source)
    epochs = aid_epochs(t, config.nhc_rate_hz)
    moving = AID_NHC if config.nhc else AID_NONE
    aid = np.where(epochs, np.where(still & config.zupt, AID_ZUPT, moving), AID_NONE).astype(np.int8)
    mount_time, mount = mounting_track(trajectory if config.nhc else None, config, heading_std)
    return Constraints(config, t, aid, still, mount_time, mount)


# ---------------------------------------------------------------------------------------------------
# numba kernels
# ---------------------------------------------------------------------------------------------------
@numba.njit(cache=True)
def vehicle_rotation_nb(tan_yaw, tan_pitch, out):
    """:func:`vehicle_rotation` (numba), written into ``out`` [3, 3]."""
    u = np.array([1.0, tan_yaw, tan_pitch])
    u /= np.sqrt(u @ u)
    y = np.array([-u[1], u[0], 0.0])                 # e_z x u
    y /= np.sqrt(y @ y)
    out[0] = u
    out[1] = y
    out[2, 0] = u[1] * y[2] - u[2] * y[1]
    out[2, 1] = u[2] * y[0] - u[0] * y[2]
    out[2, 2] = u[0] * y[1] - u[1] * y[0]


@numba.njit(cache=True)
def vehicle_velocity_rows(v, c, r_vb, axes, dz, H):
    """Components ``axes`` of the vehicle-frame velocity (m/s) into ``dz`` and their rows of ``H`` [len(axes), 15]
    (module docstring: ``M = R_vb C_bn^T`` on ``dV``, ``-M [v x]`` on ``phi``): the NHC's lateral and vertical rows,
    and the learned odometer's forward row (:mod:`bgfn.nav.odometer`)."""
    m = r_vb @ c.T                                   # NED velocity -> vehicle frame
    vv = m @ v
    mv = m @ em.skew_nb(v)
    H[:, :] = 0.0
    for i in range(axes.size):
        row = axes[i]
        dz[i] = vv[row]
        for j in range(3):
            H[i, em.DV_NED[j]] = m[row, j]
            H[i, em.PHI_NED[j]] = -mv[row, j]


_NHC_ROWS = np.array(NHC_AXES, dtype=np.int64)


@numba.njit(cache=True)
def nhc_measurement(v, c, r_vb, dz, H):
    """NHC innovation (vehicle-frame lateral and vertical velocity, m/s) into ``dz`` [2] and ``H`` [2, 15]."""
    vehicle_velocity_rows(v, c, r_vb, _NHC_ROWS, dz, H)


@numba.njit(cache=True)
def zupt_measurement(v, dz, H):
    """ZUPT innovation (the NED velocity, m/s) into ``dz`` [3] and ``H`` [3, 15] (identity on ``dV``)."""
    H[:, :] = 0.0
    for j in range(3):
        dz[j] = v[j]
        H[j, em.DV_NED[j]] = 1.0


@dataclass(frozen=True)
class VehicleSchedule:
    """The vehicle constraints bound to one run's IMU steps: what the filter engine asks at each aid epoch.

    Attributes
    ----------
    rows : ndarray of int
        Output rows of the aid epochs (:class:`~bgfn.nav.engine.AidSchedule`; row ``k + 1`` follows step ``k``).
    aid : ndarray of int8 [n]
        ``AID_NHC`` / ``AID_ZUPT`` / ``AID_NONE`` per step.
    mount : ndarray [n, 2]
        Mounting tangents in force at each step.
    config : ConstraintConfig
    """

    rows: np.ndarray
    aid: np.ndarray
    mount: np.ndarray
    config: ConstraintConfig
    joint = False

    def kind(self, k: int, v) -> int:
        """The aid of step ``k`` at velocity ``v`` (NED, m/s): ZUPT at a still epoch while the speed is at most
        ``zupt_max_speed_mps``, else NHC where the platform has it, else none."""
        kind = self.aid[k]
        if kind == AID_ZUPT and np.sqrt(v @ v) > self.config.zupt_max_speed_mps:
            # a vibration-free IMU at constant speed reads as still: no ZUPT at speed (NHC where the platform has it)
            kind = AID_NHC if self.config.nhc else AID_NONE
        return kind

    def vehicle_rotation(self, k: int) -> np.ndarray:
        """``R_vb`` in force at step ``k`` (:func:`vehicle_rotation_nb`)."""
        r_vb = np.empty((3, 3))
        vehicle_rotation_nb(self.mount[k, 0], self.mount[k, 1], r_vb)
        return r_vb

    def measurement(self, i: int, nav) -> Measurement | None:
        """NHC (the vehicle-frame lateral and vertical velocity are zero) or ZUPT (the NED velocity is zero) at the
        ``i``-th aid epoch, from the current solution of ``nav`` (:class:`bgfn.nav.engine.Stepper`)."""
        k = int(self.rows[i]) - 1
        kind = self.kind(k, nav.v)
        if kind == AID_NONE:
            return None
        n = em.N_STATES
        if kind == AID_ZUPT:
            dz, H = np.empty(3), np.empty((3, n))
            zupt_measurement(nav.v, dz, H)
            return Measurement(dz, H, np.full(3, self.config.zupt_std_mps))
        dz, H = np.empty(2), np.empty((2, n))
        nhc_measurement(nav.v, nav.c, self.vehicle_rotation(k), dz, H)
        return Measurement(dz, H, np.full(2, self.config.nhc_std_mps))


__all__ = ["AID_NHC", "AID_NONE", "AID_ZUPT", "ConstraintConfig", "Constraints", "DEFAULT_PLATFORM", "NHC_DEFAULTS",
           "PLATFORM_AIDS", "ZUPT_DEFAULTS",
           "aid_epochs", "build_constraints", "constraint_config", "mounting_track", "nhc_measurement",
           "vehicle_velocity_rows",
           "rest_noise", "stillness", "vehicle_rotation", "VehicleSchedule", "zupt_measurement"]

"""IMU error levels measured on a drive: noise at rest, vibration while driving, spectra.

How noisy a consumer MEMS IMU is in a car is not on its datasheet (engine and road vibration dominate). This module
measures the levels on any drive's IMU table, so that the stand-in's error model (``turin-sim-mpu6000``) can be set
from a recorded car's IMU and checked against it (notebook 01; the deviations page). Motion states come from the
reference speed (still, driving), not from the IMU; the vibration is the std of the high-passed signal (a car's own
motion has little power above a few hertz); the white-noise density follows from the high-pass filter's noise
bandwidth (:func:`noise_band_hz`), and the simulated vibration that reproduces a measured driving level from both
(:func:`vibration_overrides`).
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from bgfn.errors import DataError
from bgfn.nav.constraints import DEFAULT_PLATFORM

#: Reference speed below which the vehicle stands still (averaged over SMOOTH_S), m/s ...
STILL_MPS = 0.1
#: ... for at least this long, s; TRIM_S cut from both ends of each stop; the averaging span, s.
MIN_REST_S, TRIM_S, SMOOTH_S = 2.0, 0.5, 1.0
#: Reference speed above which the vehicle is driving, m/s (a car) ...
DRIVING_MPS = 3.0
#: ... and above which each platform of ``meta["platform"]`` (:data:`bgfn.nav.constraints.PLATFORM_AIDS`) is
#: moving at its own pace: a walker's 1-1.5 m/s never reaches a car's threshold.
MOVING_MPS: dict[str, float] = {"car": DRIVING_MPS, "walker": 0.5, "other": 0.5}
#: High-pass corner separating vehicle motion from vibration and noise, Hz.
HIGHPASS_HZ = 5.0
#: Minimum samples of a motion state for a level to be reported (5 s at 100 Hz).
MIN_SAMPLES = 500
#: Channels of the IMU schema, by sensor.
SENSORS = {"gyro": ("gyro_x", "gyro_y", "gyro_z"), "accel": ("accel_x", "accel_y", "accel_z")}
#: Units of the levels, by sensor.
UNITS = {"gyro": "rad/s", "accel": "m/s^2"}


def imu_rate_hz(imu: pd.DataFrame) -> float:
    """IMU rate from the median step of ``imu.time``, Hz."""
    return float(1.0 / np.median(np.diff(imu["time"].to_numpy(float))))


def _speed_at(imu_time: np.ndarray, reference: pd.DataFrame, smooth_s: float = SMOOTH_S) -> np.ndarray:
    """Reference horizontal speed, moving-averaged over ``smooth_s``, at the IMU times (m/s)."""
    t = reference["time"].to_numpy(float)
    speed = np.hypot(reference["v_n"].to_numpy(float), reference["v_e"].to_numpy(float))
    n = max(1, int(round(smooth_s / float(np.median(np.diff(t))))))
    return np.interp(imu_time, t, np.convolve(speed, np.ones(n) / n, mode="same"))


def rest_spans(imu: pd.DataFrame, reference: pd.DataFrame, still_mps: float = STILL_MPS,
               min_rest_s: float = MIN_REST_S, trim_s: float = TRIM_S) -> list[tuple[int, int]]:
    """IMU row ranges ``[i0, i1)`` where the vehicle stands (module docstring), trimmed at both ends."""
    t = imu["time"].to_numpy(float)
    still = _speed_at(t, reference) < still_mps
    edges = np.flatnonzero(np.diff(np.concatenate([[0], still.astype(np.int8), [0]])))
    trim = int(round(trim_s / float(np.median(np.diff(t)))))
    return [(int(i0 + trim), int(i1 - trim)) for i0, i1 in zip(edges[::2], edges[1::2])
            if t[i1 - 1] - t[i0] >= min_rest_s and i1 - i0 > 2 * trim]


def moving_speed(drive) -> float:
    """The speed above which ``drive``'s platform counts as moving (*driving*), m/s (:data:`MOVING_MPS`)."""
    return MOVING_MPS[drive.meta.get("platform", DEFAULT_PLATFORM)]


def motion_states(drive, still_mps: float = STILL_MPS, driving_mps: float | None = None) -> pd.Series:
    """``'still'``, ``'driving'`` or ``''`` at every IMU row (module docstring; ``driving_mps`` default: the
    platform's :func:`moving_speed`)."""
    driving_mps = moving_speed(drive) if driving_mps is None else driving_mps
    t = drive.imu["time"].to_numpy(float)
    out = np.full(t.size, "", dtype=object)
    for i0, i1 in rest_spans(drive.imu, drive.reference, still_mps):
        out[i0:i1] = "still"
    out[_speed_at(t, drive.reference) > driving_mps] = "driving"
    return pd.Series(out, index=drive.imu.index, name="state")


def rest_biases(drive, still_mps: float = STILL_MPS) -> pd.DataFrame:
    """Per stop: its span, the mean gyro reading (the gyro bias, rad/s) and the mean |f| (m/s^2).

    Returns
    -------
    DataFrame
        ``t0, t1, gyro_bias_x, gyro_bias_y, gyro_bias_z, f_norm_mean`` (one row per stop).
    """
    imu = drive.imu
    t = imu["time"].to_numpy(float)
    gyro = imu[list(SENSORS["gyro"])].to_numpy(float)
    accel = imu[list(SENSORS["accel"])].to_numpy(float)
    rows = [[t[a], t[b - 1], *gyro[a:b].mean(axis=0), np.linalg.norm(accel[a:b], axis=1).mean()]
            for a, b in rest_spans(imu, drive.reference, still_mps)]
    return pd.DataFrame(rows, columns=["t0", "t1", "gyro_bias_x", "gyro_bias_y", "gyro_bias_z", "f_norm_mean"])


def highpass(x: np.ndarray, rate_hz: float, corner_hz: float = HIGHPASS_HZ) -> np.ndarray:
    """Zero-phase 2nd-order Butterworth high pass of the columns of ``x``."""
    # imported here: scipy.signal imports scipy.stats, about a second in every process that loads a drive
    from scipy import signal
    if not 0.0 < corner_hz < rate_hz / 2:
        raise DataError("imu_levels", "highpass_hz", f"a corner in (0, {rate_hz / 2}) Hz", str(corner_hz))
    b, a = signal.butter(2, corner_hz, "highpass", fs=rate_hz)
    return signal.filtfilt(b, a, x, axis=0)


def noise_band_hz(rate_hz: float, corner_hz: float = HIGHPASS_HZ) -> float:
    """Noise bandwidth ``B`` of :func:`highpass` for white noise of density ``N``: level^2 = ``N^2 B`` (Hz)."""
    # imported here: scipy.signal imports scipy.stats, about a second in every process that loads a drive
    from scipy import signal
    b, a = signal.butter(2, corner_hz, "highpass", fs=rate_hz)
    f, h = signal.freqz(b, a, worN=8192, fs=rate_hz)
    return float(2.0 * np.trapezoid(np.abs(h) ** 4, f))


def imu_levels(drive, highpass_hz: float = HIGHPASS_HZ, still_mps: float = STILL_MPS,
               driving_mps: float | None = None) -> pd.DataFrame:
    """Noise and vibration levels of a drive's IMU, per sensor, axis and motion state.

    The high pass runs over the whole record (edges of a state's spans see their neighbours; at 5 Hz the
    filter's memory is a fraction of a second).

    Returns
    -------
    DataFrame
        ``dataset, sensor, axis, state, n, mean, level, density, unit``: ``level`` = std of the high-passed
        signal (unit); ``density`` = the white-noise density that alone gives that level
        (``level / sqrt(B)``, :func:`noise_band_hz`, unit/sqrt(Hz)); ``mean`` = mean of the raw signal (at rest: the bias
        plus gravity for the accelerometer). A state with fewer than ``MIN_SAMPLES`` rows is left out.
    """
    imu = drive.imu
    rate = imu_rate_hz(imu)
    states = motion_states(drive, still_mps, driving_mps).to_numpy()
    band = noise_band_hz(rate, highpass_hz)
    rows = []
    for sensor, cols in SENSORS.items():
        raw = imu[list(cols)].to_numpy(float)
        hp = highpass(raw, rate, highpass_hz)
        for state in ("still", "driving"):
            sel = states == state
            if sel.sum() < MIN_SAMPLES:
                continue
            for k, col in enumerate(cols):
                level = float(hp[sel, k].std())
                rows.append({"dataset": drive.name, "sensor": sensor, "axis": col[-1], "state": state,
                             "n": int(sel.sum()), "mean": float(raw[sel, k].mean()), "level": level,
                             "density": level / np.sqrt(band), "unit": UNITS[sensor]})
    return pd.DataFrame(rows, columns=["dataset", "sensor", "axis", "state", "n", "mean", "level", "density",
                                       "unit"])


def level_summary(levels: pd.DataFrame) -> pd.DataFrame:
    """One row per (dataset, sensor, state): the level's root-mean-square over the three axes, and the
    ratio driving / still (how much vibration adds to the noise at rest).

    Returns
    -------
    DataFrame
        ``dataset, sensor, still, driving, ratio, unit`` (NaN where a state is missing).
    """
    rms = (levels.assign(sq=levels["level"] ** 2)
           .groupby(["dataset", "sensor", "state"], sort=False)["sq"].mean() ** 0.5).unstack("state")
    out = rms.reindex(columns=["still", "driving"]).reset_index()
    out["ratio"] = out["driving"] / out["still"]
    out["unit"] = out["sensor"].map(UNITS)
    return out.rename_axis(columns=None)


def vibration_overrides(levels: pd.DataFrame, noise_density: dict, highpass_hz: float = HIGHPASS_HZ,
                        rate_hz: float = 100.0) -> dict:
    """Vibration std per axis of :mod:`bgfn.data.imu_errors` that reproduces measured driving levels.

    The simulated vibration's band (``vibration_freq_hz +- bandwidth / 2``) lies above ``highpass_hz``, so
    nearly all its variance survives the high pass; the white noise contributes ``N^2 B``. The rest of
    the measured driving variance is vibration; at rest the same split gives the idle fraction of the
    speed envelope (vibration std at rest / while driving, median over the axes).

    Parameters
    ----------
    levels : DataFrame
        :func:`imu_levels` of ONE drive.
    noise_density : dict
        ``{"gyro": [3], "accel": [3]}`` white-noise densities of the simulated IMU (unit/sqrt(Hz)).

    Returns
    -------
    dict
        ``vibration_gyro_std``, ``vibration_accel_std`` (lists of 3), ``vibration_idle_fraction``, and
        ``vibration_speed_ref_mps`` = ``DRIVING_MPS`` (the envelope at full level wherever the level was measured).
    """
    if levels["dataset"].nunique() != 1:
        raise DataError("imu_levels", "levels", "the levels of one drive", str(sorted(levels["dataset"].unique())))
    band = noise_band_hz(rate_hz, highpass_hz)
    out, idle = {}, []
    for sensor in SENSORS:
        white = np.asarray(noise_density[sensor], float) ** 2 * band
        vib = {}
        for state in ("still", "driving"):
            lv = levels[(levels["sensor"] == sensor) & (levels["state"] == state)].sort_values("axis")
            if len(lv) != 3:
                raise DataError(f"imu_levels {levels['dataset'].iloc[0]}", f"{sensor} {state}",
                                "three axes measured in that motion state", f"{len(lv)}")
            vib[state] = np.sqrt(np.clip(lv["level"].to_numpy(float) ** 2 - white, 0.0, None))
        out[f"vibration_{sensor}_std"] = [float(x) for x in vib["driving"]]
        ok = vib["driving"] > 0
        idle.extend(vib["still"][ok] / vib["driving"][ok])
    out["vibration_idle_fraction"] = float(np.clip(np.median(idle), 0.0, 1.0)) if idle else 0.0
    out["vibration_speed_ref_mps"] = DRIVING_MPS
    return out


def stand_in_table(measured, stand_in) -> pd.DataFrame:
    """The stand-in's vibration settings beside what a measured drive implies, and what the same measurement
    finds on the stand-in itself (the method checked on data whose truth is known).

    Parameters
    ----------
    measured, stand_in : bgfn.data.Drive
        A recorded drive, and a simulated one whose ``meta["imu_errors"]`` holds its error model.

    Returns
    -------
    DataFrame
        ``parameter`` (``vibration_gyro_std_x``, ...), ``unit``, ``<measured name>`` (implied by the recorded
        drive), ``<stand-in name> setting``, ``<stand-in name> measured``.
    """
    errs = stand_in.meta["imu_errors"]
    nd = {s: errs[f"{s}_noise_density"] for s in SENSORS}
    implied = vibration_overrides(imu_levels(measured), nd, rate_hz=imu_rate_hz(measured.imu))
    found = vibration_overrides(imu_levels(stand_in), nd, rate_hz=imu_rate_hz(stand_in.imu))
    rows = []
    for key in ("vibration_gyro_std", "vibration_accel_std"):
        unit = UNITS[key.split("_")[1]]
        for k, a in enumerate("xyz"):
            rows.append((f"{key}_{a}", unit, implied[key][k], errs[key][k], found[key][k]))
    rows.append(("vibration_idle_fraction", "-", implied["vibration_idle_fraction"],
                 errs["vibration_idle_fraction"], found["vibration_idle_fraction"]))
    return pd.DataFrame(rows, columns=["parameter", "unit", measured.name, f"{stand_in.name} setting",
                                       f"{stand_in.name} measured"])


def imu_psd(drive, state: str = "driving", nperseg: int = 512, still_mps: float = STILL_MPS,
            driving_mps: float | None = None) -> pd.DataFrame:
    """Welch power spectral density of every IMU channel over the rows of one motion state.

    The rows of the state are concatenated (the joins add a little broadband power; the spans are long
    against ``nperseg`` samples).

    Returns
    -------
    DataFrame
        ``freq_hz`` and one column per IMU channel (unit^2/Hz).
    """
    # imported here: scipy.signal imports scipy.stats, about a second in every process that loads a drive
    from scipy import signal
    imu = drive.imu
    sel = (motion_states(drive, still_mps, driving_mps) == state).to_numpy()
    if sel.sum() < nperseg:
        raise DataError(f"imu_levels {drive.name}", "state", f"at least {nperseg} IMU rows {state}",
                        f"{int(sel.sum())}")
    cols = [c for cols in SENSORS.values() for c in cols]
    f, p = signal.welch(imu.loc[sel, cols].to_numpy(float), fs=imu_rate_hz(imu), nperseg=nperseg, axis=0)
    out = pd.DataFrame(p, columns=cols)
    out.insert(0, "freq_hz", f)
    return out


def plot_imu_psd(psds: dict):
    """Amplitude spectral density of the specific force and the angular rate while driving, one line per drive
    (root of the sum of the three axes' PSDs).

    Parameters
    ----------
    psds : dict
        ``{label: imu_psd(...)}``.
    """
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.6), constrained_layout=True)
    for ax, (sensor, cols) in zip(axes, SENSORS.items()):
        for name, psd in psds.items():
            ax.semilogy(psd["freq_hz"], np.sqrt(psd[list(cols)].sum(axis=1)), label=name, lw=1.1)
        ax.set_xlabel("frequency (Hz)")
        ax.set_ylabel(f"{sensor} ASD ({UNITS[sensor]}/sqrt(Hz))")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=8)
    fig.suptitle("IMU spectra while driving (three axes summed)")
    return fig

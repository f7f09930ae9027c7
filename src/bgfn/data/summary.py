"""Dataset summary tables (notebook 01): duration, distance, rates, GNSS and IMU error parameters."""

from __future__ import annotations

import numpy as np
import pandas as pd

from bgfn.data.drive import Drive, horizontal_distance_m
from bgfn.data.imu_errors import OPTIONAL_VECTOR_KEYS, SCALAR_KEYS, VECTOR_KEYS

#: Unit of each error-parameter key (SI; see bgfn.data.imu_errors).
_UNITS = {
    "gyro_noise_density": "rad/s/sqrt(Hz)", "accel_noise_density": "m/s^2/sqrt(Hz)",
    "gyro_bias_fixed": "rad/s", "accel_bias_fixed": "m/s^2",
    "gyro_turn_on_bias_std": "rad/s", "accel_turn_on_bias_std": "m/s^2",
    "gyro_bias_instability": "rad/s", "accel_bias_instability": "m/s^2",
    "gyro_bias_corr_time": "s", "accel_bias_corr_time": "s",
    "gyro_scale_factor_tol": "1", "accel_scale_factor_tol": "1",
    "gyro_misalignment_tol": "1", "accel_misalignment_tol": "1",
    "vibration_gyro_std": "rad/s", "vibration_accel_std": "m/s^2",
    "vibration_freq_hz": "Hz", "vibration_bandwidth_hz": "Hz", "vibration_speed_ref_mps": "m/s",
    "vibration_idle_fraction": "1",
    "gyro_turn_on_bias": "rad/s", "accel_turn_on_bias": "m/s^2", "gyro_bias_constant": "rad/s",
    "accel_bias_constant": "m/s^2", "gyro_scale_factor": "1", "accel_scale_factor": "1",
}


def _fmt(value) -> str:
    if value is None:
        return ""
    if isinstance(value, str):
        return value
    arr = np.asarray(value, dtype=float)
    if arr.ndim == 0:
        return f"{float(arr):.6g}"
    return "[" + ", ".join(f"{x:.6g}" for x in arr.ravel()) + "]"


def summary_table(drive: Drive) -> pd.DataFrame:
    """One dataset as rows ``quantity, value, unit`` (vectors as ``[x, y, z]``, 6 significant digits).

    Parameters
    ----------
    drive : Drive

    Returns
    -------
    DataFrame
        Columns ``quantity``, ``value`` (str), ``unit``: time span, duration, horizontal distance,
        speeds, rates and sample counts, lever arm, truth-fit and GNSS residual diagnostics, every IMU
        error parameter and the realized draws (turn-on biases, scale factors) when simulated.
    """
    ref, meta = drive.reference, drive.meta
    t = ref["time"].to_numpy(float)
    speed = np.hypot(ref["v_n"].to_numpy(float), ref["v_e"].to_numpy(float))
    rows = [
        ("dataset", drive.name, ""),
        ("source", meta.get("source", ""), ""),
        ("gnss_source", meta.get("gnss_source", ""), ""),
        ("time_start", t[0], "s (GPS time of week)"),
        ("time_end", t[-1], "s (GPS time of week)"),
        ("duration", t[-1] - t[0], "s"),
        ("distance_horizontal", horizontal_distance_m(ref) / 1000.0, "km"),
        ("speed_max", speed.max(), "m/s"),
        ("speed_mean", speed.mean(), "m/s"),
        ("time_stopped_fraction", float(np.mean(speed < 0.5)), "1 (speed < 0.5 m/s)"),
        ("imu_rate", meta.get("imu_rate_hz"), "Hz"),
        ("imu_samples", len(drive.imu), "1"),
        ("gnss_rate", meta.get("gnss_rate_hz"), "Hz"),
        ("gnss_fixes", len(drive.gnss), "1"),
        ("gnss_std_neu", drive.gnss[["std_n", "std_e", "std_d"]].median().to_numpy(), "m (north, east, down)"),
        ("lever_arm", meta.get("lever_arm_m"), "m (body x, y, z)"),
    ]
    fit = meta.get("truth_fit") or {}
    rows += [(f"truth_fit_{k}", v, u) for k, u in (("pos_rms_m", "m (north, east, up)"),
                                                   ("vel_rms_mps", "m/s (n, e, d) vs ref.mat vel"),
                                                   ("att_rms_rad", "rad (roll, pitch, yaw)")) if (v := fit.get(k))]
    for k in ("gnss_residual_mean_m", "gnss_residual_std_m"):
        if k in meta:
            rows.append((k.removesuffix("_m"), meta[k], "m (north, east, down), fix - true antenna"))
    errs = meta.get("imu_errors") or {}
    if errs:
        rows.append(("imu_model", errs.get("model", ""), ""))
        rows += [(k, errs[k], _UNITS.get(k, "")) for k in VECTOR_KEYS + OPTIONAL_VECTOR_KEYS + SCALAR_KEYS if k in errs]
        realized = errs.get("realized") or {}
        rows += [(f"realized_{k}", realized[k], _UNITS[k]) for k in
                 ("gyro_turn_on_bias", "accel_turn_on_bias", "gyro_bias_constant", "accel_bias_constant",
                  "gyro_scale_factor", "accel_scale_factor") if k in realized]
        if "seed" in errs:
            rows.append(("imu_error_seed", str(errs["seed"]), ""))
    return pd.DataFrame([(q, _fmt(v), u) for q, v, u in rows], columns=["quantity", "value", "unit"])

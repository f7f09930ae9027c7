"""How rough an IMU is beyond its vibration: Allan deviation at rest, the bias's wander between stops, and the
yaw-rate residual while driving; measured alike on a recorded drive and on the simulated stand-in.

The stand-in ``turin-sim-mpu6000`` must drift as a real MEMS IMU in a car does. A 9-minute drive cannot give the
classic hour-long static Allan curve, so three measurements a drive does allow, each run on the stand-in too (where
the truth is known, so the method's own bias shows): the Allan deviation over the pooled stops (:func:`rest_allan`,
the white-noise density), the gyro bias of each stop and its change between stops against a Gauss-Markov model
(:func:`stop_biases`, :func:`bias_instability`: the minutes that set an outage's drift), and the gyro's yaw rate
against the reference's course rate while driving (:func:`yaw_residual_allan`). :func:`roughness_table` sets each
beside the stand-in's setting; ``implied`` = setting x recorded / stand-in measured carries the method's bias over.
"""

from __future__ import annotations

import dataclasses

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from scipy.ndimage import uniform_filter1d

from bgfn.data.allan import allan_deviation, bias_change_var, gauss_markov_avar, white_avar
from bgfn.data.gnss import COURSE_MIN_SPEED_MPS, course_over_ground, hold_trusted
from bgfn.data.imu_errors import apply_imu_errors, error_params
from bgfn.data.imu_levels import DRIVING_MPS, SENSORS, UNITS, imu_rate_hz, rest_spans
from bgfn.errors import DataError
from bgfn.nav.earth import earth_rate_n
from bgfn.nav.sim import imu_from_trajectory
from bgfn.nav.transform import dcm_from_euler

#: Averaging times of the Allan deviation at rest, s (a stop lasts seconds to a minute).
REST_TAUS_S: tuple[float, ...] = (0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0, 2.0, 5.0, 10.0)
#: Averaging times over which the white-noise density is read (white noise dominates there), s.
WHITE_TAUS_S: tuple[float, float] = (0.1, 1.0)
#: Bin of the yaw-rate residual (the reference's rate is noisy at 100 Hz), s; its averaging times, s.
BIN_S = 1.0
YAW_TAUS_S: tuple[float, ...] = (1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0)
#: Shortest stop whose mean reading counts as a bias sample, s (a car settling on its suspension, or a slow
#: creep the speed threshold misses, spoils the mean of a stop of a second or two).
MIN_STOP_S = 5.0


def rest_allan(drive, taus_s=REST_TAUS_S) -> pd.DataFrame:
    """Allan deviation of every IMU channel over the drive's stops, pooled.

    Returns
    -------
    DataFrame
        ``dataset, sensor, axis, tau_s, adev, n_pairs, unit`` (``adev`` in rad/s or m/s^2).
    """
    imu = drive.imu
    spans = rest_spans(imu, drive.reference)
    if not spans:
        raise DataError(f"imu_roughness {drive.name}", "reference speed", "at least one stop (speed below "
                        "0.1 m/s for 2 s) to measure the IMU at rest", "none")
    valid = np.zeros(len(imu), bool)
    for i0, i1 in spans:
        valid[i0:i1] = True
    rate = imu_rate_hz(imu)
    rows = []
    for sensor, cols in SENSORS.items():
        for col in cols:
            adev, pairs = allan_deviation(imu[col].to_numpy(float), rate, taus_s, valid)
            rows += [(drive.name, sensor, col[-1], float(t), float(a), int(p), UNITS[sensor])
                     for t, a, p in zip(taus_s, adev, pairs)]
    return pd.DataFrame(rows, columns=["dataset", "sensor", "axis", "tau_s", "adev", "n_pairs", "unit"])


def noise_densities(allan: pd.DataFrame, taus_s: tuple[float, float] = WHITE_TAUS_S) -> pd.DataFrame:
    """White-noise density per channel: the median of ``adev * sqrt(tau)`` over ``taus_s`` (unit/sqrt(Hz))."""
    sel = allan[(allan["tau_s"] >= taus_s[0]) & (allan["tau_s"] <= taus_s[1])].dropna(subset=["adev"])
    out = (sel.assign(density=sel["adev"] * np.sqrt(sel["tau_s"]))
           .groupby(["dataset", "sensor", "axis"], sort=False)["density"].median().reset_index())
    return out


def _course_yaw(reference: pd.DataFrame) -> np.ndarray:
    """Heading per reference row, rad: the reference's yaw where it has one, else the course over ground (held
    through stops from the last moving row, :func:`bgfn.data.gnss.course_over_ground`)."""
    yaw = reference["yaw"].to_numpy(float)
    held = course_over_ground(reference["v_n"], reference["v_e"])
    return np.where(np.isfinite(yaw), yaw, held)


def stop_biases(drive, min_stop_s: float = MIN_STOP_S) -> pd.DataFrame:
    """Per stop: its span and mid time, duration, and the gyro bias (mean reading less the Earth rate), rad/s.

    The Earth rate is rotated into a level IMU heading along the reference's yaw (or its course before the
    stop); a tilt of a few degrees changes it by under 1e-5 rad/s.

    Returns
    -------
    DataFrame
        ``t0, t1, t_mid, duration_s, gyro_bias_x, gyro_bias_y, gyro_bias_z``.
    """
    imu, ref = drive.imu, drive.reference
    t = imu["time"].to_numpy(float)
    gyro = imu[list(SENSORS["gyro"])].to_numpy(float)
    rt = ref["time"].to_numpy(float)
    yaw, lat = _course_yaw(ref), ref["lat"].to_numpy(float)
    rows = []
    for i0, i1 in rest_spans(imu, ref, min_rest_s=min_stop_s):
        k = int(np.clip(np.searchsorted(rt, 0.5 * (t[i0] + t[i1 - 1])), 0, rt.size - 1))
        w_body = dcm_from_euler(0.0, 0.0, yaw[k]).T @ earth_rate_n(lat[k])     # level IMU along the heading, rad/s
        rows.append([t[i0], t[i1 - 1], 0.5 * (t[i0] + t[i1 - 1]), t[i1 - 1] - t[i0],
                     *(gyro[i0:i1].mean(axis=0) - w_body)])
    return pd.DataFrame(rows, columns=["t0", "t1", "t_mid", "duration_s", "gyro_bias_x", "gyro_bias_y",
                                       "gyro_bias_z"])


def _allan_at(allan: pd.DataFrame, sensor: str, axis: str, tau_s: np.ndarray) -> np.ndarray:
    """The rest Allan deviation of one channel at ``tau_s``, log-log interpolated (held beyond its ends)."""
    sel = allan[(allan["sensor"] == sensor) & (allan["axis"] == axis)].dropna(subset=["adev"])
    return np.exp(np.interp(np.log(tau_s), np.log(sel["tau_s"].to_numpy()), np.log(sel["adev"].to_numpy())))


def bias_instability(drive, corr_time_s: float, allan: pd.DataFrame | None = None,
                     min_stop_s: float = MIN_STOP_S) -> pd.DataFrame:
    """Gauss-Markov std of the gyro bias per axis from its changes between stops (module docstring, 2.).

    Parameters
    ----------
    drive : bgfn.data.Drive
    corr_time_s : float
        Correlation time ``T`` of the model, s (the stand-in's setting: one model for both drives).
    allan : DataFrame, optional
        :func:`rest_allan` of the drive (default: measured here).
    min_stop_s : float
        Shortest stop used, s.

    Returns
    -------
    DataFrame
        ``dataset, axis, n_stops, n_pairs, max_separation_s, rms_change, sigma`` (rad/s; ``sigma`` NaN with
        fewer than two stops, 0 when the changes are within the stop means' noise).
    """
    stops = stop_biases(drive, min_stop_s)
    allan = rest_allan(drive) if allan is None else allan
    i, j = np.triu_indices(len(stops), 1)
    dt = np.abs(stops["t_mid"].to_numpy()[j] - stops["t_mid"].to_numpy()[i])
    shape = bias_change_var(dt, 1.0, corr_time_s)              # per unit sigma^2
    rows = []
    for axis in "xyz":
        b = stops[f"gyro_bias_{axis}"].to_numpy()
        mean_noise = _allan_at(allan, "gyro", axis, stops["duration_s"].to_numpy()) ** 2 if len(stops) else b
        change2 = (b[j] - b[i]) ** 2
        sigma = (float(np.sqrt(max(0.0, np.sum(change2 - mean_noise[i] - mean_noise[j]) / np.sum(shape))))
                 if i.size else np.nan)
        rows.append((drive.name, axis, len(stops), int(i.size), float(dt.max()) if i.size else 0.0,
                     float(np.sqrt(change2.mean())) if i.size else np.nan, sigma))
    return pd.DataFrame(rows, columns=["dataset", "axis", "n_stops", "n_pairs", "max_separation_s", "rms_change",
                                       "sigma"])


def yaw_residual_allan(drive, taus_s=YAW_TAUS_S, bin_s: float = BIN_S,
                       driving_mps: float = DRIVING_MPS) -> pd.DataFrame:
    """Allan deviation of the gyro's z reading minus the reference's course rate (module docstring, 3.).

    Returns
    -------
    DataFrame
        ``dataset, tau_s, adev, n_pairs, valid_fraction`` (rad/s; the fraction of bins used).
    """
    ref = drive.reference
    t = ref["time"].to_numpy(float)
    vn, ve = ref["v_n"].to_numpy(float), ref["v_e"].to_numpy(float)
    speed = np.hypot(vn, ve)
    course_rate = np.where(speed < COURSE_MIN_SPEED_MPS, 0.0, np.gradient(np.unwrap(np.arctan2(ve, vn)), t))
    gyro_z = np.interp(t, drive.imu["time"].to_numpy(float), drive.imu["gyro_z"].to_numpy(float))
    k = ((t - t[0]) // bin_s).astype(int)
    starts = np.flatnonzero(np.diff(np.concatenate([[-1], k])))
    count = np.add.reduceat(np.ones_like(t), starts)
    resid = np.add.reduceat(gyro_z - course_rate, starts) / count
    valid = ((np.maximum.reduceat(speed, starts) < 0.1) | (np.minimum.reduceat(speed, starts) > driving_mps))
    valid &= count >= 0.5 * bin_s / float(np.median(np.diff(t)))
    adev, pairs = allan_deviation(resid, 1.0 / bin_s, taus_s, valid)
    return pd.DataFrame({"dataset": drive.name, "tau_s": np.asarray(taus_s, float), "adev": adev,
                         "n_pairs": pairs, "valid_fraction": float(valid.mean())})


def roughness_table(measured, stand_in) -> pd.DataFrame:
    """The stand-in's white noise and gyro bias instability beside what a recorded drive shows.

    Parameters
    ----------
    measured, stand_in : bgfn.data.Drive
        A recorded drive, and a simulated one whose ``meta["imu_errors"]`` holds its error model (its gyro
        correlation time is the model's ``T`` for both).

    Returns
    -------
    DataFrame
        ``parameter, unit, <measured>, <stand-in> setting, <stand-in> measured, implied`` where ``implied`` =
        setting x recorded / stand-in measured (the setting that the same measurement would find equal).
    """
    errs = stand_in.meta["imu_errors"]
    tau_c = float(np.mean(errs["gyro_bias_corr_time"]))
    allan = {d.name: rest_allan(d) for d in (measured, stand_in)}
    dens = {name: noise_densities(a) for name, a in allan.items()}
    instab = {d.name: bias_instability(d, tau_c, allan[d.name]) for d in (measured, stand_in)}
    rows = []
    for sensor in SENSORS:
        for axis in "xyz":
            got = [float(dn.loc[(dn["sensor"] == sensor) & (dn["axis"] == axis), "density"].iloc[0])
                   for dn in (dens[measured.name], dens[stand_in.name])]
            rows.append((f"{sensor}_noise_density_{axis}", f"{UNITS[sensor]}/sqrt(Hz)", got[0],
                         float(errs[f"{sensor}_noise_density"]["xyz".index(axis)]), got[1]))
    for axis in "xyz":
        got = [float(instab[d.name].set_index("axis").loc[axis, "sigma"]) for d in (measured, stand_in)]
        rows.append((f"gyro_bias_instability_{axis}", "rad/s", got[0],
                     float(errs["gyro_bias_instability"]["xyz".index(axis)]), got[1]))
    out = pd.DataFrame(rows, columns=["parameter", "unit", measured.name, f"{stand_in.name} setting",
                                      f"{stand_in.name} measured"])
    ratio = out[measured.name] / out[f"{stand_in.name} measured"].where(out[f"{stand_in.name} measured"] > 0)
    out["implied"] = out[f"{stand_in.name} setting"] * ratio
    return out


def plot_allan(rest: pd.DataFrame, yaw: pd.DataFrame, model: dict | None = None):
    """Allan deviation at rest (three axes, one colour per drive) and the yaw-rate residual while driving.

    Parameters
    ----------
    rest : DataFrame
        :func:`rest_allan` rows of one or more drives.
    yaw : DataFrame
        :func:`yaw_residual_allan` rows of the same drives.
    model : dict, optional
        ``{label: imu_errors}``: the white-plus-Gauss-Markov model of a setting, drawn as a thin line (axis x).
    """
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.0), constrained_layout=True)
    names = list(dict.fromkeys(rest["dataset"]))
    for ax, sensor in zip(axes, SENSORS):
        for k, name in enumerate(names):
            for a, style in zip("xyz", ("-", "--", ":")):
                sel = rest[(rest["dataset"] == name) & (rest["sensor"] == sensor) & (rest["axis"] == a)]
                ax.loglog(sel["tau_s"], sel["adev"], style, color=f"C{k}", lw=1.2,
                          label=f"{name} {a}, at rest" if sensor == "gyro" or a == "x" else None)
            if sensor == "gyro":
                sel = yaw[yaw["dataset"] == name]
                ax.loglog(sel["tau_s"], sel["adev"], "o-", color=f"C{k}", ms=3, lw=0.8, alpha=0.7,
                          label=f"{name} z, yaw-rate residual driving")
        for label, errs in (model or {}).items():
            tau = np.logspace(-2, 2.5, 60)
            avar = (white_avar(tau, errs[f"{sensor}_noise_density"][0])
                    + gauss_markov_avar(tau, errs[f"{sensor}_bias_instability"][0], errs[f"{sensor}_bias_corr_time"][0]))
            ax.loglog(tau, np.sqrt(avar), color="0.5", lw=0.8, label=f"{label} (model, x)")
        ax.set_xlabel("averaging time tau (s)")
        ax.set_ylabel(f"Allan deviation ({UNITS[sensor]})")
        ax.set_title(sensor)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=6, loc="lower left")
    fig.suptitle("IMU Allan deviation: at rest (stops pooled) and the yaw-rate residual while driving")
    return fig


def trajectory_twin(recorded, imu_errors: dict, seed: int, smooth_s: float = 0.5):
    """The recorded drive with its IMU replaced by a simulated one: same trajectory, GNSS and clock.

    A recorded reference may lack an attitude (the RTK solution has none): a car's is then taken level along its
    path, the heading from the course over ground (held through stops) and the pitch from the climb angle of
    the reference velocity, both averaged over ``smooth_s``; the roll is zero. The error-free IMU that
    reproduces this trajectory (:func:`bgfn.nav.sim.imu_from_trajectory`) gets ``imu_errors``
    (:func:`bgfn.data.imu_errors.apply_imu_errors`, seeded). What differs from the recorded drive is the IMU
    alone (the reference keeps the recorded attitude or its absence, so the filter starts the same way): its INS
    drift against the recorded one's says whether the error model is as rough as the real sensor on the same
    road.

    Parameters
    ----------
    recorded : bgfn.data.Drive
    imu_errors : dict
        An error model (e.g. the stand-in's ``meta["imu_errors"]``; its ``realized`` draws are not reused).
    seed : int
        Seed of the error draws.
    smooth_s : float
        Averaging span of the heading and pitch from the velocity, s.

    Returns
    -------
    bgfn.data.Drive
        Named like the recorded drive (its profile settings apply), ``meta["twin_of"]`` set, ``imu_bias`` the
        simulated bias.
    """
    ref = recorded.reference.copy()
    if not recorded.has_attitude:
        vn, ve, vd = (ref[c].to_numpy(float) for c in ("v_n", "v_e", "v_d"))
        speed = np.hypot(vn, ve)
        if not (speed >= COURSE_MIN_SPEED_MPS).any():
            raise DataError(f"trajectory twin of {recorded.name}", "reference speed",
                            f"some motion above {COURSE_MIN_SPEED_MPS} m/s to take a heading from", "none")
        n = max(1, int(round(smooth_s * imu_rate_hz(recorded.imu))))
        course = uniform_filter1d(np.unwrap(course_over_ground(vn, ve)), n, mode="nearest")
        # the climb angle, held through slow rows like the course (the same rows are trusted)
        climb = hold_trusted(np.arctan2(-vd, np.maximum(speed, COURSE_MIN_SPEED_MPS)), speed >= COURSE_MIN_SPEED_MPS)
        climb = uniform_filter1d(climb, n, mode="nearest")
        ref["roll"], ref["pitch"], ref["yaw"] = 0.0, climb, np.angle(np.exp(1j * course))
    params = error_params({k: v for k, v in imu_errors.items()
                           if k not in ("realized", "p0_gyro_bias_std", "p0_accel_bias_std", "note", "file_profile")})
    speed = np.hypot(ref["v_n"].to_numpy(float), ref["v_e"].to_numpy(float))
    imu, errors, bias = apply_imu_errors(imu_from_trajectory(ref, source=f"trajectory twin of {recorded.name}"),
                                         params, int(seed), speed=speed[1:])
    meta = {**recorded.meta, "imu_errors": errors, "twin_of": recorded.name,
            "source": f"{recorded.name}'s trajectory and GNSS with a simulated {params.get('model', '')} IMU"}
    # the reference keeps the recorded drive's attitude (none for the RTK solution), so the filter starts the way
    # it does on the recorded drive (self-alignment): only the IMU differs
    return dataclasses.replace(recorded, imu=imu, meta=meta, imu_bias=bias)

"""Datasets of the Turin drive and of a recorded car drive: ``load_drive(name, **overrides)``, cached in
``data/processed/``.

``turin-sim-ekinox`` (the paper's dataset test: NaveGo's truth, an IMU synthesized from it with the Ekinox-D errors,
the real Ekinox fixes), ``turin-sim-mpu6000`` (the stand-in for the paper's private field test: MPU-6000 errors and
a simulated 1 Hz receiver), ``navego-ekinox`` and ``navego-mpu6000`` (the recorded IMUs), ``rtklib-drive0708`` (a
real car drive, its RTK fixed solution as the reference, a seeded degraded copy as the GNSS), or a folder path (a
user's CSV drive, :mod:`bgfn.data.csv_drive`). Every draw is seeded by ``seed``; a built dataset is cached under a
key that hashes its name, parameters, raw files' checksums and the data modules' source, so a change rebuilds;
``t_start``/``t_end`` crop after the cache.
"""

from __future__ import annotations

import copy
import hashlib
import json
import logging
from pathlib import Path
from typing import Callable

import numpy as np
import pandas as pd
from scipy.interpolate import CubicSpline

from bgfn.config import PROJECT_ROOT, profile_path, read_profile
from bgfn.data import acquire
from bgfn.data.csv_drive import CSV_FILES, TABLE_OF, load_csv_drive
from bgfn.data.drive import Drive, load_cached, prune_stale, save_drive
from bgfn.data.gnss import decimate, degrade_fixes, fix_errors, imu_position, simulate_fixes
from bgfn.data.imu_errors import MPU6000, apply_imu_errors, error_params
from bgfn.data.names import dataset_folder, profile_entry
from bgfn.data.navego import read_gnss, read_imu, read_reference, resample_imu
from bgfn.data.registry import COMMON_PARAMS, DATASETS, DEFAULT_DATASET
from bgfn.data.rtklib import LEVER_ARM_M as RTKLIB_LEVER_ARM_M, Q_FIX, quality_spans, read_imu_csv, read_pos, read_tag
from bgfn.data.trajectory import smooth_reference
from bgfn.errors import DataError
from bgfn.io import sources_hash
from bgfn.nav.earth import curvature_radii
from bgfn.nav.metrics import REFERENCE_EXCLUDED_KEY
from bgfn.nav.sim import imu_from_trajectory
from bgfn.schema import ATTITUDE_COLUMNS, REFERENCE_COLUMNS

log = logging.getLogger(__name__)

#: Datasets with a clock of their own: the ``data:`` section's common ``t_start``/``t_end`` (the Turin drive's
#: GPS time of week) do not crop them; their own section may.
OWN_CLOCK = ("rtklib-drive0708",)
_NOT_IN_KEY = ("t_start", "t_end")
#: Modules whose source is hashed into the cache key.
_KEY_MODULES = ("acquire", "navego", "rtklib", "trajectory", "imu_errors", "gnss", "drive", "drives", "registry")


def substream_seed(seed: int, stream: int) -> int:
    """An independent 32-bit seed for sub-stream ``stream`` of ``seed`` (``numpy.random.SeedSequence``)."""
    return int(np.random.SeedSequence([int(seed), int(stream)]).generate_state(1)[0])


def dataset_params(name: str, overrides: dict | None = None) -> dict:
    """Defaults of dataset ``name`` with ``overrides`` applied (unknown keys raise DataError)."""
    if name not in DATASETS:
        raise DataError("load_drive", "name", f"one of {', '.join(DATASETS)} or a CSV folder", repr(name))
    params = copy.deepcopy(DATASETS[name])
    for key, value in (overrides or {}).items():
        if key not in params:
            raise DataError(name, key, f"a parameter of {name}: {', '.join(params)}", "unknown parameter")
        params[key] = copy.deepcopy(value)
    if not isinstance(params["seed"], (int, np.integer)) or isinstance(params["seed"], bool):
        raise DataError(name, "seed", "an integer", repr(params["seed"]))
    return params


def profile_overrides(name: str, profile: str) -> dict:
    """Dataset parameters that profile ``params/<profile>.yaml`` sets for dataset ``name``.

    The profile's ``data:`` section may hold ``seed`` (default: the profile's top-level ``seed``), the
    common parameters (``imu_rate_hz``, ``smoothing_degree``, ``position_sigma_m``,
    ``attitude_sigma_rad``, ``t_start``, ``t_end``) and one mapping per dataset name with that dataset's
    parameters (e.g. ``turin-sim-ekinox: {gnss_rate_hz: 1.0}``); other keys (``datasets``, plot spans)
    belong to notebook 01. A common parameter applies to the datasets that have it; the common crop does not
    apply to the datasets of :data:`OWN_CLOCK`.

    Returns
    -------
    dict
        Overrides for :func:`dataset_params` (unknown per-dataset keys raise there).
    """
    cfg = read_profile(profile)
    data = cfg["data"]
    out = {"seed": cfg["seed"] if data["seed"] is None else data["seed"]}   # data.seed null: the profile's
    own = DATASETS.get(name, {})
    out.update({k: data[k] for k in COMMON_PARAMS if k in data and k != "seed" and k in own
                and not (k in _NOT_IN_KEY and name in OWN_CLOCK)})
    section = data.get(name) or {}
    if not isinstance(section, dict):
        raise DataError(profile_path(profile), f"data.{name}", "a mapping of dataset parameters",
                        type(section).__name__)
    unknown = sorted(set(section) - set(DATASETS.get(name, {})))
    if unknown:
        raise DataError(profile_path(profile), f"data.{name}.{unknown[0]}",
                        f"a parameter of {name}: {', '.join(DATASETS.get(name, {}))}", "unknown parameter")
    out.update(section)
    return out


def _source_hash() -> str:
    here = Path(__file__).resolve().parent
    nav = here.parent / "nav"
    return sources_hash([here / f"{m}.py" for m in _KEY_MODULES] + [nav / "sim.py", nav / "earth.py",
                                                                     nav / "transform.py"])


def cache_key(name: str, params: dict, checksums: dict) -> str:
    """SHA-256 (hex) of the dataset name, parameters (minus crop), raw checksums and the code."""
    keyed = {k: v for k, v in params.items() if k not in _NOT_IN_KEY}
    blob = json.dumps({"name": name, "params": keyed, "raw": checksums, "code": _source_hash()},
                      sort_keys=True, default=str)
    return hashlib.sha256(blob.encode()).hexdigest()


# ---------------------------------------------------------------------------------------------- builders
def _truth(ref: pd.DataFrame, p: dict, t_start=None, t_end=None) -> tuple[pd.DataFrame, dict]:
    return smooth_reference(ref, rate_hz=p["imu_rate_hz"], degree=p["smoothing_degree"],
                            position_sigma_m=p["position_sigma_m"], attitude_sigma_rad=p["attitude_sigma_rad"],
                            t_start=t_start, t_end=t_end)


def _gnss_residuals(gnss: pd.DataFrame, truth: pd.DataFrame, lever_arm, excluded_s=()) -> dict:
    """Mean and std of (fix - true antenna position), north/east/down, m, over the truth's span (outside the
    spans where the reference is not trusted)."""
    d = fix_errors(gnss, truth, lever_arm, excluded_s)[["north_m", "east_m", "down_m"]].to_numpy()
    return {"gnss_residual_mean_m": d.mean(axis=0).tolist(), "gnss_residual_std_m": d.std(axis=0).tolist()}


def _speed(truth: pd.DataFrame) -> np.ndarray:
    return np.hypot(truth["v_n"].to_numpy(float), truth["v_e"].to_numpy(float))


def _build_sim(name: str, p: dict, paths: dict) -> Drive:
    ref = read_reference(paths["ref.mat"])
    truth, fit = _truth(ref, p)
    imu_true = imu_from_trajectory(truth, source=f"{name} truth")
    profile = "ekinox-d" if name == "turin-sim-ekinox" else "mpu6000"
    params = error_params(profile, p["imu_errors"])
    imu, imu_errors, imu_bias = apply_imu_errors(imu_true, params, substream_seed(p["seed"], 1),
                                                 speed=_speed(truth)[1:])
    meta = {"imu_rate_hz": float(p["imu_rate_hz"]), "gnss_rate_hz": float(p["gnss_rate_hz"]),
            "imu_errors": imu_errors, "truth_fit": fit, "params": p}
    if name == "turin-sim-ekinox":
        gnss_raw, info = read_gnss(paths["ekinox_gnss.mat"])
        gnss = decimate(gnss_raw, info["rate_hz"], p["gnss_rate_hz"])
        meta.update(lever_arm_m=info["lever_arm_m"], gnss_source="real Ekinox fixes (ekinox_gnss.mat)",
                    source=f"NaveGo {acquire.NAVEGO_TAG} ref.mat (smoothed truth) + simulated Ekinox-D IMU "
                           f"+ real Ekinox GNSS")
    else:
        gnss, _ = simulate_fixes(truth, p["lever_arm_m"], substream_seed(p["seed"], 2), rate_hz=p["gnss_rate_hz"],
                                 white_std_m=p["gnss_white_std_m"], correlated_std_m=p["gnss_correlated_std_m"],
                                 correlated_tau_s=p["gnss_correlated_tau_s"])
        meta.update(lever_arm_m=[float(x) for x in p["lever_arm_m"]],
                    gnss_source="simulated u-blox-like receiver (white + Gauss-Markov position errors)",
                    gnss_errors={"white_std_m": p["gnss_white_std_m"],
                                 "correlated_std_m": p["gnss_correlated_std_m"],
                                 "correlated_tau_s": p["gnss_correlated_tau_s"], "seed": substream_seed(p["seed"], 2)},
                    source=f"NaveGo {acquire.NAVEGO_TAG} ref.mat (smoothed truth) + simulated MPU-6000 IMU "
                           f"+ simulated u-blox GNSS")
    meta.update(_gnss_residuals(gnss, truth, meta["lever_arm_m"]))
    return Drive(name, truth, imu, gnss, meta, imu_bias)


def _build_real(name: str, p: dict, paths: dict) -> Drive:
    imu_file = "ekinox_imu.mat" if name == "navego-ekinox" else "mpu6000_imu.mat"
    ref = read_reference(paths["ref.mat"])
    imu_native, profile = read_imu(paths[imu_file])
    t_imu = imu_native["time"].to_numpy(float)
    t_lo = max(ref["time"].iloc[0], 2 * t_imu[0] - t_imu[1])  # row 0 covers one interval before t[0]
    t_hi = min(ref["time"].iloc[-1], imu_native["time"].iloc[-1])
    truth, fit = _truth(ref, p, t_lo, t_hi)
    imu = resample_imu(imu_native, p["imu_rate_hz"], t_start=truth["time"].iloc[0], t_end=truth["time"].iloc[-1])
    gnss_raw, info = read_gnss(paths["ekinox_gnss.mat"])
    gnss = decimate(gnss_raw, info["rate_hz"], p["gnss_rate_hz"])
    if name == "navego-ekinox":
        larm = info["lever_arm_m"]
        prof = {"model": "ekinox-d"}
        for src, dst in (("arw", "gyro_noise_density"), ("vrw", "accel_noise_density"),
                         ("gb_sta", "gyro_bias_fixed"), ("ab_sta", "accel_bias_fixed"),
                         ("gb_dyn", "gyro_bias_instability"), ("ab_dyn", "accel_bias_instability"),
                         ("gb_corr", "gyro_bias_corr_time"), ("ab_corr", "accel_bias_corr_time")):
            if src in profile and len(profile[src]) in (1, 3):
                prof[dst] = profile[src]
        errors = error_params("ekinox-d", {k: v for k, v in prof.items()})
    else:
        larm = [float(x) for x in p["lever_arm_m"]]
        errors = error_params(MPU6000)
    errors["file_profile"] = profile
    errors["realized"] = None  # real sensor: the true errors are unknown
    meta = {"imu_rate_hz": float(p["imu_rate_hz"]), "gnss_rate_hz": float(p["gnss_rate_hz"]),
            "native_imu_rate_hz": float(1.0 / np.median(np.diff(imu_native["time"]))),
            "lever_arm_m": larm, "imu_errors": errors, "truth_fit": fit, "params": p,
            "gnss_source": "real Ekinox fixes (ekinox_gnss.mat)",
            "source": f"NaveGo {acquire.NAVEGO_TAG} {imu_file} (resampled) + real GNSS + smoothed ref.mat truth"}
    meta.update(_gnss_residuals(gnss, truth, larm))
    return Drive(name, truth, imu, gnss, meta)


def _rtk_reference(fixed: pd.DataFrame, grid: np.ndarray) -> pd.DataFrame:
    """The RTK antenna solution at ``grid`` (s): a cubic spline through the fixed positions, its derivative as
    the velocity (NED, m/s), attitude NaN.

    The solution's own velocity column is not used: in this file it is the backward difference of successive
    positions (its std is ``sqrt(2)`` times the position std over 0.25 s, and it matches the positions' central
    difference 0.125 s earlier), i.e. the mean velocity of the past interval, late by half an epoch.
    """
    t = fixed["time"].to_numpy(float)
    splines = {c: CubicSpline(t, fixed[c].to_numpy(float)) for c in ("lat", "lon", "h")}
    out = {"time": grid, **{c: s(grid) for c, s in splines.items()}}
    r_m, r_n = curvature_radii(out["lat"])
    out["v_n"] = splines["lat"](grid, 1) * (r_m + out["h"])
    out["v_e"] = splines["lon"](grid, 1) * (r_n + out["h"]) * np.cos(out["lat"])
    out["v_d"] = -splines["h"](grid, 1)
    for c in ATTITUDE_COLUMNS:
        out[c] = np.full(grid.size, np.nan)
    return pd.DataFrame(out, columns=list(REFERENCE_COLUMNS))


def _build_rtklib(name: str, p: dict, paths: dict) -> Drive:
    """The RTKLIB-logged car drive (``bgfn.data.rtklib``; module table).

    - IMU: the real samples, rotated to the body frame, on their tagged times (8-11 ms steps), integrated and
      resampled onto the regular ``imu_rate_hz`` grid (:func:`bgfn.data.navego.resample_imu`).
    - Reference: the RTK fixed epochs (Q = 1) on the grid (:func:`_rtk_reference`), moved from the antenna to the
      IMU with the lever arm (:func:`bgfn.data.gnss.imu_position`: level along the course, since the drive has
      no attitude; 5 cm arm, millimetres of error). Its velocity is the antenna's (the rotation term
      ``omega x lever`` is below 3 cm/s). ``roll, pitch, yaw`` are NaN. The spans around the epochs that are
      not fixed go to ``meta["reference_excluded_s"]``, left out of every metric.
    - GNSS: every epoch of the solution (all qualities: the copy's own errors are metres), decimated to
      ``gnss_rate_hz``, with the seeded white + Gauss-Markov errors of the simulated u-blox receiver
      (:func:`bgfn.data.gnss.degrade_fixes`); velocity = the reference's at the fix times (a consumer
      receiver's Doppler velocity is of that class, a few cm/s; the filter uses positions only).
    - IMU errors: no datasheet comes with the data; the filter gets the MPU-6000 consumer-MEMS profile
      (:data:`bgfn.data.imu_errors.MPU6000`, with ``imu_errors`` overrides; deviations page).
    """
    pos, week = read_pos(paths["gnss_1934_sf.pos"])
    imu_native, imu_info = read_imu_csv(paths["imu_1934.csv"], read_tag(paths["imu_1934.csv.tag"]), week=week,
                                        time_offset_s=p["imu_time_offset_s"])
    fixed = pos.loc[pos["q"] == Q_FIX].reset_index(drop=True)
    if len(fixed) < 2:
        raise DataError(paths["gnss_1934_sf.pos"], "Q", "RTK fixed epochs (Q = 1)", f"{len(fixed)}")
    rate = float(p["imu_rate_hz"])
    t_imu = imu_native["time"].to_numpy(float)
    lo = max(float(fixed["time"].iloc[0]), 2 * t_imu[0] - t_imu[1])  # row 0 covers one interval before t[0]
    hi = min(float(fixed["time"].iloc[-1]), float(t_imu[-1]))
    grid = np.arange(int(np.ceil(lo * rate - 1e-9)), int(np.floor(hi * rate + 1e-9)) + 1) / rate
    antenna = _rtk_reference(fixed, grid)
    larm = [float(x) for x in RTKLIB_LEVER_ARM_M]
    lat, lon, h = imu_position(antenna, larm)
    ref = antenna.assign(lat=lat, lon=lon, h=h)
    imu = resample_imu(imu_native, rate, t_start=grid[0], t_end=grid[-1])
    native_hz = 1.0 / float(np.median(np.diff(pos["time"])))
    sol = decimate(pos[["time", "lat", "lon", "h"]], round(native_hz), p["gnss_rate_hz"])
    sol = sol.loc[(sol["time"] >= grid[0]) & (sol["time"] <= grid[-1])].reset_index(drop=True)
    for c in ("v_n", "v_e", "v_d"):
        sol[c] = np.interp(sol["time"], grid, antenna[c])
    gnss, _ = degrade_fixes(sol, substream_seed(p["seed"], 2), rate_hz=p["gnss_rate_hz"],
                            white_std_m=p["gnss_white_std_m"], correlated_std_m=p["gnss_correlated_std_m"],
                            correlated_tau_s=p["gnss_correlated_tau_s"])
    inside = pos.loc[(pos["time"] >= grid[0]) & (pos["time"] <= grid[-1])]
    excluded = [s for s in quality_spans(pos) if s[1] >= grid[0] and s[0] <= grid[-1]]
    errors = error_params(MPU6000, p["imu_errors"])
    errors["realized"] = None  # real sensor: the true errors are unknown
    errors["note"] = ("no datasheet comes with the data: the MPU-6000 consumer-MEMS profile stands in "
                      "(the sensor is a TDK ICM-45686)")
    meta = {"imu_rate_hz": rate, "gnss_rate_hz": float(p["gnss_rate_hz"]),
            "native_imu_rate_hz": float(1.0 / np.median(np.diff(t_imu))), "lever_arm_m": larm,
            "imu_errors": errors, "params": p, REFERENCE_EXCLUDED_KEY: excluded,
            "imu_time": imu_info,
            "rtk": {"epochs": int(len(inside)), "fixed": int((inside["q"] == Q_FIX).sum()),
                    "rate_hz": native_hz, "gps_week": int(week)},
            "gnss_source": "degraded copy of the RTK solution (decimated; white + Gauss-Markov position errors)",
            "gnss_errors": {"white_std_m": p["gnss_white_std_m"], "correlated_std_m": p["gnss_correlated_std_m"],
                            "correlated_tau_s": p["gnss_correlated_tau_s"], "seed": substream_seed(p["seed"], 2)},
            "source": (f"{acquire.RTKLIB_FILES['imu_1934.csv'].source} (BSD 3-Clause, (c) 2025 rtklibexplorer): "
                       "real TDK ICM-45686 IMU + u-blox X20 RTK solution as reference (no attitude) + "
                       "degraded copy of it as GNSS")}
    meta.update(_gnss_residuals(gnss, ref, larm, excluded))
    return Drive(name, ref, imu, gnss, meta)


_BUILDERS: dict[str, tuple[tuple[str, ...], Callable]] = {
    "turin-sim-ekinox": (("ref.mat", "ekinox_gnss.mat"), _build_sim),
    "turin-sim-mpu6000": (("ref.mat",), _build_sim),
    "navego-ekinox": (("ref.mat", "ekinox_gnss.mat", "ekinox_imu.mat"), _build_real),
    "navego-mpu6000": (("ref.mat", "ekinox_gnss.mat", "mpu6000_imu.mat"), _build_real),
    "rtklib-drive0708": (tuple(acquire.RTKLIB_FILES), _build_rtklib),
}


#: Parameters a CSV drive takes (from the profile's ``data:`` section or as overrides).
CSV_PARAMS: tuple[str, ...] = ("imu_rate_hz", "t_start", "t_end")


def _load_folder(folder: Path, profile: str | None, overrides: dict) -> Drive:
    """A user's CSV drive (:func:`bgfn.data.csv_drive.load_csv_drive`) with the profile's ``data:`` grid rate and
    crop (``imu_rate_hz``, ``t_start``, ``t_end``), checked (:meth:`Drive.validate`) with messages naming the files."""
    extra = sorted(set(overrides) - set(CSV_PARAMS))
    if extra:
        raise DataError(folder, extra[0], f"a parameter of a CSV drive: {', '.join(CSV_PARAMS)}", "unknown parameter")
    params = {}
    if profile is not None:
        data = read_profile(profile)["data"]
        params = {k: data[k] for k in CSV_PARAMS if data.get(k) is not None}
    params.update({k: v for k, v in overrides.items() if v is not None})
    files = {TABLE_OF[f]: str(folder / f) for f in CSV_FILES}
    return load_csv_drive(folder, **params).validate(str(folder), files=files)


def load_drive(name: str | Path = DEFAULT_DATASET, *, profile: str | None = None,
               data_dir: str | Path | None = None, mirror: str | Path | None = None, download: bool = True,
               cache: bool = True, **overrides) -> Drive:
    """Load a dataset of the Turin drive, or a user's CSV folder.

    Parameters
    ----------
    name : str or Path
        A key of ``DATASETS`` (default ``"turin-sim-ekinox"``) or a folder in the CSV schema, absolute or
        relative to the repository root, else to the current directory (:func:`bgfn.data.names.dataset_folder`);
        with ``profile``, also the id of a folder the profile names (as a loaded profile lists it).
    profile : str, optional
        Take the parameters from the ``data:`` section of ``params/<profile>.yaml``
        (:func:`profile_overrides`); explicit ``overrides`` win.
    data_dir : str or Path, optional
        Data folder (raw files and cache); default ``$BGFN_DATA_DIR`` or ``<repo>/data``.
    mirror : str or Path, optional
        Mirror folder of the dataset's raw files; default ``$BGFN_DATA_MIRROR`` or
        ``<repo>/../shared/data/navego`` (NaveGo), ``$BGFN_RTKLIB_MIRROR`` or
        ``<repo>/../shared/data/rtklib-drive0708`` (``rtklib-drive0708``).
    download : bool
        Try the pinned URL when a file is neither in ``raw`` nor in the mirror.
    cache : bool
        Read/write the processed dataset in ``<data>/processed``.
    **overrides
        Dataset parameters (see ``DATASETS``): ``seed``, ``imu_rate_hz``, ``gnss_rate_hz``,
        ``smoothing_degree``, ``position_sigma_m``, ``attitude_sigma_rad``, ``imu_errors`` (dict of
        error-profile keys), ``lever_arm_m``, ``gnss_*_std_m``, ``gnss_correlated_tau_s``, ``t_start``,
        ``t_end``. For a CSV folder only ``imu_rate_hz``, ``t_start``, ``t_end`` (:data:`CSV_PARAMS`; also taken
        from the profile's ``data:`` section).

    Returns
    -------
    Drive

    Raises
    ------
    DataError
        Unknown name/parameter, bad file content; :class:`bgfn.data.acquire.MissingFileError` when a needed
        file cannot be had (for the real IMU files: says that the simulated datasets stand in);
        :class:`bgfn.errors.ChecksumError` on a checksum mismatch.
    """
    entry = profile_entry(name, profile) if profile is not None else None    # an id: the folder the profile names
    name = entry if entry is not None else name
    folder = dataset_folder(name)
    if folder is not None:
        return _load_folder(folder, profile, overrides)
    if name not in DATASETS:
        if isinstance(name, Path) or "/" in str(name) or "\\" in str(name):
            raise DataError(name, "folder", f"a folder with {', '.join(CSV_FILES)} (a relative path is taken from "
                            f"{PROJECT_ROOT}, else from the current directory)", "no such folder")
        raise DataError("load_drive", "name", f"one of {', '.join(DATASETS)} or a CSV folder (absolute, or "
                        f"relative to {PROJECT_ROOT} or the current directory)", repr(str(name)))
    if profile is not None:
        overrides = {**profile_overrides(name, profile), **overrides}
    params = dataset_params(name, overrides)
    needed, builder = _BUILDERS[name]
    paths, checksums = {}, {}
    for f in needed:
        res = acquire.resolve(f, data_dir=data_dir, mirror=mirror, download=download)
        if res.path is None:
            spec = acquire.raw_files()[f]
            hint = f"; {spec.when_missing}" if not spec.required else ""
            raise acquire.MissingFileError(f, "file", f"{spec.source} {f} (needed by {name}) in "
                                           f"{acquire.raw_dir(data_dir)}, the mirror or the pinned URL",
                                           f"nothing: {res.detail}{hint}")
        paths[f], checksums[f] = res.path, res.checksum
    key = cache_key(name, params, checksums)
    stem = acquire.processed_dir(data_dir) / name / key[:20]
    drive = load_cached(stem, key) if cache else None
    if drive is None:
        drive = builder(name, params, paths)
        drive.meta["cache_key"] = key
        drive.meta["raw_checksums"] = checksums
        drive.validate()
        if cache:
            code = _source_hash()
            save_drive(drive, stem, key, code)
            log.info("cached %s in %s", name, stem)
            for old in prune_stale(stem.parent, code):        # built by other code: unreachable
                log.info("removed stale cache entry %s", old)
    drive.meta["params"] = params
    if params["t_start"] is not None or params["t_end"] is not None:
        drive = drive.crop(params["t_start"], params["t_end"])
    return drive

"""Notebook 02 workflow: the KF baseline on a drive (full GPS/INS run, standalone INS in the outages).

The ``nav:`` section of the profile configures it (keys and defaults: :class:`bgfn.settings.Nav`): the datasets,
the initial stds, where the filter starts (the reference's first row or a self-alignment, :mod:`bgfn.nav.alignment`),
the bias model, the noise scale (a number, or ``auto``: :mod:`bgfn.nav.tuning`), NaveGo's setup
(:mod:`bgfn.nav.navego_setup`), the innovation gate and the vehicle constraints of the ``INS+NHC`` rows
(:mod:`bgfn.nav.constraints`). The outages are the profile's ``outage_windows``
(:func:`bgfn.nav.outages.outage_windows`).
"""

from __future__ import annotations

import copy
from dataclasses import dataclass
from pathlib import Path

import numba
import numpy as np
import pandas as pd

from .. import paper, row_labels, settings
from ..config import DEFAULT_DATASET_KEY
from ..errors import DataError
from ..io import atomic_write_csv, cached, content_hash, sources_hash
from . import constraints as cn, metrics, navego_setup
from .alignment import ALIGNMENT_DEFAULTS, MODES, Alignment, align
from .consistency import nis_summary
from .error_model import PHI_D, STATE_NAMES
from .filter import FilterResult, run_filter, run_outage
from .gnss_aid import gate_thresholds
from .outage_window import check_windows, epochs_before
from .reference_attitude import check_attitude
from .state import FilterNoise, FilterState, initial_covariance, initial_state, noise_from_imu_errors, save_states
from .tuning import NOISE_SEARCH_DEFAULTS, NoiseTuning, search_noise_scale

#: Defaults of the ``nav:`` profile section (their home: :class:`bgfn.settings.Nav`).
NAV_DEFAULTS: dict = settings.defaults("nav")
#: ``nav.noise_scale`` that asks for the factor from the data.
AUTO = "auto"
#: Label of the standalone INS with the vehicle constraints (:func:`bgfn.paper.nhc_label`).
INS_NHC = paper.nhc_label("INS")


def nav_config(section: dict | None) -> dict:
    """``NAV_DEFAULTS`` updated with a profile's ``nav:`` section (unknown keys raise)."""
    cfg = copy.deepcopy(NAV_DEFAULTS)
    for key, value in (section or {}).items():
        if key not in cfg:
            raise DataError("params nav", key, f"one of {sorted(cfg)}", "unknown key")
        if key == "noise_scale":                                 # a number, 'auto', or per dataset over the default's
            cfg[key] = ({**cfg[key], **value} if isinstance(value, dict) and isinstance(cfg[key], dict) else value)
        elif isinstance(cfg[key], dict):                         # init, alignment, noise_search, nhc, zupt: key by key
            unknown = set(value or {}) - set(cfg[key])
            if unknown:
                raise DataError(f"params nav.{key}", sorted(unknown)[0], f"one of {sorted(cfg[key])}",
                                "unknown key")
            cfg[key].update(value or {})
        else:
            cfg[key] = value
    gate_thresholds(cfg["innovation_gate"], "params nav")      # a bad probability fails here, by name
    navego_setup.check_tuning(cfg["ins_tuning"], "params nav")
    cn.constraint_config(cfg)                                   # and bad constraint settings
    if cfg["alignment"]["mode"] not in MODES:
        raise DataError("params nav.alignment", "mode", f"one of {MODES}", repr(cfg["alignment"]["mode"]))
    spec = cfg["noise_scale"]
    for key, scale in (spec.items() if isinstance(spec, dict) else [(None, spec)]):
        if scale != AUTO and (isinstance(scale, bool) or not isinstance(scale, (int, float)) or not scale > 0):
            raise DataError("params nav", "noise_scale" + (f".{key}" if key else ""),
                            f"a positive number or {AUTO!r}", repr(scale))
    if isinstance(spec, dict) and DEFAULT_DATASET_KEY not in spec:
        raise DataError("params nav", "noise_scale", f"a '{DEFAULT_DATASET_KEY}' entry beside the per-dataset ones",
                        repr(spec))
    return cfg


def noise_scale_of(cfg: dict, dataset: str):
    """``nav.noise_scale`` for one drive: the number or ``auto``, or from a mapping its entry (else ``default``).

    Drives differ: a simulated IMU's filter is set from the error model it was made with (1), a recorded IMU's
    datasheet says nothing of the car's vibration (``auto``)."""
    spec = cfg["noise_scale"]
    return spec.get(dataset, spec[DEFAULT_DATASET_KEY]) if isinstance(spec, dict) else spec


def gps_aids(drive, cfg: dict, initial: FilterState, noise: FilterNoise) -> list:
    """The aids of the GPS-aided run beside the GNSS fixes: the vehicle constraints with ``constraints_in_gps_run``,
    none otherwise (the paper's filter).

    When asked, a first GPS-aided pass without them gives the vehicle frame (its causal running estimate,
    :func:`bgfn.nav.constraints.mounting_track`), then the constraints hold the whole drive's detector and aid
    epochs. Used by every GPS-aided run (:func:`run_drive`, :func:`run_baseline`,
    :func:`bgfn.evaluate.navigation_context`) so that they agree.
    """
    if not cfg["constraints_in_gps_run"]:
        return []
    first = run_filter(filter_imu(drive, cfg), initial, noise, drive.gnss, drive.meta.get("lever_arm_m", [0.0, 0.0, 0.0]),
                       gate_probability=cfg["innovation_gate"], source=drive.name)
    return [outage_constraints(drive, cfg, first)]


def outage_constraints(drive, cfg: dict, solution: FilterResult):
    """The vehicle constraints of the ``INS+NHC`` runs of ``drive``: the stillness detector over its IMU and the
    vehicle frame from the GPS-aided ``solution``'s trajectory, each epoch weighted by its heading std
    (:func:`bgfn.nav.constraints.build_constraints`, ``nav.nhc.mounting_weight``)."""
    heading_std = solution.sd[STATE_NAMES[PHI_D]].to_numpy(float)
    return cn.build_constraints(drive.imu, drive.meta["imu_errors"], cn.constraint_config(cfg), solution.trajectory,
                                source=drive.name, platform=drive.meta.get("platform", cn.DEFAULT_PLATFORM),
                                heading_std=heading_std)


#: Bumped when a GPS-aided run changes in a way the hashed sources do not show (:func:`run_key`).
RUN_CACHE_VERSION = 1


def _code_version() -> str:
    """The sources a GPS-aided run is made by: the navigation package and the core facts it imports."""
    here = Path(__file__).resolve().parent
    core = here.parent
    return sources_hash(sorted(here.glob("*.py")) + [core / f"{m}.py" for m in ("settings", "paper", "schema",
                                                                               "config", "errors", "io")])


def run_key(drive, cfg: dict, **inputs) -> dict:
    """The key of a GPS-aided run of ``drive`` (:func:`bgfn.io.cached`): the drive's content (truth, IMU, GNSS,
    bias, facts), the ``nav:`` settings, the run's other ``inputs``, the code and the numerical libraries."""
    return {"drive": content_hash({"name": drive.name, "reference": drive.reference, "imu": drive.imu,
                                   "gnss": drive.gnss, "imu_bias": drive.imu_bias, "meta": drive.meta}),
            "nav": cfg, **inputs, "code": _code_version(), "version": RUN_CACHE_VERSION,
            "libraries": [np.__version__, pd.__version__, numba.__version__]}


def run_drive(drive, section: dict | None = None, snapshots: dict | None = None) -> FilterResult:
    """GPS/INS filter over a whole drive with every GNSS fix (the paper's online-training mode).

    Parameters
    ----------
    drive : bgfn.data.Drive
    section : dict, optional
        A profile's ``nav:`` section (defaults: ``NAV_DEFAULTS``).
    snapshots : dict, optional
        ``{name: time}`` of filter states to save (see :func:`bgfn.nav.filter.run_filter`).

    Returns
    -------
    FilterResult
    """
    cfg = nav_config(section)

    def compute() -> FilterResult:
        initial, noise = initial_and_noise(drive, cfg)
        return run_filter(filter_imu(drive, cfg), initial, noise, drive.gnss, _lever(drive), snapshots=snapshots,
                          gate_probability=cfg["innovation_gate"], source=drive.name,
                          aids=gps_aids(drive, cfg, initial, noise))

    # computed once per drive and settings: notebooks 03, 06 and the studies take the INS attitude from it
    return cached("gps_aided_run", lambda: run_key(drive, cfg, snapshots=snapshots), compute)


@dataclass
class FilterSetup:
    """Where and how the filter of a drive starts (:func:`prepare_filter`).

    Attributes
    ----------
    initial : FilterState
        State at the start: the reference's first row, or the self-alignment's epoch (later).
    noise : FilterNoise
    noise_scale : float
        The factor on the white-noise densities in ``noise`` (the profile's number, or the one found).
    alignment : bgfn.nav.alignment.Alignment or None
        The self-alignment (:mod:`bgfn.nav.alignment`); None when the filter starts from the reference.
    tuning : NoiseTuning or None
        The noise search (:mod:`bgfn.nav.tuning`); None when ``noise_scale`` is a number.
    reference_attitude : dict or None
        The check of the reference's attitude (:func:`bgfn.nav.reference_attitude.check_attitude`; not ``usable``:
        ``auto`` aligned itself instead); None without a reference attitude.
    """

    initial: FilterState
    noise: FilterNoise
    noise_scale: float
    alignment: Alignment | None = None
    tuning: NoiseTuning | None = None
    reference_attitude: dict | None = None

    def record(self) -> dict:
        """JSON-ready record (``kf_baseline.json``)."""
        a = self.alignment
        return {"start_time": float(self.initial.time), "noise_scale": float(self.noise_scale),
                "reference_attitude": self.reference_attitude,
                "noise_tuning": self.tuning.record() if self.tuning is not None else None,
                "alignment": None if a is None else {
                    "time": float(a.state.time), "gnss_time": a.gnss_time, "roll_deg": float(np.degrees(a.roll)),
                    "pitch_deg": float(np.degrees(a.pitch)), "yaw_deg": float(np.degrees(a.yaw)),
                    "level_source": a.level_source, "course_source": a.course_source, "rest_end": a.rest_end,
                    "moving_from": a.moving_from, "level_std_deg": float(np.degrees(a.level_std)),
                    "azimuth_std_deg": float(np.degrees(a.azimuth_std))}}


def _lever(drive) -> list:
    return drive.meta.get("lever_arm_m", [0.0, 0.0, 0.0])


def _has_attitude(drive) -> bool:
    return bool(getattr(drive, "has_attitude", True))


def _navego(cfg: dict) -> bool:
    return cfg["ins_tuning"] == "navego"


def _noise(drive, cfg: dict, scale: float) -> FilterNoise:
    """Process noise with the factor ``scale`` on the white-noise densities (``nav.ins_tuning`` picks the model)."""
    errors, source = drive.meta["imu_errors"], f"{drive.name} meta['imu_errors']"
    if _navego(cfg):
        return navego_setup.navego_noise(errors, scale, source=source)
    walk = scale if cfg["noise_search"]["bias_walk"] else 1.0     # the factor on the bias walk too, when asked
    return noise_from_imu_errors(errors, cfg["bias_model"], scale, source=source, bias_walk_scale=walk)


def reference_attitude(drive, cfg: dict) -> dict | None:
    """:func:`bgfn.nav.reference_attitude.check_attitude` of the drive's reference under ``nav.alignment`` (None:
    the reference has no attitude)."""
    return check_attitude(drive.reference, drive.imu, cfg["alignment"]) if _has_attitude(drive) else None


def _initial(drive, cfg: dict, noise: FilterNoise, attitude: dict | None) -> tuple[FilterState, Alignment | None]:
    """The state the filter starts from (``nav.alignment.mode``) and the self-alignment when it ran; ``auto`` aligns
    itself when the reference's attitude fails its check (:mod:`bgfn.nav.reference_attitude`)."""
    mode = cfg["alignment"]["mode"]
    if mode == "reference" and not _has_attitude(drive):
        raise DataError(drive.name, "nav.alignment.mode", "'gnss' or 'auto' for a drive without a reference "
                        "attitude (roll, pitch, yaw all finite)", "'reference'")
    refused = mode == "auto" and attitude is not None and not attitude["usable"]
    if mode == "gnss" or (mode == "auto" and not _has_attitude(drive)) or refused:
        options = {k: v for k, v in cfg["alignment"].items() if k != "mode"}
        a = align(filter_imu(drive, cfg), drive.gnss, _lever(drive), noise, options, source=drive.name)
        initial, alignment = a.state, a
    else:
        row = drive.reference.iloc[0]
        init = cfg["init"]
        P0 = initial_covariance(row[["lat", "lon", "h"]].to_numpy(float), noise, init["position_std_m"],
                                init["height_std_m"], init["velocity_std_mps"], np.radians(init["level_std_deg"]),
                                np.radians(init["azimuth_std_deg"]))
        initial, alignment = initial_state(row, P0), None
    if _navego(cfg):      # NaveGo starts its bias estimates at the dynamic-bias values (navego_setup)
        errors = drive.meta["imu_errors"]
        initial.gyro_bias, initial.accel_bias = navego_setup.initial_bias_estimates(
            errors, f"{drive.name} meta['imu_errors']")
    return initial, alignment


def prepare_filter(drive, cfg: dict) -> FilterSetup:
    """Initial state and noise of a drive's filter (``nav.alignment``, ``nav.noise_scale``).

    With ``noise_scale: auto`` the factor comes from :func:`bgfn.nav.tuning.search_noise_scale` over GPS-aided runs
    of the whole drive from the same initial state (the initial state does not depend on the factor: P0 holds
    only the bias priors of the noise).

    Parameters
    ----------
    drive : bgfn.data.Drive
    cfg : dict
        Output of :func:`nav_config`.

    Returns
    -------
    FilterSetup
    """
    scale = noise_scale_of(cfg, drive.name)
    auto = scale == AUTO
    noise = _noise(drive, cfg, 1.0 if auto else scale)
    attitude = reference_attitude(drive, cfg)
    initial, alignment = _initial(drive, cfg, noise, attitude)
    if not auto:
        return FilterSetup(initial, noise, float(scale), alignment, reference_attitude=attitude)

    def mean_nis(scale: float) -> tuple[float, float]:
        run = run_filter(filter_imu(drive, cfg), initial, _noise(drive, cfg, scale), drive.gnss, _lever(drive),
                         gate_probability=cfg["innovation_gate"], source=drive.name)
        s = nis_summary(run.updates)
        if not s["fixes"]:
            raise DataError(drive.name, "gnss", "GNSS fixes to set nav.noise_scale: auto from", "none fused")
        return s["mean_nis"], s["dof"]

    # the search's filter runs are three quarters of a navigation context of such a drive, built again by every
    # study on it: kept once per drive and settings (the same factor, bit for bit)
    tuning = cached("noise_scale", lambda: run_key(drive, cfg), lambda: search_noise_scale(mean_nis, cfg["noise_search"]))
    return FilterSetup(initial, _noise(drive, cfg, tuning.scale), tuning.scale, alignment, tuning, attitude)


def initial_and_noise(drive, cfg: dict) -> tuple[FilterState, FilterNoise]:
    """Initial filter state and noise for a drive (:func:`prepare_filter` without its record).

    With ``ins_tuning: navego`` the noise and the bias priors are NaveGo's (:func:`bgfn.nav.navego_setup.navego_noise`)
    and the bias estimates start at the dynamic-bias values; the filter must then read :func:`filter_imu`.

    Parameters
    ----------
    drive : bgfn.data.Drive
    cfg : dict
        Output of :func:`nav_config`.

    Returns
    -------
    initial : FilterState
        At the reference's first row, or at the self-alignment's epoch (``nav.alignment``).
    noise : FilterNoise
    """
    s = prepare_filter(drive, cfg)
    return s.initial, s.noise


def filter_imu(drive, cfg: dict) -> pd.DataFrame:
    """The IMU table the filter reads: ``drive.imu`` itself, or with ``ins_tuning: navego`` a copy without the
    profile's static biases (:func:`bgfn.nav.navego_setup.remove_static_biases`)."""
    if not _navego(cfg):
        return drive.imu
    return navego_setup.remove_static_biases(
        drive.imu, *navego_setup.static_biases(drive.meta["imu_errors"], f"{drive.name} meta['imu_errors']"))


def filter_start(drive, section: dict | None) -> float:
    """Time the filter of ``drive`` starts at with a profile's ``nav:`` section, s: the reference's first row, or
    the self-alignment's epoch. Cheap (no filter run): for the checks of outage windows and sweep starts."""
    cfg = nav_config(section)
    mode, attitude = cfg["alignment"]["mode"], reference_attitude(drive, cfg)
    if mode == "reference" or (mode == "auto" and attitude is not None and attitude["usable"]):
        return float(drive.reference["time"].iloc[0])
    initial, _ = _initial(drive, cfg, _noise(drive, {**cfg, "noise_scale": 1.0}, 1.0), attitude)
    return float(initial.time)


@dataclass
class Baseline:
    """KF baseline of one drive.

    Attributes
    ----------
    drive_name : str
    full : FilterResult
        GPS/INS over the whole drive (GNSS everywhere).
    errors : DataFrame
        ``metrics.navigation_errors`` of ``full``.
    rms : DataFrame
        ``metrics.rms_table`` of ``errors``.
    states : dict
        ``{"outage_1": FilterState, ...}`` at the outage starts.
    outage_errors : dict
        ``{"outage_1": DataFrame}``: errors of the standalone INS in each outage, then those of ``INS+NHC``
        (column ``method``).
    outage_table : DataFrame
        One row per outage and method (``INS``, then ``INS+NHC``): ``dataset``, ``outage``, ``method`` and
        ``metrics.outage_metrics``.
    noise : FilterNoise
    constraints : dict
        :meth:`bgfn.nav.constraints.Constraints.summary` of the ``INS+NHC`` runs' constraints.
    reference_equals_gnss : bool
        The drive's reference is its GNSS (``meta["reference_equals_gnss"]``, :mod:`bgfn.data.reference_check`):
        the errors against it are no accuracy.
    """

    drive_name: str
    full: FilterResult
    errors: pd.DataFrame
    rms: pd.DataFrame
    states: dict
    outage_errors: dict
    outage_table: pd.DataFrame
    noise: FilterNoise
    setup: FilterSetup | None = None
    constraints: dict | None = None
    reference_equals_gnss: bool = False


def run_baseline(drive, cfg: dict, windows, keep: bool = True) -> Baseline:
    """Full-drive GPS/INS run, then the standalone INS in each outage from the saved state at its start, without
    and with the vehicle constraints (``INS``, ``INS+NHC``: :func:`outage_constraints`).

    Parameters
    ----------
    drive : bgfn.data.Drive
    cfg : dict
        Output of :func:`nav_config`.
    windows : sequence of (start, duration)
        The outages, s (:func:`bgfn.nav.outages.outage_windows`).
    keep : bool
        Keep the run on disk for the next caller with the same inputs (:func:`bgfn.io.cached`): the profile's own
        runs (notebooks 02 and 08); another filter setup, read once, passes False.

    Returns
    -------
    Baseline
    """
    if not keep:
        return _run_baseline(drive, cfg, windows)
    # computed once per drive, settings and outages: notebook 02 runs it, notebook 08 takes the same runs
    return cached("baseline", lambda: run_key(drive, cfg, windows=[tuple(map(float, w)) for w in windows]),
                  lambda: _run_baseline(drive, cfg, windows))


def _run_baseline(drive, cfg: dict, windows) -> Baseline:
    setup = prepare_filter(drive, cfg)
    initial, noise = setup.initial, setup.noise
    # the filter may start after the reference's first row (self-alignment): outages must come after its start;
    # the given order is kept (Outage k as in notebook 04)
    windows = check_windows(windows, float(initial.time), float(drive.imu["time"].iloc[-1]),
                            f"{drive.name}: profile outage_windows (filter start {initial.time:.2f} s)", sort=False)
    imu = filter_imu(drive, cfg)
    lever = _lever(drive)
    names = [f"outage_{i + 1}" for i in range(len(windows))]
    starts = epochs_before(drive.imu["time"], [w.start for w in windows], drive.name)
    full = run_filter(imu, initial, noise, drive.gnss, lever, snapshots=dict(zip(names, starts)),
                      gate_probability=cfg["innovation_gate"], source=drive.name,
                      aids=gps_aids(drive, cfg, initial, noise))
    errors = metrics.navigation_errors(full.trajectory, drive.reference, drive.meta)
    aids = outage_constraints(drive, cfg, full)
    rows, outage_errors = [], {}
    for n, w in zip(names, windows):
        parts = []
        for method, with_aids in (("INS", []), (INS_NHC, [aids])):
            res = run_outage(imu, full.states[n], w, noise, lever, source=drive.name, aids=with_aids)
            e = metrics.navigation_errors(res.trajectory, drive.reference, drive.meta)
            e.insert(1, "t_rel", e["time"] - w.start)
            e.insert(0, "method", method)
            parts.append(e)
            rows.append({"dataset": drive.name, "outage": n, "method": method, **metrics.outage_metrics(e, w)})
        outage_errors[n] = pd.concat(parts, ignore_index=True)
    table = pd.DataFrame(rows).sort_values("method", key=lambda m: m != "INS", kind="stable").reset_index(drop=True)
    return Baseline(drive.name, full, errors, metrics.rms_table(errors), full.states, outage_errors, table, noise,
                    setup, aids.summary(), bool(drive.meta.get("reference_equals_gnss", False)))


def ins_layout(outage_table: pd.DataFrame, dataset: str | None = None) -> pd.DataFrame:
    """Standalone-INS max errors in the paper's layout (:func:`bgfn.paper.layout`, methods ``INS`` and, when the
    table has them, ``INS+NHC``).

    Parameters
    ----------
    outage_table : DataFrame
        ``Baseline.outage_table`` of one dataset (per method one row per outage, in order; no ``method``
        column: all ``INS``).
    dataset : str, optional
        When it stands for one of the tests (:func:`bgfn.paper.test_of`), the paper's INS row of that test is
        beside ours (of its field test, labelled ``paper (field test)``, for the real drive).

    Returns
    -------
    DataFrame
        Rows ``Outage k``; columns ``(source, method, East/North)``, m (the paper's side: ``INS`` only).
    """
    method = outage_table["method"] if "method" in outage_table.columns else pd.Series("INS", outage_table.index)
    parts = []
    for m in dict.fromkeys(method):
        rows = outage_table[method == m]
        parts.append(pd.DataFrame({"outage": np.arange(1, len(rows) + 1), "method": m,
                                   "max_east_m": rows["max_abs_east"].to_numpy(float),
                                   "max_north_m": rows["max_abs_north"].to_numpy(float)}))
    ours = pd.concat(parts, ignore_index=True)
    test = paper.test_of(dataset) if dataset else None
    return paper.layout(ours, paper.published_values(test) if test else None, methods=tuple(dict.fromkeys(method)),
                        paper_label=paper.paper_label(test) if test else "paper")


def ins_max_error_file(outage_table: pd.DataFrame) -> pd.DataFrame:
    """:func:`ins_layout` (ours) flattened for ``tables/kf_outage_max_errors_<d>.csv``: ``outage``
    (``Outage k``), ``INS_east_m``, ``INS_north_m`` and, with the constraints' rows, ``INS+NHC_east_m``,
    ``INS+NHC_north_m`` (m, 2 decimals)."""
    ours = ins_layout(outage_table)["ours"]
    methods = list(dict.fromkeys(ours.columns.get_level_values("method")))
    return pd.DataFrame({"outage": list(ours.index),
                         **{f"{m}_{axis.lower()}_m": ours[(m, axis)].round(2).to_numpy()
                            for m in methods for _, axis in paper.AXES}})


def save_baseline(b: Baseline, out, file_id: str, lat=None) -> dict:
    """Write one drive's baseline under ``out`` (``results/<profile>``) atomically.

    Files (``<d>`` = the dataset's id, :func:`bgfn.data.names.dataset_id`, never a folder path):

    - ``nav_states_<d>.npz``: the filter states at the outage starts (:func:`bgfn.nav.state.save_states`,
      names ``outage_1``, ``outage_2``, ...), the start of every outage run of notebook 04;
    - ``tables/kf_rms_<d>.csv``: RMS / max-abs errors of the full GPS/INS run;
    - ``tables/kf_outage_max_errors_<d>.csv``: :func:`ins_max_error_file`;
    - ``tables/kf_outage_metrics_<d>.csv``: all outage metrics;
    - ``tables/kf_outage_errors_<d>.csv``: standalone-INS error series (``outage``, ``method``, ``t_rel``,
      ``east``, ``north``, ``down``, ``horizontal``, m).

    Returns
    -------
    dict
        JSON-ready summary (RMS, outage metrics, mean NIS, the filter's start and noise factor
        (:meth:`FilterSetup.record`), the constraints' facts) for ``kf_baseline.json``.
    """
    out = Path(out)
    d = file_id
    # the INS+NHC rows named by the aids that ran on this drive (INS+ZUPT for a walker; the code keys them +NHC)
    aids = cn.platform_aids((b.constraints or {}).get("platform", cn.DEFAULT_PLATFORM))
    save_states(out / f"nav_states_{d}.npz", b.states)
    atomic_write_csv(out / "tables" / f"kf_rms_{d}.csv", b.rms.reset_index(), float_format="%.6g")
    atomic_write_csv(out / "tables" / f"kf_outage_max_errors_{d}.csv",
                     row_labels.ran_labels(ins_max_error_file(b.outage_table), aids))
    atomic_write_csv(out / "tables" / f"kf_outage_metrics_{d}.csv", row_labels.ran_labels(b.outage_table, aids),
                     float_format="%.6g")
    series = pd.concat([e.assign(outage=name)[["outage", "method", "t_rel", "east", "north", "down", "horizontal"]]
                        for name, e in b.outage_errors.items()], ignore_index=True)
    atomic_write_csv(out / "tables" / f"kf_outage_errors_{d}.csv", row_labels.ran_labels(series, aids),
                     float_format="%.6g")
    upd = b.full.updates
    return {"rms": {k: float(v) for k, v in b.rms["rms"].items()},
            "outages": b.outage_table.drop(columns=["dataset"]).to_dict(orient="records"),
            "gnss_updates": int(len(upd)), "gnss_rejected": int((~upd["accepted"]).sum()) if len(upd) else 0,
            "mean_nis": float(upd["nis"].mean()) if len(upd) else None,
            "mean_nis_dof": float(upd["dof"].mean()) if len(upd) else None,
            "nis_verdict": nis_summary(upd)["verdict"], "constraints": b.constraints,
            "reference_equals_gnss": b.reference_equals_gnss,
            "states_file": f"nav_states_{d}.npz", **(b.setup.record() if b.setup is not None else {})}


def gate_comparison(drive, cfg: dict, windows, probability: float, baseline: Baseline | None = None) -> pd.DataFrame:
    """The baseline of ``drive`` without and with an innovation gate on the GNSS fixes (notebook 02).

    Parameters
    ----------
    drive : bgfn.data.Drive
    cfg : dict
        Output of :func:`nav_config`; its ``innovation_gate`` is replaced by None and by ``probability``.
    windows : sequence of (start, duration)
        The outages, s (as for :func:`run_baseline`).
    probability : float
        Chi-square probability of the gate (:func:`bgfn.nav.gnss_aid.gate_thresholds`).
    baseline : Baseline, optional
        The run with ``cfg`` as it is (notebook 02 has it already): reused for the setting it matches.

    Returns
    -------
    DataFrame
        One row per setting (``innovation_gate``: ``none`` or the probability): ``gnss_rejected`` (fixes not
        fused), ``mean_nis``, the full-drive horizontal ``rms_h_m`` and ``max_h_m`` against the reference, and
        the standalone INS's ``max_east_m`` / ``max_north_m`` in each outage ``k`` (``outage_k_...``), which
        start from the filter's state.
    """
    rows = []
    if baseline is not None and baseline.setup is not None:       # a factor found once serves both settings
        cfg = {**cfg, "noise_scale": baseline.setup.noise_scale}
    for gate in (None, probability):
        same = baseline is not None and gate == cfg["innovation_gate"]
        b = baseline if same else run_baseline(drive, {**cfg, "innovation_gate": gate}, windows, keep=False)
        upd = b.full.updates
        row = {"dataset": drive.name, "innovation_gate": "none" if gate is None else f"{gate:g}",
               "gnss_fixes": int(len(upd)), "gnss_rejected": int((~upd["accepted"]).sum()),
               "mean_nis": float(upd["nis"].mean()) if len(upd) else float("nan"),
               "rms_h_m": float(b.rms.loc["horizontal", "rms"]), "max_h_m": float(b.rms.loc["horizontal", "max_abs"])}
        for k, r in enumerate(b.outage_table[b.outage_table["method"] == "INS"].itertuples(index=False)):
            row[f"outage_{k + 1}_max_east_m"] = float(r.max_abs_east)
            row[f"outage_{k + 1}_max_north_m"] = float(r.max_abs_north)
        rows.append(row)
    return pd.DataFrame(rows)

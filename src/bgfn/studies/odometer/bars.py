"""The bars a learned odometer must clear (beyond the paper), in the outage sweep's windows.

A learned odometer predicts the forward speed and its std from body-frame IMU windows, fused with the NHC rows
(:mod:`bgfn.nav.odometer`). With the sweep's starts, folds and durations this module runs ``INS+NHC``;
``INS+NHC+HOLD`` (the speed at the outage start held); ``RIDGE-ODO`` (a ridge on band energies,
:class:`bgfn.learning.odometry.RidgeOdometer`); the networks as odometers (``BGFN-ODO`` ...,
trained per fold with beta-NLL, their std calibrated on validation windows) and their seed ensembles; and
``ORACLE-SPEED`` (the reference's speed plus white noise ``sigma``; ``+WALK`` adds a random walk): how accurate a
speed must be to help. Learned odometers are fused with ``R = kappa std^2``, ``kappa`` the integrated
autocorrelation of their validation errors. With ``paper_outages`` every row also runs in the drive's two
evaluation outages (:data:`PAPER_FOLD`, ``outage_odometer_paper.csv``), outside the sweep's statistics.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np
import pandas as pd

from bgfn.config import odometer_inputs, odometer_network_seeds
from bgfn.errors import DataError
from bgfn.data import load_drive
from bgfn.evaluate.hybrid import navigation_context, run_outages, window_metrics
from bgfn.studies.odometer.ridge_curve import ridge_curve
from bgfn.studies.outage_sweep.sweep import profile_sweep_plan, sweep_train_config
from bgfn.learning import odometry as lo
from bgfn.learning.split import overlaps
from bgfn.nav.outages import outage_windows
from bgfn.train.checkpoints import checkpoint_name, odometer_models_dir
from bgfn.train.objectives import SpeedObjective
from bgfn.train.options import optimizer_options
from bgfn.train.speed import torch_threads
from bgfn.nav import odometer as no
from bgfn.nav.constraints import DEFAULT_PLATFORM
from bgfn import train
from bgfn.paper import METHOD_LABELS, ensemble_label, nhc_label, odometer_label
from bgfn.parallel import Runner
from bgfn.stats import holm_adjust, wilcoxon_p

HOLD, RIDGE, ORACLE, ORACLE_WALK = "INS+NHC+HOLD", "RIDGE-ODO", "ORACLE-SPEED", "ORACLE-SPEED+WALK"
#: A network odometer's row: ``BGFN-ODO``, ``Transformer-ODO``, ...
NETWORK_ODOMETERS: tuple[str, ...] = tuple(odometer_label(m) for m in METHOD_LABELS)
#: The equal-weight ensemble of a network's seeds per fold (``evaluate.odometer.ensemble``): ``BGFN-ODO-ENS`` ...
ENSEMBLE_ODOMETERS: tuple[str, ...] = tuple(ensemble_label(m) for m in NETWORK_ODOMETERS)
#: The learned odometers: the family a page names its best of (the ridge, each network, each ensemble), whose
#: p-values against INS+NHC are Holm-adjusted together (:func:`holm_vs_nhc`).
LEARNED_ODOMETERS: tuple[str, ...] = (RIDGE, *NETWORK_ODOMETERS, *ENSEMBLE_ODOMETERS)
#: Rows of the odometer table, in order.
ODOMETER_METHODS: tuple[str, ...] = (nhc_label("INS"), HOLD, RIDGE, *NETWORK_ODOMETERS, *ENSEMBLE_ODOMETERS, ORACLE,
                                     ORACLE_WALK)
#: Columns of ``tables/outage_odometer.csv``.
ODOMETER_COLUMNS: tuple[str, ...] = ("dataset", "start_s", "duration_s", "method", "sigma_mps", "seed", "fold",
                                     "max_h_m", "rmse_h_m", "final_h_m", "speed_rmse_mps", "coverage_2sigma")


#: The fold of the drive's two evaluation outages (module docstring).
PAPER_FOLD = -1
#: Columns of ``tables/outage_odometer_paper.csv`` (:func:`paper_outage_table`).
PAPER_COLUMNS: tuple[str, ...] = ("dataset", "outage", "start_s", "duration_s", "method", "sigma_mps", "max_h_m",
                                  "speed_rmse_mps", "coverage_2sigma", "runs")
#: Columns of ``tables/outage_odometer_networks.csv`` (:func:`network_table`).
NETWORK_COLUMNS: tuple[str, ...] = ("dataset", "method", "fold", "seed", "lr", "epochs", "val_rmse_mps", "calibration",
                                    "correlation", "outage_speed_rmse_mps", "outage_coverage_2sigma")
#: Columns of ``tables/outage_odometer_summary.csv`` (:func:`odometer_summary`).
SUMMARY_COLUMNS: tuple[str, ...] = ("dataset", "duration_s", "method", "sigma_mps", "max_h_m", "ratio_to_nhc",
                                    "speed_rmse_mps", "coverage_2sigma", "runs", "p_vs_nhc", "p_vs_nhc_holm")


@dataclass(frozen=True)
class OdometerRun:
    """One aid in some outages (an independent run): ``label``, the outages ``(start, duration)``, the aid
    (:class:`bgfn.nav.odometer.Odometer` or the bare constraints), and what the row records."""

    label: str
    windows: list
    aid: object
    method: str
    sigma_mps: float
    seed: int
    fold: int


def odometer_run(ctx, run: OdometerRun, pseudo: dict) -> list:
    """The outage runs of one :class:`OdometerRun` (no network: the aid alone)."""
    return run_outages(ctx, run.windows, None, run.method, None, pseudo, aids=no.aid_list(run.aid))


def reference_speed(drive, time) -> np.ndarray:
    """The reference's horizontal speed at ``time`` (s), m/s (a car's forward speed up to its small slip)."""
    ref = drive.reference
    return np.interp(np.asarray(time, float), ref["time"].to_numpy(float),
                     np.hypot(ref["v_n"].to_numpy(float), ref["v_e"].to_numpy(float)))


def oracle_track(epochs: np.ndarray, truth: np.ndarray, sigma: float, walk: float, seed: int,
                 rate_hz: float) -> no.SpeedTrack:
    """``truth`` plus white noise of std ``sigma`` and a random walk of ``walk`` m/s per sqrt(s), seeded; std
    ``sigma``."""
    rng = np.random.default_rng([int(seed), int(round(1e6 * sigma))])
    drift = np.cumsum(rng.standard_normal(epochs.size)) * walk / np.sqrt(rate_hz)
    return no.SpeedTrack(epochs, truth + sigma * rng.standard_normal(epochs.size) + drift, np.full(epochs.size,
                                                                                                    float(sigma)))


def odometer_rows(cfg: dict, profile: str, dataset: str, ecfg: dict, runner: Runner | None = None,
                  drive=None) -> tuple[pd.DataFrame, dict]:
    """The odometer bars of one dataset in the sweep's windows (module docstring): rows
    (:data:`ODOMETER_COLUMNS`) and facts (the ridge's std per fold, the epochs, the wall time)."""
    t0 = time.perf_counter()
    oc, sw = ecfg["odometer"], ecfg["sweep"]
    drive = drive if drive is not None else load_drive(dataset, profile=profile)
    platform = drive.meta.get("platform", DEFAULT_PLATFORM)
    if platform != "car":
        # a forward speed along the vehicle's x axis, fused with the NHC rows: a car's aid; a walker takes no NHC
        return pd.DataFrame(columns=list(ODOMETER_COLUMNS)), {
            "ridge_std_mps": {}, "paper_windows": [], "wall_s": time.perf_counter() - t0, "skipped": platform,
            "speed_series": None}
    plan = profile_sweep_plan(cfg, drive, sw)
    dmax = max(float(d) for d in sw["durations_s"])
    paper = [(float(s), float(d)) for s, d in outage_windows(cfg, drive, dataset)] if oc["paper_outages"] else []
    ctx = navigation_context(drive, cfg.get("nav"), sorted({*map(float, plan["start_s"]), *(s for s, _ in paper)}))
    con = ctx.constraints
    rate = float(con.config.nhc_rate_hz)
    window, imu_rate = lo.window_samples(drive.imu, oc["window_s"])       # the ridge's band energies need 2 s
    traj = ctx.full.trajectory
    tt = traj["time"].to_numpy(float)
    speed = lo.forward_speed(traj, con.mounting_at(tt))                    # the GPS-aided solution's
    epochs = np.arange(np.ceil(tt[0] * rate) / rate, tt[-1], 1.0 / rate)
    all_windows = lo.speed_windows(drive.imu, epochs, window)
    ws = lo.speed_windows(drive.imu, epochs, window, np.interp(epochs, tt, speed))
    truth = reference_speed(drive, all_windows.t_end)
    gate = oc["gate_probability"]
    margin, val_fraction = float(cfg["train"]["margin_s"]), float(cfg["train"]["val_fraction"])
    folds = {int(k): [(float(s), dmax) for s in plan.loc[plan["fold"] == k, "start_s"]]
             for k in sorted(plan["fold"].unique())}
    if paper:
        folds[PAPER_FOLD] = paper
    # one honest split per fold: the ridge and the networks learn from the same windows, the networks through
    # their front ends (evaluate.odometer.inputs, per network)
    data = {k: lo.build_speed_data(ws, fw, margin, val_fraction, int(oc["val_blocks"]), bool(oc["calibration_blocks"]))
            for k, fw in folds.items()}
    runs, tracks = [], {}
    facts = {"ridge_std_mps": {}, "ridge_correlation": {}, "epochs": int(len(all_windows)),
             "paper_windows": folds.get(PAPER_FOLD, [])}
    honest = {"time": all_windows.t_end, "truth": truth, "outages": [], "tracks": {}}   # each outage: its own fold's

    def keep(label: str, track: no.SpeedTrack, inside: np.ndarray) -> None:
        """Put ``track``'s speed and std inside one fold's outages into the honest series of ``label``."""
        speed, std = honest["tracks"].setdefault(label, (np.full(truth.size, np.nan), np.full(truth.size, np.nan)))
        speed[inside], std[inside] = track.at(all_windows.t_end[inside])

    for k, fw in folds.items():
        model = lo.RidgeOdometer.fit(data[k].train, data[k].calibration_windows, imu_rate, float(oc["ridge_alpha"]),
                                     float(oc["correlation_max_lag_s"]))
        track = model.track(all_windows).correlated(model.correlation if oc["correlation"] else 1.0)
        facts["ridge_std_mps"][int(k)] = model.std_mps
        facts["ridge_correlation"][int(k)] = model.correlation
        if k != PAPER_FOLD:             # the speed figure: the sweep's outages (the paper's two overlap them)
            keep(RIDGE, track, overlaps(all_windows.t_end, all_windows.t_end, np.array([[s, s + d] for s, d in fw])))
            honest["outages"] += fw
        runs.append(OdometerRun(f"{dataset} fold {k} {RIDGE}", fw, no.Odometer(con, track, gate), RIDGE,
                                np.nan, 0, int(k)))
        tracks[runs[-1].label] = track
        runs.append(OdometerRun(f"{dataset} fold {k} {nhc_label('INS')}", fw, con, nhc_label("INS"), np.nan, 0,
                                int(k)))
        for s, d in fw:
            v0 = float(np.interp(s, tt, speed))
            held = no.SpeedTrack(epochs, np.full(epochs.size, v0), np.full(epochs.size, float(oc["hold_std_mps"])))
            runs.append(OdometerRun(f"{dataset} fold {k} {s:.0f} s {HOLD}", [(s, d)], no.Odometer(con, held, gate), HOLD,
                                    np.nan, 0, int(k)))
            tracks[runs[-1].label] = held
        walks = [(ORACLE, 0.0)] + ([(ORACLE_WALK, float(oc["walk_mps_per_sqrt_s"]))]
                                   if oc["walk_mps_per_sqrt_s"] > 0 else [])
        for (method, walk), sigma, seed in ((w, s, e) for w in walks for s in oc["sigmas_mps"] for e in oc["seeds"]):
            track = oracle_track(all_windows.t_end, truth, float(sigma), walk, int(seed), rate)
            runs.append(OdometerRun(f"{dataset} fold {k} {method} {sigma:g} m/s seed {seed}", fw,
                                    no.Odometer(con, track, gate), method, float(sigma), int(seed), int(k)))
            tracks[runs[-1].label] = track
    inputs_of = {m: odometer_inputs(oc, m) for m in oc["methods"]}
    nets = {}
    for inputs in dict.fromkeys(inputs_of.values()):        # one front end at a time, the networks in their order
        group = {**ecfg, "odometer": {**oc, "methods": [m for m, i in inputs_of.items() if i == inputs]}}
        nets.update(network_odometers(cfg, profile, dataset, group,
                                      {k: lo.with_inputs(d, inputs, imu_rate) for k, d in data.items()},
                                      lo.network_inputs(all_windows, inputs, imu_rate), runner))
    facts["networks"] = {}
    for (label, k, seed), (track, fact) in nets.items():
        runs.append(OdometerRun(f"{dataset} fold {k} {label} seed {seed}", folds[k], no.Odometer(con, track, gate),
                                label, np.nan, seed, k))
        tracks[runs[-1].label] = track
        facts["networks"][f"{label} fold {k} seed {seed}"] = {**fact, "method": label, "fold": int(k),
                                                               "seed": int(seed)}
        if seed == min(odometer_network_seeds(oc, dataset)) and k != PAPER_FOLD:
            keep(label, track, overlaps(all_windows.t_end, all_windows.t_end,
                                        np.array([[s, s + d] for s, d in folds[k]])))
    results = (runner or Runner()).map(odometer_run, [(ctx, r, ecfg["pseudo_gps"]) for r in runs],
                                       labels=[r.label for r in runs], desc=f"odometer bars {dataset}")
    rows = []
    paper_duration = dict(paper)                 # start -> the evaluation outage's own duration
    for run, outs in zip(runs, results):
        track = tracks.get(run.label)
        for r in outs:
            # a paper outage at its own duration only; a sweep window at every duration of the sweep
            for du in (sw["durations_s"] if run.fold != PAPER_FOLD else [paper_duration[r.start]]):
                m = window_metrics(r.errors, r.start, float(du))
                rows.append({"dataset": dataset, "start_s": r.start, "duration_s": float(du), "method": run.method,
                             "sigma_mps": run.sigma_mps, "seed": run.seed, "fold": run.fold,
                             **{c: m[c] for c in ("max_h_m", "rmse_h_m", "final_h_m")},
                             **no.speed_errors(track, all_windows.t_end, truth, r.start, float(du))})
    # the ridge's speed error as more folds hold out less of the drive (bgfn.studies.odometer.ridge_curve)
    n_starts = int(plan["fold"].size)                                       # more folds than starts: one per start
    plans = {n: profile_sweep_plan(cfg, drive, {**sw, "folds": n})
             for n in sorted({min(int(n), n_starts) for n in oc["curve_folds"]})}
    facts["curve"] = ridge_curve(dataset, plans, ws, all_windows, truth, dmax, margin, val_fraction,
                                 int(oc["val_blocks"]), float(oc["ridge_alpha"]), imu_rate)
    facts["wall_s"] = time.perf_counter() - t0
    facts["speed_series"] = honest
    return pd.DataFrame(rows, columns=list(ODOMETER_COLUMNS)), facts


def network_odometers(cfg: dict, profile: str, dataset: str, ecfg: dict, data: dict[int, lo.SpeedData],
                      all_windows: lo.SpeedWindows, runner: Runner | None = None) -> dict:
    """The learned odometers of ``evaluate.odometer.methods`` (``BGFN-ODO`` ...), per sweep fold and seed: each
    trained on that fold's honest speed data (``data``, :func:`bgfn.learning.odometry.build_speed_data`, its windows
    through the front end) with the odometers' budget (:func:`odometer_train_config`) and the profile's
    ``train.lr`` (not the increments' search), its std calibrated on its validation windows
    (:func:`bgfn.learning.odometry.calibration_factor`, NIS = 1), and its speed over every epoch.

    Returns ``{(label, fold, seed): (SpeedTrack, facts)}``.
    """
    oc = ecfg["odometer"]
    if not oc["methods"] or (oc["network_datasets"] is not None and dataset not in oc["network_datasets"]):
        return {}
    # notebook 03's search tuned the rates for the increments, another target, and one of its picks (e.g. 0.27 for
    # BGFN on the real drive) can cripple a speed network: the same train.lr for every network, or with
    # lr_search the rate of each network chosen per fold by train.lr_search's grid on the speed objective
    tc = odometer_train_config(cfg["train"], ecfg)
    search = speed_lr_search(tc, profile, dataset, oc["methods"], data, runner) if oc["lr_search"] else None
    runs, keys = [], []
    for k in sorted(data):
        out = odometer_models_dir(profile, dataset, int(k))
        tk = train.with_selected_lr(tc, None if search is None else search[search["dataset"] == fold_name(dataset, k)])
        for m in oc["methods"]:
            for seed in odometer_network_seeds(oc, dataset):
                label = odometer_label(m)
                runs.append(train.TrainingRun(f"{dataset} fold {k} {label} seed {seed}", m, data[int(k)],
                                              train.size_config(tk, m), tk, int(seed), out, None,
                                              {"dataset": dataset, "profile": profile, "fold": int(k),
                                               "objective": "speed"}))
                keys.append((label, int(k), int(seed)))
    cards = train.train_runs(runs, runner, desc=f"odometer networks {dataset}")
    tracks = {}
    # a run sets its process's torch threads to train.optimizer.num_threads: with 1 job the runs ran here and left
    # that count, with several this process kept its own; predicting under the runs' count gives the same tracks
    # either way (a thread count changes the order of floating-point sums; measured: a few 1e-4 m in 120 s outages)
    with torch_threads(optimizer_options(tc)["num_threads"]):
        for key, run, card in zip(keys, runs, cards):
            tracks[key] = calibrated_track(run, card, all_windows, bool(oc["correlation"]),
                                           float(oc["correlation_max_lag_s"]))
    if oc["ensemble"] and len(odometer_network_seeds(oc, dataset)) > 1:
        tracks.update(ensemble_tracks(tracks, data, bool(oc["ensemble_recalibrate"]), bool(oc["correlation"]),
                                      float(oc["correlation_max_lag_s"])))
    return tracks


def ensemble_tracks(tracks: dict, data: dict[int, lo.SpeedData], recalibrate: bool = False,
                    correlation: bool = False, max_lag_s: float = lo.DEFAULT_MAX_LAG_S) -> dict:
    """Per network and fold, the equal-weight ensemble of its seeds' calibrated tracks (``tracks``, as
    :func:`network_odometers` returns them): the mean speed and the mixture's std
    (:func:`bgfn.learning.odometry.ensemble_speed`; a deep ensemble's predictive distribution, each member already
    calibrated on the validation windows). With ``recalibrate`` that std is scaled once more to NIS = 1 on the
    fold's calibration windows (``data[fold].calibration_windows``: its validation blocks, or those early stopping
    never saw); off by default, because the members agree most there, next to
    their training windows, so the factor takes back the disagreement the ensemble adds where they do not (the
    methods page gives the measurement). With ``correlation`` the filter fuses it with the integrated
    autocorrelation of its own validation errors (:func:`bgfn.learning.odometry.error_correlation`, up to
    ``max_lag_s``), as each member. Keyed ``(BGFN-ODO-ENS, fold, lowest seed)``; its facts: the factor applied (1
    without ``recalibrate``), the NIS on the validation windows before it, the validation speed RMSE, the
    correlation and the members."""
    groups: dict = {}
    for (label, fold, seed), (track, _) in tracks.items():         # in the runs' order: fold, network, seed
        groups.setdefault((label, fold), []).append((seed, track))
    out = {}
    for (label, fold), members in groups.items():
        if len(members) < 2:
            continue
        t = members[0][1].time
        speed, std = lo.ensemble_speed(np.stack([m.speed for _, m in members]), np.stack([m.std for _, m in members]))
        val = data[fold].calibration_windows
        v_speed, v_std = no.SpeedTrack(t, speed, std).at(val.t_end)
        fitted = lo.calibration_factor(v_speed - val.speed, v_std)      # sqrt(NIS) on the validation windows
        factor = fitted if recalibrate else 1.0
        kappa = lo.error_correlation(val.t_end, v_speed - val.speed, v_std * factor, max_lag_s=max_lag_s)
        out[(ensemble_label(label), fold, members[0][0])] = (
            no.SpeedTrack(t, speed, std * factor, kappa if correlation else 1.0),
            {"calibration": factor, "val_nis": fitted ** 2, "epochs": np.nan, "lr": np.nan, "members": len(members),
             "val_rmse_mps": float(np.sqrt(np.nanmean((v_speed - val.speed) ** 2))), "correlation": kappa})
    return out


def calibrated_track(run: train.TrainingRun, card: dict, all_windows: lo.SpeedWindows, correlation: bool = False,
                     max_lag_s: float = lo.DEFAULT_MAX_LAG_S) -> tuple:
    """One trained odometer network's :class:`bgfn.nav.odometer.SpeedTrack` over ``all_windows``, its std calibrated
    on its validation windows (:func:`bgfn.learning.odometry.calibration_factor`), and its facts. The integrated
    autocorrelation of its calibrated validation errors (:func:`bgfn.learning.odometry.error_correlation`, up to
    ``max_lag_s``) is always a fact; with ``correlation`` the filter fuses the track with it."""
    net = train.load_trained(Path(run.out_dir) / checkpoint_name(run.method, run.seed), device="cpu")
    obj = SpeedObjective(run.data)
    cal = run.data.calibration_windows                  # the validation blocks, or those early stopping never saw
    speed_val, std_val = obj.to_units(train.predict_normalized(net.model, net.norm.x(cal.x)))
    factor = lo.calibration_factor(speed_val - cal.speed, std_val)
    kappa = lo.error_correlation(cal.t_end, speed_val - cal.speed, std_val * factor, max_lag_s=max_lag_s)
    speed, std = obj.to_units(train.predict_normalized(net.model, net.norm.x(all_windows.x)))
    return (no.SpeedTrack(all_windows.t_end, np.maximum(speed, 0.0), std * factor, kappa if correlation else 1.0),
            {"calibration": factor, "val_rmse_mps": card["val_rmse_mps"], "epochs": card["epochs_run"],
             "lr": train.method_lr(run.train_cfg, run.method), "correlation": kappa})


def odometer_train_config(train_section: dict, ecfg: dict) -> dict:
    """The odometer networks' ``train:`` section: the sweep's (:func:`bgfn.studies.outage_sweep.sweep.sweep_train_config`)
    with ``evaluate.odometer.train`` laid over it the same way (null: the sweep's budget as it is)."""
    return sweep_train_config(sweep_train_config(train_section, ecfg["sweep"]), {"train": ecfg["odometer"]["train"]})


def fold_name(dataset: str, fold: int) -> str:
    """``<dataset> fold <k>``: a fold's name in the odometers' learning-rate search and its progress lines."""
    return f"{dataset} fold {int(fold)}"


def speed_lr_search(tc: dict, profile: str, dataset: str, methods, data: dict[int, lo.SpeedData],
                    runner: Runner | None = None) -> pd.DataFrame:
    """The learning rate of every odometer network ``methods`` per fold (``evaluate.odometer.lr_search``): the grid,
    extension and budget of ``tc``'s ``lr_search`` (``tc``: the odometers' ``train:`` section,
    :func:`odometer_train_config`; :func:`bgfn.train.search_profile_rates`, the same for every
    network), on a tuning split inside each fold's training windows (:func:`bgfn.learning.odometry.inner_speed_split`),
    so that neither the fold's outages nor its calibration block choose it; the sweep's model sizes.

    Returns
    -------
    DataFrame
        :data:`bgfn.train.LR_SEARCH_COLUMNS` with ``dataset`` = :func:`fold_name` and ``tuning_rmse_m`` the tuning
        speed RMSE (m/s); ``selected`` marks each network's rate per fold.
    """
    if not train.lr_search_options(tc)["grid"]:
        raise DataError("evaluate.odometer", "lr_search", "a train.lr_search.grid to search (or lr_search: false)",
                        "no grid")
    learning = {fold_name(dataset, k): (d, odometer_models_dir(profile, dataset, int(k)) / "lr_search")
                for k, d in sorted(data.items())}
    table = train.search_profile_rates(learning, methods, tc, runner, split=lo.inner_speed_split,
                                       extra_card={"dataset": dataset, "profile": profile, "objective": "speed"})
    return table[list(train.LR_SEARCH_COLUMNS)]


def run_odometer_bars(cfg: dict, profile: str, datasets, ecfg: dict, runner: Runner | None = None,
                      report: Callable[[str], None] | None = None) -> tuple[pd.DataFrame, dict]:
    """:func:`odometer_rows` of every dataset (notebook 07); the rows in dataset order and the facts."""
    parts, facts = [], {}
    for name in datasets:
        rows, facts[name] = odometer_rows(cfg, profile, name, ecfg, runner)
        parts.append(rows)
        if report is not None and not facts[name].get("skipped"):   # a skipped drive: the page says why
            report(f"{name}: {len(rows)} odometer rows in {facts[name]['wall_s']:.1f} s; RIDGE-ODO std per fold "
                   + ", ".join(f"{v:.2f} m/s (kappa {facts[name]['ridge_correlation'][k]:.1f})"
                               for k, v in facts[name]["ridge_std_mps"].items()))
    rows = pd.concat(parts, ignore_index=True) if parts else pd.DataFrame(columns=list(ODOMETER_COLUMNS))
    return rows, facts


def paper_outage_table(rows: pd.DataFrame, windows: dict) -> pd.DataFrame:
    """The rows of :data:`PAPER_FOLD` per dataset, outage (numbered as the profile's ``outage_windows``: ``windows``,
    ``{dataset: [(start, duration), ...]}``), method and sigma: the median over seeds of the max horizontal error
    and speed RMSE, and the share of the seeds' epochs within 2 sigma (:data:`PAPER_COLUMNS`)."""
    if rows.empty:
        return pd.DataFrame(columns=list(PAPER_COLUMNS))
    number = {(ds, float(s)): k for ds, w in windows.items() for k, (s, _) in enumerate(w, start=1)}
    r = rows.assign(outage=[number[(ds, float(s))] for ds, s in zip(rows["dataset"], rows["start_s"])])
    order = {m: i for i, m in enumerate(ODOMETER_METHODS)}
    out = (r.groupby(["dataset", "outage", "start_s", "duration_s", "method", "sigma_mps"], dropna=False, sort=False)
           .agg(max_h_m=("max_h_m", "median"), speed_rmse_mps=("speed_rmse_mps", "median"),
                coverage_2sigma=("coverage_2sigma", "mean"), runs=("max_h_m", "size")).reset_index())
    out = out.assign(rank=out["method"].map(order)).sort_values(["dataset", "outage", "rank", "sigma_mps"],
                                                                kind="stable")
    return out.drop(columns="rank").reset_index(drop=True)[list(PAPER_COLUMNS)]


def network_table(rows: pd.DataFrame, facts: dict) -> pd.DataFrame:
    """Every network odometer of the sweep's folds (dataset, method, fold, seed): its learning rate and epochs, its
    speed RMSE on the validation block its std was calibrated on, the calibration factor and the integrated
    autocorrelation of its calibrated validation errors (:func:`bgfn.learning.odometry.error_correlation`), and in
    its own fold's outages at the sweep's longest duration its speed RMSE (the RMS over the starts: each holds the
    same epochs) and the share of epochs within its +-2 sigma (:data:`NETWORK_COLUMNS`). Where the outage RMSE is
    far above the validation RMSE, the validation block did not represent the outages, and the calibrated std is
    too small there."""
    out = []
    for name, f in facts.items():
        for net in (f.get("networks") or {}).values():
            if net["fold"] == PAPER_FOLD:
                continue
            r = rows[(rows["dataset"] == name) & (rows["method"] == net["method"]) & (rows["fold"] == net["fold"])
                     & (rows["seed"] == net["seed"])]
            r = r[r["duration_s"] == r["duration_s"].max()] if len(r) else r
            out.append({"dataset": name, **{k: net[k] for k in ("method", "fold", "seed", "lr", "epochs")},
                        "val_rmse_mps": net["val_rmse_mps"], "calibration": net["calibration"],
                        "correlation": net.get("correlation", np.nan),
                        "outage_speed_rmse_mps": float(np.sqrt(np.mean(r["speed_rmse_mps"] ** 2))) if len(r)
                        else np.nan,
                        "outage_coverage_2sigma": float(r["coverage_2sigma"].mean()) if len(r) else np.nan})
    return pd.DataFrame(out, columns=list(NETWORK_COLUMNS))


def odometer_summary(rows: pd.DataFrame) -> pd.DataFrame:
    """Median max horizontal error (m) per dataset, duration and method (the oracle per sigma), with the median
    speed RMSE, the 2-sigma coverage, the median per-start ratio to ``INS+NHC`` and the two-sided Wilcoxon
    signed-rank p-value of the per-start differences to it (``p_vs_nhc``; seeds' median per start), and for the
    learned odometers that p Holm-adjusted over them (``p_vs_nhc_holm``, :func:`holm_vs_nhc`).

    ``coverage_2sigma`` is the share of *all* the outages' epochs within +-2 sigma: the mean of the outages' shares,
    each outage of one duration holding the same epochs. (A median of the shares says how a typical outage went:
    above half of the outages inside 2 sigma throughout it reads 100 %, though some epochs were far outside.)"""
    if rows.empty:
        return pd.DataFrame(columns=list(SUMMARY_COLUMNS))
    base = rows[rows["method"] == nhc_label("INS")].groupby(["dataset", "duration_s", "start_s"])["max_h_m"].first()
    r = rows.join(base.rename("nhc_m"), on=["dataset", "duration_s", "start_s"])
    r["ratio_to_nhc"] = r["max_h_m"] / r["nhc_m"]
    key = ["dataset", "duration_s", "method", "sigma_mps"]
    out = r.groupby(key, dropna=False, sort=False).agg(
        max_h_m=("max_h_m", "median"), ratio_to_nhc=("ratio_to_nhc", "median"),
        speed_rmse_mps=("speed_rmse_mps", "median"), coverage_2sigma=("coverage_2sigma", "mean"),
        runs=("max_h_m", "size")).reset_index()
    # Wilcoxon signed-rank of the per-start difference to INS+NHC (one value per start: the seeds' median)
    per_start = r.groupby(key + ["start_s"], dropna=False, sort=False)[["max_h_m", "nhc_m"]].median()
    p = per_start.groupby(level=key, dropna=False, sort=False).apply(
        lambda g: wilcoxon_p(g["max_h_m"] - g["nhc_m"])).rename("p_vs_nhc").reset_index()
    out = out.merge(p, on=key, how="left")                  # pandas matches the NaN sigma of non-oracle rows
    out["p_vs_nhc_holm"] = holm_vs_nhc(out)
    return out.sort_values(["dataset", "duration_s"], kind="stable").reset_index(drop=True)[list(SUMMARY_COLUMNS)]


def holm_vs_nhc(summary: pd.DataFrame) -> pd.Series:
    """``p_vs_nhc`` of the learned odometers (:data:`LEARNED_ODOMETERS`) Holm-adjusted over those of one dataset and
    duration with a p-value (:func:`bgfn.stats.holm_adjust`): a page that names the best of them names the smallest
    of several p-values, small by chance alone. NaN for the other rows (INS+NHC, the held speed, the oracles)."""
    out = np.full(len(summary), np.nan)
    learned = summary["method"].isin(LEARNED_ODOMETERS).to_numpy()
    keys = summary[["dataset", "duration_s"]].reset_index(drop=True)           # by position: any index will do
    p = summary["p_vs_nhc"].to_numpy(dtype=float)
    for rows in keys[learned].groupby(["dataset", "duration_s"], sort=False).indices.values():
        at = np.flatnonzero(learned)[rows]
        out[at] = holm_adjust(p[at])
    return pd.Series(out, index=summary.index, name="p_vs_nhc_holm")

"""The learned odometer trained on some drives of a fleet and tested on drives it never saw (beyond the paper).

Leave-one-drive-out (``fleet.protocol: leave_one_out``): every drive is tested once, trained on all the others;
``named``: the ``fleet.train`` drives train, each of ``fleet.test`` is tested. The learned odometers learn from
every labelled window of the training drives (their GPS-available time: a training drive holds no outage of the
test), pooled (:func:`pooled_speed_data`), with the within-drive study's validation blocks and ridge
(:class:`bgfn.learning.odometry.RidgeOdometer`, ``evaluate.odometer``); the networks (``fleet.networks``) through
:func:`bgfn.studies.odometer.bars.network_odometers`. Each test drive runs the odometer table's rows in its sweep
windows (:func:`bgfn.studies.outage_sweep.sweep.profile_sweep_plan`, every start one fold: no start was trained
on), with the same runs and row format (:mod:`bgfn.studies.odometer.bars`), and its honest speed series gives the
offset per outage (:func:`bgfn.studies.odometer.errors.error_parts_table`).
"""

from __future__ import annotations

import itertools

import numpy as np
import pandas as pd

from bgfn.config import odometer_inputs
from bgfn.errors import DataError
from bgfn.evaluate.hybrid import navigation_context, window_metrics
from bgfn.learning import odometry as lo
from bgfn.learning.split import overlaps
from bgfn.nav import odometer as no
from bgfn.paper import nhc_label
from bgfn.parallel import Runner
from bgfn.studies.fleet.drives import PreparedDrive
from bgfn.studies.odometer import bars
from bgfn.studies.odometer.errors import error_parts_table
from bgfn.studies.outage_sweep.sweep import profile_sweep_plan

#: Seconds between two drives' clocks in pooled windows: no window of one drive pairs with another's
#: (validation purge, error autocorrelation).
DRIVE_TIME_SHIFT_S = 1.0e7
#: The learned odometers of the table (the family of the Holm adjustment).
LEARNED = (bars.RIDGE, *bars.NETWORK_ODOMETERS, *bars.ENSEMBLE_ODOMETERS)


def fleet_splits(names: list[str], fleet: dict) -> list[tuple[str, list[str]]]:
    """``[(test drive, [training drives]), ...]`` of the protocol (module docstring)."""
    if fleet["protocol"] == "leave_one_out":
        return [(n, [m for m in names if m != n]) for n in names]
    train, test = list(fleet["train"]), list(fleet["test"])
    for key, chosen in (("train", train), ("test", test)):
        unknown = [n for n in chosen if n not in names]
        if unknown or not chosen:
            raise DataError("fleet", key, f"names among the fleet's drives ({', '.join(names)})",
                            ", ".join(unknown) or "none")
    if set(train) & set(test):
        raise DataError("fleet", "train/test", "disjoint lists", ", ".join(sorted(set(train) & set(test))))
    return [(n, train) for n in test]


def learning_params(cfg: dict) -> dict:
    """What the fleet's learned odometers take from a profile: ``evaluate.odometer``'s window, ridge, validation and
    correlation keys, ``train.val_fraction`` and the aid rate ``nav.nhc.rate_hz``."""
    oc = cfg["evaluate"]["odometer"]
    return {"window_s": float(oc["window_s"]), "ridge_alpha": float(oc["ridge_alpha"]),
            "max_lag_s": float(oc["correlation_max_lag_s"]), "correlation": bool(oc["correlation"]),
            "val_fraction": float(cfg["train"]["val_fraction"]), "val_blocks": int(oc["val_blocks"]),
            "calibration_blocks": bool(oc["calibration_blocks"]),
            "aid_rate_hz": float(((cfg.get("nav") or {}).get("nhc") or {}).get("rate_hz") or 1.0)}


def drive_windows(p: PreparedDrive, epochs, window_s: float, labelled: bool = True) -> lo.SpeedWindows:
    """The prepared IMU's windows of ``window_s`` ending at ``epochs`` (s), with the speed label (or NaN)."""
    window = int(round(window_s * p.rate_hz))
    epochs = np.asarray(epochs, dtype=float)
    return lo.speed_windows(p.imu, epochs, window, p.label_at(epochs) if labelled else None)


def aid_epochs(t0: float, t1: float, rate_hz: float) -> np.ndarray:
    """The aid grid ``k / rate_hz`` inside ``[t0, t1)``, s."""
    return np.arange(np.ceil(t0 * rate_hz) / rate_hz, t1, 1.0 / rate_hz)


def concat_windows(parts: list[lo.SpeedWindows]) -> lo.SpeedWindows:
    """Windows of several drives as one set, drive ``i``'s times shifted by ``i`` :data:`DRIVE_TIME_SHIFT_S`."""
    shift = [np.full(len(w), i * DRIVE_TIME_SHIFT_S) for i, w in enumerate(parts)]
    return lo.SpeedWindows(np.concatenate([w.x for w in parts]), np.concatenate([w.speed for w in parts]),
                           np.concatenate([w.t_end for w in parts]) + np.concatenate(shift),
                           np.concatenate([w.t_start for w in parts]) + np.concatenate(shift))


def pooled_speed_data(train: list[PreparedDrive], params: dict) -> lo.SpeedData:
    """Every labelled window of the training drives (NaN labels left out) pooled, split into training, validation
    and calibration blocks as within a drive (:func:`bgfn.learning.odometry.build_speed_data`, no outage: none of
    the test drive's time is in them), ``val_blocks`` per training drive."""
    parts = []
    for p in train:
        epochs = aid_epochs(p.label_time[0], p.label_time[-1], params["aid_rate_hz"])
        w = drive_windows(p, epochs, params["window_s"])
        parts.append(w.subset(np.isfinite(w.speed)))
    return lo.build_speed_data(concat_windows(parts), (), 0.0, params["val_fraction"],
                               params["val_blocks"] * len(train), params["calibration_blocks"])


def fit_ridge(data: lo.SpeedData, rate_hz: float, params: dict) -> lo.RidgeOdometer:
    """``RIDGE-ODO`` on pooled training data (its std and correlation from the calibration windows)."""
    return lo.RidgeOdometer.fit(data.train, data.calibration_windows, rate_hz, params["ridge_alpha"],
                                params["max_lag_s"])


def ridge_track(model: lo.RidgeOdometer, windows: lo.SpeedWindows, params: dict) -> no.SpeedTrack:
    """The ridge's track over a test drive's windows (fused with its correlation when ``correlation``)."""
    return model.track(windows).correlated(model.correlation if params["correlation"] else 1.0)


def speed_series(t, truth, outages, tracks: dict) -> dict:
    """The honest speed series of :func:`bgfn.studies.odometer.errors.error_parts_table`: each track's speed and std
    inside the ``outages`` ``[(start, duration), ...]``, NaN elsewhere; and ``fused_std``: the std the filter fuses
    each speed with (:meth:`bgfn.nav.odometer.SpeedTrack.fused_std`), which the window means are judged by."""
    t, truth = np.asarray(t, dtype=float), np.asarray(truth, dtype=float)
    inside = overlaps(t, t, np.array([[s, s + d] for s, d in outages], dtype=float).reshape(-1, 2))
    out, fused = {}, {}
    for label, track in tracks.items():
        speed, std = np.full(t.size, np.nan), np.full(t.size, np.nan)
        speed[inside], std[inside] = track.at(t[inside])
        out[label], fused[label] = (speed, std), track.fused_std(std)
    return {"time": t, "truth": truth, "outages": list(outages), "tracks": out, "fused_std": fused}


def held_track(epochs, starts, duration: float, speed_at_start, std: float) -> no.SpeedTrack:
    """The speed at each outage start held over that outage (``INS+NHC+HOLD`` in one track), std ``std``; NaN
    outside the outages."""
    epochs = np.asarray(epochs, dtype=float)
    v = np.full(epochs.size, np.nan)
    for s in sorted(starts):
        v[(epochs > s) & (epochs <= s + duration + 1e-6)] = float(speed_at_start(s))
    return no.SpeedTrack(epochs, v, np.full(epochs.size, float(std)))


class TestDrive:
    """A test drive ready for the odometer rows: its GPS-aided run with a state at every sweep start
    (:func:`bgfn.evaluate.hybrid.navigation_context`), its aid epochs, its prepared windows there, the reference's
    speed and the GPS-aided solution's forward speed (the held speed's)."""

    def __init__(self, cfg: dict, p: PreparedDrive, params: dict):
        sw = cfg["evaluate"]["sweep"]
        self.prepared, self.name = p, p.name
        self.plan = profile_sweep_plan(cfg, p.drive, sw)
        self.starts = [float(s) for s in self.plan["start_s"]]
        self.durations = [float(d) for d in sw["durations_s"]]
        self.dmax = max(self.durations)
        self.ctx = navigation_context(p.drive, cfg.get("nav"), self.starts)
        self.con = self.ctx.constraints
        self.rate = float(self.con.config.nhc_rate_hz)
        traj = self.ctx.full.trajectory
        self.tt = traj["time"].to_numpy(float)
        self.solution_speed = lo.forward_speed(traj, self.con.mounting_at(self.tt))
        self.windows = drive_windows(p, aid_epochs(self.tt[0], self.tt[-1], self.rate), params["window_s"], False)
        self.truth = bars.reference_speed(p.drive, self.windows.t_end)
        self.outages = [(s, self.dmax) for s in self.starts]

    def start_speed(self, s: float) -> float:
        """The GPS-aided solution's forward speed at ``s`` (what ``INS+NHC+HOLD`` holds)."""
        return float(np.interp(s, self.tt, self.solution_speed))


def test_runs(test: TestDrive, learned: dict, oc: dict) -> tuple[list, dict]:
    """The odometer table's runs in a test drive's outages (:class:`bgfn.studies.odometer.bars.OdometerRun`, one
    fold, 0): INS+NHC, the held speed per start, the oracle grid, and each learned track of ``learned``
    (``{(label, seed): SpeedTrack}``); and the tracks by run label."""
    con, gate, fw, name = test.con, oc["gate_probability"], test.outages, test.name
    runs, tracks = [bars.OdometerRun(f"{name} {nhc_label('INS')}", fw, con, nhc_label("INS"), np.nan, 0, 0)], {}
    for (label, seed), track in learned.items():
        runs.append(bars.OdometerRun(f"{name} {label} seed {seed}", fw, no.Odometer(con, track, gate), label,
                                     np.nan, int(seed), 0))
        tracks[runs[-1].label] = track
    epochs = test.windows.t_end
    for s, d in fw:
        held = no.SpeedTrack(epochs, np.full(epochs.size, test.start_speed(s)),
                             np.full(epochs.size, float(oc["hold_std_mps"])))
        runs.append(bars.OdometerRun(f"{name} {s:.0f} s {bars.HOLD}", [(s, d)], no.Odometer(con, held, gate),
                                     bars.HOLD, np.nan, 0, 0))
        tracks[runs[-1].label] = held
    walks = [(bars.ORACLE, 0.0)] + ([(bars.ORACLE_WALK, float(oc["walk_mps_per_sqrt_s"]))]
                                    if oc["walk_mps_per_sqrt_s"] > 0 else [])
    for (method, walk), sigma, seed in ((w, s, e) for w in walks for s in oc["sigmas_mps"] for e in oc["seeds"]):
        track = bars.oracle_track(epochs, test.truth, float(sigma), walk, int(seed), test.rate)
        runs.append(bars.OdometerRun(f"{name} {method} {sigma:g} m/s seed {seed}", fw, no.Odometer(con, track, gate),
                                     method, float(sigma), int(seed), 0))
        tracks[runs[-1].label] = track
    return runs, tracks


def run_rows(test: TestDrive, runs: list, tracks: dict, pseudo: dict, runner: Runner | None,
             durations=None) -> pd.DataFrame:
    """The runs in the test drive's outages, scored as the odometer table's rows
    (:data:`bgfn.studies.odometer.bars.ODOMETER_COLUMNS`) at each of ``durations`` (the sweep's)."""
    results = (runner or Runner()).map(bars.odometer_run, [(test.ctx, r, pseudo) for r in runs],
                                       labels=[r.label for r in runs], desc=f"fleet rows {test.name}")
    rows = []
    for run, outs in zip(runs, results):
        track = tracks.get(run.label)
        for r in outs:
            for du in (durations or test.durations):
                m = window_metrics(r.errors, r.start, float(du))
                rows.append({"dataset": test.name, "start_s": r.start, "duration_s": float(du), "method": run.method,
                             "sigma_mps": run.sigma_mps, "seed": run.seed, "fold": run.fold,
                             **{c: m[c] for c in ("max_h_m", "rmse_h_m", "final_h_m")},
                             **no.speed_errors(track, test.windows.t_end, test.truth, r.start, float(du))})
    return pd.DataFrame(rows, columns=list(bars.ODOMETER_COLUMNS))


def network_inputs(cfg: dict) -> dict[str, str]:
    """What each network of ``evaluate.odometer.methods`` reads: ``fleet.inputs``' choice, else
    ``evaluate.odometer.inputs`` (the raw IMU window or its band frames,
    :func:`bgfn.learning.odometry.network_inputs`)."""
    oc, chosen = cfg["evaluate"]["odometer"], (cfg.get("fleet") or {}).get("inputs") or {}
    return {m: chosen.get(m, odometer_inputs(oc, m)) for m in oc["methods"]}


def with_calibration_windows(test_windows: lo.SpeedWindows, data: lo.SpeedData) -> lo.SpeedWindows:
    """The test drive's windows, their times shifted back by :data:`DRIVE_TIME_SHIFT_S` (before every training
    drive's clock), followed by the training data's calibration windows: one track over both lets an ensemble
    calibrate on those (:func:`bgfn.studies.odometer.bars.ensemble_tracks`), as it does within a drive, whose track
    covers its validation blocks."""
    cal = data.calibration_windows
    cal = cal.subset(np.argsort(cal.t_end, kind="stable"))
    return lo.SpeedWindows(np.concatenate([test_windows.x, cal.x]), np.concatenate([test_windows.speed, cal.speed]),
                           np.concatenate([test_windows.t_end - DRIVE_TIME_SHIFT_S, cal.t_end]),
                           np.concatenate([test_windows.t_start - DRIVE_TIME_SHIFT_S, cal.t_start]))


def network_tracks(cfg: dict, profile: str, key: str, data: lo.SpeedData, test, runner: Runner | None) -> dict:
    """The odometer networks (``evaluate.odometer.methods``, their seeds and ensembles) trained on the pooled
    ``data`` as one fold and run over the test drive's windows (:func:`bgfn.studies.odometer.bars.network_odometers`;
    checkpoints under the model key ``key``; the ensembles calibrated on the training data's calibration windows,
    :func:`with_calibration_windows`), each on its inputs (:func:`network_inputs`), all with one budget:
    ``{(label, seed): SpeedTrack}`` on the test drive's clock."""
    ecfg, rate = cfg["evaluate"], test.prepared.rate_hz
    groups: dict[str, list[str]] = {}
    for m, inputs in network_inputs(cfg).items():
        groups.setdefault(inputs, []).append(m)
    both, n = with_calibration_windows(test.windows, data), len(test.windows)
    out = {}
    for inputs, methods in groups.items():
        oc = {**ecfg["odometer"], "network_datasets": None, "methods": methods, "inputs": inputs}
        nets = bars.network_odometers(cfg, profile, key, {**ecfg, "odometer": oc},
                                      {0: lo.with_inputs(data, inputs, rate)}, lo.network_inputs(both, inputs, rate),
                                      runner)
        out.update({(label, seed): no.SpeedTrack(test.windows.t_end, track.speed[:n], track.std[:n],
                                                 track.correlation)
                    for (label, _, seed), (track, _) in nets.items()})
    return out


def training_minutes(data: lo.SpeedData, aid_rate_hz: float) -> float:
    """Minutes of labelled windows the odometer trained on (its training windows at the aid rate)."""
    return len(data.train) / aid_rate_hz / 60.0


def curve_combinations(train: list[str], fleet: dict) -> list[tuple[str, ...]]:
    """The training sets of the learning curve: for 1 .. len(train) drives every combination, or
    ``curve_max_combinations`` of them drawn with ``curve_seed`` where there are more (the full set always)."""
    rng = np.random.default_rng(int(fleet["curve_seed"]))
    out = []
    for k in range(1, len(train) + 1):
        combos = list(itertools.combinations(train, k))
        if len(combos) > int(fleet["curve_max_combinations"]):
            pick = rng.choice(len(combos), int(fleet["curve_max_combinations"]), replace=False)
            combos = [combos[i] for i in sorted(pick)]
        out += combos
    return out


def curve_tracks(cfg: dict, profile: str, key: str, test, by_name: dict, train: list[str], params: dict,
                 runner: Runner | None, full: dict | None = None) -> list[tuple[tuple[str, ...], lo.SpeedData, dict]]:
    """Per training set of :func:`curve_combinations`: its drives, its pooled data and the learned tracks over the
    test drive's windows (``test.windows``, ``test.prepared``), ``{(label, seed): SpeedTrack}``: ``RIDGE-ODO``, and
    with ``fleet.networks`` and ``fleet.curve_networks`` the networks (:func:`network_tracks`, checkpoints under
    ``<key>-curve<i>``); ``full``: the tracks already trained on all of ``train`` (the split's), taken as they are
    for that set."""
    fleet, out = cfg["fleet"], []
    networks = bool(fleet["networks"] and fleet["curve_networks"])
    for i, combo in enumerate(curve_combinations(train, fleet)):
        data = pooled_speed_data([by_name[n] for n in combo], params)
        if full is not None and set(combo) == set(train):
            out.append((combo, data, {k: v for k, v in full.items() if networks or k[0] == bars.RIDGE}))
            continue
        learned = {(bars.RIDGE, 0): ridge_track(fit_ridge(data, test.prepared.rate_hz, params), test.windows, params)}
        if networks:
            learned.update(network_tracks(cfg, profile, f"{key}-curve{i + 1}", data, test, runner))
        out.append((combo, data, learned))
    return out


def curve_speed_rows(test, sets: list, duration: float, aid_rate_hz: float) -> list[dict]:
    """Per training set of :func:`curve_tracks` and learned track: the test drive, the method and seed, the training
    drives and minutes, the offset per outage and the speed RMSE in the test's outages (``test.outages``) over
    their first ``duration`` s (:func:`bgfn.studies.odometer.errors.error_parts_table`)."""
    rows = []
    for combo, data, learned in sets:
        for (label, seed), track in learned.items():
            series = speed_series(test.windows.t_end, test.truth, test.outages, {label: track})
            parts = error_parts_table(test.name, series, [duration])
            rows.append({"test_drive": test.name, "method": label, "seed": int(seed), "n_train": len(combo),
                         "train_drives": "; ".join(combo), "train_min": training_minutes(data, aid_rate_hz),
                         "offset_rms_mps": float(parts["offset_rms_mps"].iloc[0]) if len(parts) else np.nan,
                         "speed_rmse_mps": float(parts["speed_rmse_mps"].iloc[0]) if len(parts) else np.nan})
    return rows


def curve_rows(cfg: dict, profile: str, key: str, test: TestDrive, by_name: dict, train: list[str], params: dict,
               runner: Runner | None, full: dict | None = None) -> pd.DataFrame:
    """The learning curve on one test drive (:data:`CURVE_COLUMNS`): per training set and learned odometer
    (:func:`curve_tracks`), its training minutes, the offset per outage and the speed RMSE in the test's outages over
    their first ``fleet.curve_duration_s`` (:func:`curve_speed_rows`), and the median max horizontal error there."""
    d, oc = float(cfg["fleet"]["curve_duration_s"]), cfg["evaluate"]["odometer"]
    sets = curve_tracks(cfg, profile, key, test, by_name, train, params, runner, full)
    facts = curve_speed_rows(test, sets, d, params["aid_rate_hz"])
    runs, tracks = [], {}
    for j, (label, seed, track) in enumerate((lb, sd, tk) for _, _, learned in sets
                                             for (lb, sd), tk in learned.items()):
        runs.append(bars.OdometerRun(f"{test.name} curve {j} {label} seed {seed}", test.outages,
                                     no.Odometer(test.con, track, oc["gate_probability"]), label, np.nan, int(seed), j))
        tracks[runs[-1].label] = track
    rows = run_rows(test, runs, tracks, cfg["evaluate"]["pseudo_gps"], runner, [d])
    med = rows.groupby("fold")["max_h_m"].median()
    for j, f in enumerate(facts):
        f["median_max_h_m"] = float(med.get(j, np.nan))
    return pd.DataFrame(facts, columns=list(CURVE_COLUMNS))


#: Columns of ``tables/fleet_curve.csv`` (:func:`curve_rows`).
CURVE_COLUMNS: tuple[str, ...] = ("test_drive", "method", "seed", "n_train", "train_drives", "train_min",
                                  "offset_rms_mps", "speed_rmse_mps", "median_max_h_m")

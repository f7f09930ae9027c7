"""What a profile's run will do on its drives, decided once before notebook 01: the run plan.

:func:`make_plan` takes the loaded profile and its drives and asks, with the notebooks' own functions, what every
notebook needs of them: the evaluation outages (notebooks 02-04, 08), training and validation windows outside them
(03), room for the outage sweep's starts (06; the INS drift and NEES scan of 08 run from the same starts) and its
folds' training, the learned odometers' windows (07). A need that a drive cannot meet is

- *scaled* to the drive where the profile leaves it to a rule (an own log of 60 s gets outages, warm-ups, gaps,
  margins and sweep durations that fit it: every time of the outage rule and ``train.margin_s`` by one factor), or
- *switched off* with its reason (a study whose drives cannot hold it, with all its parts: the sweep takes the
  odometer bars that ride on its starts, the INS drift and the NEES scan with it), or
- refused: one :class:`~bgfn.errors.DataError` naming the key and what the drive holds (the paper's own steps,
  02-05, are never switched off).

The plan (:class:`RunPlan`) is written to ``results/<profile>/run_plan.json`` by the profile check
(``python -m bgfn.profile_schema``); :func:`bgfn.profile_schema.load_profile` lays its ``overrides`` over the
profile for every notebook, notebook 01 prints it (:mod:`bgfn.report.run_plan` words it) and notebook 08 asks it
whether its parts run (:func:`part_runs`). Nothing is re-derived later, so the check and the notebooks agree.
"""

from __future__ import annotations

import hashlib
import json
import warnings
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from bgfn.config import DEFAULT_DATASET_KEY, odometer_datasets, results_dir, set_keys
from bgfn.errors import DataError
from bgfn.evaluate import evaluate_config
from bgfn.learning import learning_options
from bgfn.learning import odometry as lo
from bgfn.learning.split import split_windows
from bgfn.nav.baseline import filter_start
from bgfn.nav.constraints import DEFAULT_PLATFORM
from bgfn.nav.outages import is_rule, outage_entry, outage_windows, picked_outages, snapped_outages
from bgfn.settings_check import complete
from bgfn.studies.outage_sweep.sweep import profile_sweep_plan, sweep_train_config

#: The plan's file under ``results/<profile>/``.
PLAN_FILE = "run_plan.json"
#: The factors the times of an outage rule (and ``train.margin_s``) are scaled by, in turn, until a drive holds them.
SCALE_FACTORS = (1.0, 0.75, 0.5, 0.35, 0.25, 0.2, 0.15)
#: The shortest outage a scaled rule may ask, s: shorter, the log is refused (five pseudo-GPS fixes at 1 Hz).
MIN_OUTAGE_S = 5.0
#: The fewest training and validation windows (notebook 03's split) a drive must give for the plan to pass.
MIN_TRAIN_WINDOWS, MIN_VAL_WINDOWS = 8, 2
#: Parts of a notebook that no key switches on or off by itself: the plan says whether they run.
PARTS = ("ins_drift", "nees_scan")


@dataclass
class RunPlan:
    """The run plan of one profile on its drives (module docstring).

    Attributes
    ----------
    profile : str
    fingerprint : str
        :func:`fingerprint` of the profile the plan was made for (a plan for another version is refused).
    drives : dict
        Per drive: ``t_first``/``t_last`` (s: the filter's start, the last IMU epoch), ``span_s``, ``outages``
        (``asked`` and ``run``: (start, duration) s before and after :func:`bgfn.nav.outages.snap_windows`),
        ``rule`` (what the rule made of the drive, :attr:`bgfn.nav.outage_rules.PickedOutages.thresholds`, or None),
        ``train_windows``/``val_windows`` (notebook 03's split).
    overrides : dict
        ``{"dotted.key": value}`` laid over the profile (the scaled and switched-off keys).
    scaled : list of dict
        ``key``, ``asked``, ``planned``, ``reason`` (a code :mod:`bgfn.report.run_plan` words) and its facts.
    off : list of dict
        ``part`` (a key or one of :data:`PARTS`), ``reason`` and its facts.
    """

    profile: str
    fingerprint: str
    drives: dict = field(default_factory=dict)
    overrides: dict = field(default_factory=dict)
    scaled: list = field(default_factory=list)
    off: list = field(default_factory=list)

    def runs(self, part: str) -> bool:
        """Whether ``part`` (one of :data:`PARTS`) runs."""
        return not any(o["part"] == part for o in self.off)

    @property
    def changes(self) -> bool:
        """Whether the plan changes anything of the profile."""
        return bool(self.overrides or self.off)


def fingerprint(cfg: dict) -> str:
    """A short hash of a loaded profile (every key, defaults filled): what a plan was made for."""
    text = json.dumps(cfg, sort_keys=True, default=str)
    return hashlib.sha256(text.encode("utf-8")).hexdigest()[:16]


def plan_path(profile: str) -> Path:
    """``results/<profile>/run_plan.json``."""
    return results_dir(profile, create=False) / PLAN_FILE


def read_plan(profile: str) -> RunPlan | None:
    """The plan the profile check wrote for ``profile``, or None when it wrote none (a notebook run alone)."""
    path = plan_path(profile)
    if not path.is_file():
        return None
    return RunPlan(**json.loads(path.read_text(encoding="utf-8")))


def plan_json(plan: RunPlan) -> str:
    """The plan as the JSON file holds it."""
    return json.dumps(asdict(plan), indent=1, default=float) + "\n"


def part_runs(profile: str, part: str) -> bool:
    """Whether a part of :data:`PARTS` runs under ``profile``'s plan (no plan: it runs)."""
    plan = read_plan(profile)
    return True if plan is None else plan.runs(part)


# ------------------------------------------------------------------------------------------------ the needs
def _split_counts(cfg: dict, drive, windows, t_first: float) -> tuple[int, int]:
    """(training, validation) windows of notebook 03's honest split (:func:`bgfn.learning.split_windows`) on the
    drive's GNSS increments after the filter's start; (0, 0) when the split refuses."""
    opt = learning_options(cfg["train"])
    t = drive.imu["time"].to_numpy(float)
    rate = 1.0 / float(np.median(np.diff(t)))
    span = int(opt["window"]) / rate
    fixes = (drive.gnss if hasattr(drive, "gnss") else drive.reference)["time"].to_numpy(float)   # the increments' ends
    fixes = fixes[::max(1, int(opt["epoch_stride"]))]
    hi = fixes[(fixes >= t_first + span) & (fixes <= t[-1])]
    ws = _Span(hi - span, hi)
    try:
        tr, va, _ = split_windows(ws, windows, float(opt["margin_s"]), float(opt["val_fraction"]),
                                  opt["val_position"], "honest")
    except DataError:
        return 0, 0
    return int(len(tr)), int(len(va))


class _Span:
    """What :func:`bgfn.learning.split_windows` reads of a window set: its spans, its length."""

    def __init__(self, lo_: np.ndarray, hi_: np.ndarray):
        self.span = (lo_, hi_)

    def __len__(self) -> int:
        return int(self.span[0].size)


def _outages_and_training(cfg: dict, drives: dict, starts: dict) -> dict:
    """Per drive of notebooks 02-04: the outages (asked, run), the rule's facts and the split's counts; raises
    :class:`DataError` (the drive's outages do not fit, or the split is too small)."""
    out = {}
    for name, drive in drives.items():
        snapped = snapped_outages(cfg, drive, name)
        run = [w.window for w in snapped]
        t0, t1 = starts[name], float(drive.imu["time"].iloc[-1])
        early = [w for w in run if w[0] < t0 - 1e-6]
        if early:
            raise DataError(name, "outage_windows", f"outages after the filter's start {t0:.2f} s", str(early[0]))
        n_train, n_val = _split_counts(cfg, drive, run, t0)
        if n_train < MIN_TRAIN_WINDOWS or n_val < MIN_VAL_WINDOWS:
            raise DataError(name, "train.margin_s", f"at least {MIN_TRAIN_WINDOWS} training and {MIN_VAL_WINDOWS} "
                            "validation windows outside the outages +- train.margin_s",
                            f"{n_train} and {n_val}")
        picked = picked_outages(cfg, drive, name)
        out[drive.name] = {"t_first": t0, "t_last": t1, "span_s": t1 - t0,
                     "outages": [{"asked": list(w.asked), "run": list(w.window)} for w in snapped],
                     "rule": None if picked is None else {**picked.thresholds, "kinds": picked.kinds},
                     "train_windows": n_train, "val_windows": n_val}
    return out


def _rule_keys(cfg: dict, names) -> list[str]:
    """The ``outage_windows`` keys whose entry is a rule for some of ``names`` (``default`` or a drive's)."""
    spec = cfg.get("outage_windows")
    keys = []
    for name in names:
        entry = outage_entry(cfg, name)
        if is_rule(entry) and isinstance(spec, dict):
            key = name if name in spec else DEFAULT_DATASET_KEY
            if key not in keys:
                keys.append(key)
    return keys


def _scaled_outages(cfg: dict, drives: dict, starts: dict, typed) -> tuple[dict, dict, list]:
    """The outages and training of every drive, the rule's times and ``train.margin_s`` scaled by the first of
    :data:`SCALE_FACTORS` that every drive holds (a key the profile's own file sets is kept as typed): (drive facts,
    overrides, scaled entries)."""
    keys = _rule_keys(cfg, drives)
    first_error = None
    for f in SCALE_FACTORS if keys else (1.0,):
        over, scaled = {}, []
        for key in keys:
            rule = cfg["outage_windows"][key]
            step = float(rule["step_s"])
            for k in ("duration_s", "warmup_s", "gap_s", "min_training_s"):
                if typed(f"outage_windows.{key}.{k}"):
                    continue
                asked = float(rule[k])
                value = asked * f if k != "duration_s" else max(step, np.floor(asked * f / step) * step)
                if k == "duration_s" and f < 1.0 and value < MIN_OUTAGE_S:
                    value = None
                if value is not None and value != asked:
                    over[f"outage_windows.{key}.{k}"] = float(value)
                    scaled.append({"key": f"outage_windows.{key}.{k}", "asked": asked, "planned": float(value)})
        margin = float(cfg["train"]["margin_s"])
        if f < 1.0 and margin * f != margin and not typed("train.margin_s"):
            over["train.margin_s"] = margin * f
            scaled.append({"key": "train.margin_s", "asked": margin, "planned": margin * f})
        if f < 1.0 and not scaled:
            break                                           # nothing left to scale (typed, or below MIN_OUTAGE_S)
        trial = complete(set_keys(cfg, over))
        try:
            facts = _outages_and_training(trial, drives, starts)
        except DataError as exc:
            first_error = first_error or exc
            if not keys:
                break
            continue
        spans = {n: round(d["span_s"], 1) for n, d in facts.items()}   # keyed by the drives' own names
        for s in scaled:
            s.update(reason="short_log", factor=f, spans_s=spans)
        return facts, over, scaled
    span = {drives[n].name: float(drives[n].imu["time"].iloc[-1]) - starts[n] for n in drives}
    exc = first_error
    held = [f"outage_windows.{k}.{p}" for k in keys for p in ("duration_s", "warmup_s", "gap_s", "min_training_s")
            if typed(f"outage_windows.{k}.{p}")] + (["train.margin_s"] if typed("train.margin_s") else [])
    key = (held[0] if held else f"outage_windows.{keys[0]}.duration_s") if keys else exc.field
    holds = ", ".join(f"{n}: {s:.1f} s after the filter's start" for n, s in span.items())
    advice = ((f"; with {', '.join(held)} as typed, no scaling of the other times fits it" if held else
               f"; no outages of the rule of {MIN_OUTAGE_S:g} s or more fit it") if keys else
              "; shorten the listed outages or train.margin_s, or record a longer log")
    raise DataError(", ".join(span), key, f"{exc.expected}: the log holds {holds}{advice}", exc.found)


def _sweep_fits(cfg: dict, drive, sw: dict) -> str | None:
    """None when the sweep's starts fit ``drive`` and every fold leaves its networks training windows; else the
    reason's code."""
    try:
        plan = profile_sweep_plan(cfg, drive, sw)
    except DataError:
        return "no_room"
    dmax = max(float(d) for d in sw["durations_s"])
    t0 = filter_start(drive, cfg.get("nav"))
    fold_cfg = {**cfg, "train": sweep_train_config(cfg["train"], sw)}
    for k in sorted(plan["fold"].unique()):
        windows = [(float(s), dmax) for s in plan.loc[plan["fold"] == k, "start_s"]]
        n_train, n_val = _split_counts(fold_cfg, drive, windows, t0)
        if n_train < MIN_TRAIN_WINDOWS or n_val < MIN_VAL_WINDOWS:
            return "fold_training"
    return None


def _sweep(cfg: dict, load, starts: dict, typed) -> tuple[dict, list, list]:
    """The sweep's durations and warm-up scaled to its drives (unless typed in the profile's own file), or the
    sweep off: (overrides, scaled, off)."""
    ev = cfg["evaluate"]
    sw = evaluate_config(ev, cfg["train"])["sweep"]
    names = list(sw["datasets"])
    if not names:
        return {}, [], []
    over, scaled = {}, []
    failing = {n: _sweep_fits(cfg, load(n), sw) for n in names}
    if not any(failing.values()):
        return {}, [], []
    # scale: a warm-up of at most a third of the shortest drive, the durations that fit after it
    room = min(float(load(n).imu["time"].iloc[-1]) - starts[n] for n in names)
    warm = min(float(sw["warmup_s"]), max(0.0, float(np.floor(room / 3.0 * 10.0) / 10.0)))
    warm = float(sw["warmup_s"]) if typed("evaluate.sweep.warmup_s") else warm
    durations = [float(d) for d in sw["durations_s"] if d <= room - warm - 1.0]
    if not durations and room - warm - 1.0 >= MIN_OUTAGE_S:
        durations = [float(np.floor(min(room - warm - 1.0, min(sw["durations_s"]))))]
    if typed("evaluate.sweep.durations_s"):
        durations = durations if durations == [float(d) for d in sw["durations_s"]] else []
    if durations:
        trial_sw = {**sw, "warmup_s": warm, "durations_s": durations}
        failing = {n: _sweep_fits(cfg, load(n), trial_sw) for n in names}
        if not any(failing.values()):
            for key, asked, planned in (("warmup_s", sw["warmup_s"], warm), ("durations_s", sw["durations_s"], durations)):
                if planned != asked:
                    over[f"evaluate.sweep.{key}"] = planned
                    scaled.append({"key": f"evaluate.sweep.{key}", "asked": asked, "planned": planned,
                                   "reason": "short_log", "room_s": round(room, 1)})
            o_dur = [float(d) for d in ev["oracle"]["durations_s"]]
            kept = [d for d in o_dur if d <= max(durations)]
            if kept != o_dur:
                over["evaluate.oracle.durations_s"] = kept
                scaled.append({"key": "evaluate.oracle.durations_s", "asked": o_dur, "planned": kept,
                               "reason": "sweep_durations"})
            return over, scaled, []
    why = next(r for r in failing.values() if r)
    return ({"evaluate.sweep.datasets": []}, [],
            [{"part": "evaluate.sweep.datasets", "reason": why, "room_s": round(room, 1),
              "durations_s": list(sw["durations_s"]), "warmup_s": float(sw["warmup_s"])}])


def _odometer(cfg: dict, load) -> tuple[dict, list]:
    """The odometer bars off when the sweep is off or a drive's folds leave no windows: (overrides, off)."""
    ev = cfg["evaluate"]
    sw = evaluate_config(ev, cfg["train"])["sweep"]
    od = ev.get("odometer") or {}
    bars = odometer_datasets(od, sw["datasets"])
    if not bars:
        return {}, []
    off = {"evaluate.odometer.datasets": [], "evaluate.odometer.network_datasets": []}
    if not sw["datasets"]:
        return off, [{"part": "evaluate.odometer.datasets", "reason": "sweep_off"}]
    margin, val_fraction = float(cfg["train"]["margin_s"]), float(cfg["train"]["val_fraction"])
    rate = float(((cfg.get("nav") or {}).get("nhc") or {}).get("rate_hz", 1.0))
    for name in bars:
        drive = load(name)
        if drive.meta.get("platform", DEFAULT_PLATFORM) != "car":
            continue                                        # a walker's bars are skipped by notebook 07 itself
        plan = profile_sweep_plan(cfg, drive, sw)
        dmax = max(float(d) for d in sw["durations_s"])
        window, _ = lo.window_samples(drive.imu, float(od["window_s"]))
        t = drive.imu["time"].to_numpy(float)
        epochs = np.arange(np.ceil(t[0] * rate) / rate, t[-1], 1.0 / rate)
        ws = lo.speed_windows(drive.imu, epochs, window, np.ones(epochs.size))
        # the bars' folds (and the paper's outages as one more), then the ridge curve's fold counts (notebook 07)
        folds = [(f"fold {k}", [(float(s), dmax) for s in plan.loc[plan["fold"] == k, "start_s"]], True)
                 for k in sorted(plan["fold"].unique())]
        if od["paper_outages"]:
            folds.append(("the paper's outages", [tuple(w) for w in outage_windows(cfg, drive, name)], True))
        for n in sorted({min(int(n), int(plan["fold"].size)) for n in od["curve_folds"]}):
            curve = profile_sweep_plan(cfg, drive, {**sw, "folds": n})
            folds += [(f"fold {k} of the ridge curve's {n}", [(float(s), dmax) for s in
                                                             curve.loc[curve["fold"] == k, "start_s"]], False)
                      for k in sorted(curve["fold"].unique())]
        for label, held, calibrated in folds:
            try:
                with warnings.catch_warnings(), np.errstate(all="ignore"):   # an empty split's normalizer
                    warnings.simplefilter("ignore", RuntimeWarning)
                    data = lo.build_speed_data(ws, held, margin, val_fraction, int(od["val_blocks"]),
                                               bool(od["calibration_blocks"]) and calibrated)
                ok = len(data.train) >= 2 and len(data.calibration_windows if calibrated else data.val) >= 1
            except DataError:
                ok = False
            if not ok:
                return off, [{"part": "evaluate.odometer.datasets", "reason": "fold_windows",
                              "dataset": drive.name, "fold": label}]
    return {}, []


def make_plan(cfg: dict, load, typed=lambda key: False) -> RunPlan:
    """The run plan of a loaded profile (module docstring).

    Parameters
    ----------
    cfg : dict
        The profile as :func:`bgfn.profile_schema.load_profile` reads it without a plan (every key checked).
    load : callable
        ``load(name) -> Drive`` for every dataset the profile names (the profile check loads them once).
    typed : callable
        ``typed(dotted_key) -> bool``: whether the profile's own file sets the key (never scaled: what a user
        typed is either held or refused; a base's or a default's value is scaled).

    Raises
    ------
    DataError
        A need of the paper's notebooks (02-05) that no scaling meets: the key, and what the log holds.
    """
    tr, ev = cfg["train"], cfg["evaluate"]
    names = list(dict.fromkeys(cfg["nav"].get("datasets", []) + tr.get("datasets", []) + ev.get("datasets", [])))
    drives = {n: load(n) for n in names}
    starts = {n: filter_start(d, cfg["nav"]) for n, d in drives.items()}
    facts, over, scaled = _scaled_outages(cfg, drives, starts, typed)
    planned = complete(set_keys(cfg, over))
    sweep_starts = dict(starts)

    def load_any(name):
        if name not in drives:
            drives[name] = load(name)
        if name not in sweep_starts:
            sweep_starts[name] = filter_start(drives[name], planned["nav"])
        return drives[name]

    for name in evaluate_config(planned["evaluate"], planned["train"])["sweep"]["datasets"]:
        load_any(name)
    s_over, s_scaled, off = _sweep(planned, load_any, sweep_starts, typed)
    over.update(s_over)
    scaled += s_scaled
    planned = complete(set_keys(cfg, over))
    o_over, o_off = _odometer(planned, load_any)
    over.update(o_over)
    off += o_off
    planned = complete(set_keys(cfg, over))
    sw = evaluate_config(planned["evaluate"], planned["train"])["sweep"]
    # notebook 08: the INS drift and the NEES scan start at the sweep's starts on every drive of nav:
    if not sw["datasets"]:
        off += [{"part": p, "reason": "sweep_off"} for p in PARTS]
    else:
        short = [drives[n].name for n in planned["nav"].get("datasets", [])
                 if _sweep_fits(planned, drives[n], sw) == "no_room"]
        if short:
            off += [{"part": p, "reason": "no_room", "datasets": short} for p in PARTS]
    return RunPlan(cfg["profile"], fingerprint(cfg), facts, over, scaled, off)

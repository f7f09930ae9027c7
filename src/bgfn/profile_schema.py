"""The schema of a profile (``params/<profile>.yaml``): every key, its type and range, checked before anything runs.

This module is the package's edge, the top of its layers: it may import everything it checks, and nothing of the
package imports it. :func:`load_profile` reads the merged profile (:func:`bgfn.config.read_profile`, a ``base:``
chain included) and checks it against :data:`SCHEMA` and the cross-field facts of :func:`cross_check`;
:func:`with_overrides` does the same for a notebook's parameters. So every notebook's first cell and
``make reproduce`` (its ``check-profile`` step, ``python -m bgfn.profile_schema <profile>``) refuse a bad
profile at once, with one message naming the YAML file that set the key, the key path and the value. Keys
may be left out (the module that reads a section fills its defaults: ``bgfn.nav.baseline.NAV_DEFAULTS``,
``bgfn.train`` and ``bgfn.learning`` defaults, ``bgfn.evaluate.EVALUATE_DEFAULTS``); a key that is not in the
schema is an error with the closest valid key suggested (a typo never silently falls back to a default).

The checks that need the data (outages inside the drive, a rule's outages found in it, a window shorter than
the GPS-available data, a possible outage sweep) run in :func:`check_with_drives`, the ``make`` step, after the
data are fetched.
"""

from __future__ import annotations

import argparse
import difflib
import math
import os
import re
import sys
from dataclasses import dataclass, field
from typing import Any

from bgfn.config import (DEFAULT_DATASET_KEY, MAIN_VARIANT, VARIANT_NAME, VARIANT_RUN_KEYS, file_setting,
                         odometer_datasets, profile_chain, read_profile, set_keys, variant_config)
from bgfn.data import load_drive
from bgfn.data.names import profile_datasets, unique_ids
from bgfn.errors import DataError
from bgfn.evaluate import EVALUATE_DEFAULTS, evaluate_config
from bgfn.studies.outage_sweep.sweep import sweep_plan
from bgfn.learning import learning_options
from bgfn.learning.odometry import ODOMETER_INPUTS
from bgfn.nav.baseline import filter_start
from bgfn.nav.constraints import MOUNTING_WEIGHTS, MOUNTINGS
from bgfn.nav.outages import check_windows, is_rule, outage_entry, picked_outages
from bgfn.paper import METHOD_LABELS
from bgfn.parallel import BACKENDS, SCHEDULER_ENV


class ProfileError(ValueError):
    """A profile value that breaks the schema: ``path`` (dotted key), what was ``expected``, what was ``found``."""

    def __init__(self, path: str, expected: str, found: str):
        super().__init__(f"{path}: expected {expected}, found {found}")
        self.path, self.expected, self.found = path, expected, found


@dataclass(frozen=True)
class Spec:
    """What one key holds. ``kind``: ``number``, ``integer``, ``text``, ``flag``, ``list``, ``section``
    (known keys), ``mapping`` (free keys, each value ``item``), ``either`` (one of ``options``) or ``any``."""

    kind: str
    null: bool = False
    lo: float | None = None
    hi: float | None = None
    lo_open: bool = False
    hi_open: bool = False
    choices: tuple = ()
    item: "Spec | None" = None
    length: int | None = None
    min_len: int = 0
    fields: dict = field(default_factory=dict)
    options: tuple = ()


def number(lo=None, hi=None, *, lo_open=False, hi_open=False, null=False) -> Spec:
    return Spec("number", null, lo, hi, lo_open, hi_open)


def integer(lo=None, hi=None, *, null=False) -> Spec:
    return Spec("integer", null, lo, hi)


def text(*choices, null=False) -> Spec:
    return Spec("text", null, choices=tuple(choices))


def flag() -> Spec:
    return Spec("flag")


def seq(item: Spec | None = None, *, length=None, min_len=0, null=False) -> Spec:
    return Spec("list", null, item=item, length=length, min_len=min_len)


def section(**fields: Spec) -> Spec:
    return Spec("section", fields={k.replace("__", "-"): v for k, v in fields.items()})


def mapping(item: Spec) -> Spec:
    return Spec("mapping", item=item)


def either(*options: Spec) -> Spec:
    """A value that meets one of ``options`` (a list or a mapping, say); the message is the option of the
    value's own type."""
    return Spec("either", options=tuple(options))


ANY = Spec("any")
_POS = number(0, lo_open=True)
_NONNEG = number(0)
_SEED = integer(0)
_FRACTION = number(0, 1, lo_open=True, hi_open=True)
_NAMES = seq(text(), min_len=1)

#: The optimization keys (``train.optimizer``), the same for every method.
OPTIMIZER = section(
    epochs=integer(1), batch_size=integer(1), lr=_POS, weight_decay=_NONNEG,
    schedule=text("plateau", "cosine", "none"), lr_factor=number(0, 1, lo_open=True, hi_open=True),
    lr_patience=integer(0), min_lr=_NONNEG, patience=integer(1), min_delta=_NONNEG, grad_clip=_NONNEG,
    max_train_windows=integer(1, null=True), max_val_windows=integer(1, null=True), eval_batch_size=integer(1),
    num_threads=integer(1, null=True))

#: The ``train:`` section (notebook 03).
TRAIN = section(
    datasets=_NAMES, methods=_NAMES, seeds=seq(_SEED, min_len=1),
    attitude_source=text("kf", "reference"), window=integer(2),
    alignment=text("ending", "next"), yaw_encoding=text("unwrap", "relative", "raw"),
    target_frame=text("ned", "heading"), extra_channels=seq(text()), epoch_stride=integer(1),
    margin_s=_NONNEG, protocol=text("honest", "leaky"), val_fraction=_FRACTION,
    val_position=Spec("any"),            # 'start' | 'middle' | 'end' | fraction: checked in cross_check
    target_screen_sigma=number(0, lo_open=True, null=True),
    optimizer=OPTIMIZER, lr=mapping(_POS),
    lr_search=section(grid=seq(_POS, null=True), fraction=_FRACTION, seed=_SEED, extend=integer(0),
                      epochs=integer(1, null=True), patience=integer(1, null=True),
                      max_train_windows=integer(1, null=True), max_val_windows=integer(1, null=True)),
    recheck_all_windows=flag(), recheck_runs=text("first", "all"), size=text(), sizes=mapping(mapping(mapping(ANY))))

#: The parameters of the real car drive ``rtklib-drive0708`` (``data.rtklib-drive0708``; the defaults and the
#: builder's own checks in :data:`bgfn.data.drives.DATASETS`).
RTKLIB_DRIVE = section(
    seed=_SEED, imu_rate_hz=_POS, gnss_rate_hz=_POS, gnss_white_std_m=seq(_NONNEG, length=3),
    gnss_correlated_std_m=seq(_NONNEG, length=3), gnss_correlated_tau_s=_POS, imu_errors=mapping(ANY),
    imu_time_offset_s=number(-1.0, 1.0), t_start=number(null=True), t_end=number(null=True))
#: Evaluation outages typed in: ``[[start, duration], ...]`` (s, GPS time of week).
OUTAGE_LIST = seq(seq(number(), length=2), min_len=1)
#: Outages picked from a drive by a rule (:mod:`bgfn.nav.outage_rules`; its defaults fill left-out keys).
OUTAGE_RULE = section(
    rule=text("cruise_and_manoeuvre"), duration_s=_POS, step_s=_POS, warmup_s=_NONNEG, min_speed_mps=_NONNEG,
    cruise_max_yaw_rate_dps=_NONNEG, manoeuvre_min_yaw_rate_dps=_NONNEG, gap_s=_NONNEG, min_training_s=_NONNEG)
#: ``outage_windows``: one list for every dataset, or per dataset name (and ``default``) a list or a rule.
OUTAGE_WINDOWS = either(OUTAGE_LIST, mapping(either(OUTAGE_LIST, OUTAGE_RULE)))

#: ``variants``: name -> overrides of the profile (a partial ``train:`` section), merged over it as a ``base:``
#: chain merges (:func:`bgfn.config.merge_sections`); ``variant_runs``: which networks every variant trains
#: (null: ``train.datasets`` / ``train.methods``). Read by :mod:`bgfn.train.variants`.
VARIANT = section(train=Spec("section", fields=TRAIN.fields))
VARIANT_RUNS = section(datasets=seq(text(), min_len=1, null=True), methods=seq(text(), min_len=1, null=True),
                       seeds=seq(_SEED, min_len=1))
# Variant names (a folder name of ``models/variants/``; ``main`` is the profile itself) and the keys a variant may
# not set (which networks it trains is ``variant_runs``'s): :data:`bgfn.config.VARIANT_NAME`, ``MAIN_VARIANT``,
# ``VARIANT_RUN_KEYS``.

#: The whole profile.
SCHEMA = section(
    profile=text(), description=text(), seed=_SEED, base=text(), datasets=_NAMES,
    outage_windows=OUTAGE_WINDOWS,
    variants=mapping(VARIANT), variant_runs=VARIANT_RUNS,
    # where the independent runs go (bgfn.parallel.Runner): jobs null = the cores here; backend dask: scheduler
    parallel=section(jobs=integer(1, null=True), backend=text(*BACKENDS), scheduler=text(null=True)),
    data=section(
        datasets=_NAMES, seed=_SEED, imu_rate_hz=_POS, smoothing_degree=integer(1, 5),
        position_sigma_m=_POS, attitude_sigma_rad=_POS, t_start=number(null=True), t_end=number(null=True),
        imu_plot_start_tow=number(null=True), imu_plot_duration_s=_POS, rtklib__drive0708=RTKLIB_DRIVE),
    nav=section(
        datasets=_NAMES,
        init=section(position_std_m=_POS, height_std_m=_POS, velocity_std_mps=_POS, level_std_deg=_POS,
                     azimuth_std_deg=_POS),
        alignment=section(
            mode=text("reference", "gnss", "auto"), speed_threshold_mps=_POS, heading_time_s=_POS,
            level_time_s=_POS, still_window_s=_POS, still_min_s=_NONNEG, still_accel_std_mps2=_POS,
            still_gyro_std_dps=_POS, level_std_deg=_POS, azimuth_std_deg=_POS, velocity_std_mps=_POS),
        bias_model=text("random_walk", "gauss_markov"),
        noise_scale=Spec("any"),             # a positive number or 'auto', or per dataset: checked in cross_check
        noise_search=section(range=seq(_POS, length=2), max_runs=integer(1), tolerance=_POS, bias_walk=flag()),
        innovation_gate=number(0, 1, lo_open=True, hi_open=True, null=True),
        ins_tuning=text("shipped", "navego"),
        # the vehicle constraints of the +NHC rows (bgfn.nav.constraints)
        nhc=section(std_mps=_POS, rate_hz=_POS, mounting=text(*MOUNTINGS), mounting_min_speed_mps=_NONNEG,
                    mounting_weight=text(*MOUNTING_WEIGHTS)),
        zupt=section(std_mps=_POS, window_s=_POS, accel_ratio=_NONNEG, gyro_ratio=_NONNEG, max_speed_mps=_NONNEG),
        constraints_in_gps_run=flag()),
    train=TRAIN,
    evaluate=section(
        datasets=_NAMES, real_imu=flag(), methods=_NAMES, seeds=seq(_SEED, min_len=1, null=True),
        seed_aggregate=text("median", "first"),
        pseudo_gps=section(std_m=Spec("any"), std_growth_m_per_s=_NONNEG, fusion_rate_hz=_POS),
        series_rate_hz=_POS, train_missing=flag(), nhc_rows=flag(),
        sweep=section(datasets=seq(text()), n_starts=integer(1), durations_s=seq(_POS, min_len=1),
                      folds=integer(1), seeds=seq(_SEED, min_len=1), warmup_s=_NONNEG,
                      train=Spec("section", null=True, fields=TRAIN.fields), n_boot=integer(1),
                      level=_FRACTION, boot_seed=_SEED),
        oracle=section(sigmas_m=seq(_NONNEG), seeds=seq(_SEED, min_len=1), durations_s=seq(_POS)),
        odometer=section(datasets=seq(text(), null=True), methods=seq(text(*METHOD_LABELS)),
                         network_datasets=seq(text(), null=True),
                         network_seeds=either(seq(_SEED, min_len=1), mapping(seq(_SEED, min_len=1))),
                         paper_outages=flag(), window_s=number(0.5), sigmas_mps=seq(_POS), walk_mps_per_sqrt_s=_NONNEG,
                         seeds=seq(_SEED, min_len=1), hold_std_mps=_POS, ridge_alpha=_POS,
                         gate_probability=number(0, 1, lo_open=True, hi_open=True, null=True), lr_search=flag(),
                         inputs=text(*ODOMETER_INPUTS), val_blocks=integer(1), curve_folds=seq(integer(1)),
                         ensemble=flag(), ensemble_recalibrate=flag(), correlation=flag(), correlation_max_lag_s=_POS,
                         calibration_blocks=flag(),
                         train=Spec("section", null=True, fields=TRAIN.fields))),
    energy=section(
        e_mac_pj=_POS, e_ac_pj=_POS, dataset=text(null=True), seed=integer(0, null=True), allow_untrained=flag(),
        max_windows=integer(1, null=True), batch_size=integer(1), sweep_time_steps=seq(integer(1), min_len=1),
        sweep_max_rate=number(0, 1, lo_open=True), crosscheck_windows=integer(1),
        crosscheck_tolerance_pct=_POS))

#: ``data:`` keys that are not in its section are the parameters of one dataset (a mapping; checked by
#: :func:`bgfn.data.drives.dataset_params`).
_DATASET_PARAMS = mapping(ANY)
_SIZES = ("smoke", "quick", "paper")


def _fmt(v: Any) -> str:
    return repr(v) if not isinstance(v, float) else f"{v:g}"


def _range(spec: Spec) -> str:
    lo = "" if spec.lo is None else f"{'>' if spec.lo_open else '>='} {spec.lo:g}"
    hi = "" if spec.hi is None else f"{'<' if spec.hi_open else '<='} {spec.hi:g}"
    return " and ".join(p for p in (lo, hi) if p)


def _describe(spec: Spec) -> str:
    if spec.kind == "either":
        return " or ".join(_describe(o) for o in spec.options) + (" or null" if spec.null else "")
    what = {"number": "a number", "integer": "an integer", "text": "a string", "flag": "true or false",
            "list": "a list", "section": "a mapping of keys", "mapping": "a mapping", "any": "a value"}[spec.kind]
    if spec.choices:
        what = "one of " + ", ".join(repr(c) for c in spec.choices)
    rng = _range(spec)
    if rng:
        what += f" {rng}"
    if spec.kind == "list" and spec.length:
        what += f" of {spec.length} items"
    elif spec.kind == "list" and spec.min_len:
        what += f" of at least {spec.min_len} item"
    return what + (" or null" if spec.null else "")


def check(value: Any, spec: Spec, path: str) -> None:
    """Raise :class:`ProfileError` where ``value`` breaks ``spec`` (``path``: dotted key, for the message)."""
    if value is None:
        if spec.null or spec.kind == "any":
            return
        raise ProfileError(path, _describe(spec), "null")
    k = spec.kind
    if k == "either":
        failures = []
        for option in spec.options:
            try:
                check(value, option, path)
                return
            except ProfileError as exc:
                failures.append((option, exc))
        for option, exc in failures:            # the option of the value's own type says best what is wrong
            if (option.kind == "list") == isinstance(value, list) and \
                    (option.kind in ("section", "mapping")) == isinstance(value, dict):
                raise exc
        raise ProfileError(path, _describe(spec), _fmt(value))
    if k in ("number", "integer"):
        ok = isinstance(value, int) if k == "integer" else isinstance(value, (int, float))
        if isinstance(value, bool) or not ok or (isinstance(value, float) and not math.isfinite(value)):
            raise ProfileError(path, _describe(spec), _fmt(value))
        bad_lo = spec.lo is not None and (value <= spec.lo if spec.lo_open else value < spec.lo)
        bad_hi = spec.hi is not None and (value >= spec.hi if spec.hi_open else value > spec.hi)
        if bad_lo or bad_hi:
            raise ProfileError(path, _describe(spec), _fmt(value))
    elif k == "text":
        if not isinstance(value, str) or (spec.choices and value not in spec.choices):
            raise ProfileError(path, _describe(spec), _fmt(value))
    elif k == "flag":
        if not isinstance(value, bool):
            raise ProfileError(path, _describe(spec), _fmt(value))
    elif k == "list":
        if not isinstance(value, list) or len(value) < spec.min_len or (spec.length and len(value) != spec.length):
            raise ProfileError(path, _describe(spec), _fmt(value))
        if spec.item is not None:
            for i, v in enumerate(value):
                check(v, spec.item, f"{path}[{i}]")
    elif k in ("section", "mapping"):
        if not isinstance(value, dict):
            raise ProfileError(path, _describe(spec), type(value).__name__)
        for key, v in value.items():
            sub = f"{path}.{key}" if path else str(key)
            if k == "mapping":
                check(v, spec.item, sub)
            elif key in spec.fields:
                check(v, spec.fields[key], sub)
            elif path == "data" and isinstance(v, dict):
                check(v, _DATASET_PARAMS, sub)
            else:
                close = difflib.get_close_matches(str(key), list(spec.fields), n=1, cutoff=0.6)
                hint = f" (did you mean {path + '.' if path else ''}{close[0]}?)" if close else ""
                raise ProfileError(sub, f"one of the keys {', '.join(sorted(spec.fields))}{hint}", "unknown key")


def _window_entries(cfg: dict) -> list[tuple[str, Any]]:
    """``(key path, entry)`` of every ``outage_windows`` entry: the one list, or each dataset's list or rule."""
    spec = cfg.get("outage_windows")
    if isinstance(spec, dict):
        return [(f"outage_windows.{k}", v) for k, v in spec.items()]
    return [("outage_windows", spec or [])]


def _windows(entry) -> list[tuple[float, float]]:
    return [(float(s), float(d)) for s, d in entry]


def _check_window_list(path: str, entry: list, t0, t1) -> None:
    """Positive durations, no overlap, inside ``data.t_start``/``data.t_end``."""
    for i, (s, d) in enumerate(_windows(entry)):
        if d <= 0:
            raise ProfileError(f"{path}[{i}]", "a positive duration, s", _fmt([s, d]))
    wins = sorted(_windows(entry))
    for (s0, d0), (s1, d1) in zip(wins[:-1], wins[1:]):
        if s1 < s0 + d0:
            raise ProfileError(path, "windows that do not overlap",
                               f"[{s0:g}, {s0 + d0:g}] overlaps [{s1:g}, {s1 + d1:g}]")
    for i, (s, d) in enumerate(_windows(entry)):
        if (t0 is not None and s < t0) or (t1 is not None and s + d > t1):
            raise ProfileError(f"{path}[{i}]", f"inside the data [{t0}, {t1}] s (data.t_start, data.t_end)",
                               _fmt([s, d]))


def _check_outage_entries(cfg: dict) -> None:
    """Each list entry well formed; each rule names its rule; a mapping answers for every dataset."""
    data = cfg.get("data") or {}
    t0, t1 = data.get("t_start"), data.get("t_end")
    if t0 is not None and t1 is not None and t1 <= t0:
        raise ProfileError("data.t_end", f"a time after data.t_start = {t0:g} s", _fmt(t1))
    for path, entry in _window_entries(cfg):
        if isinstance(entry, dict):
            if "rule" not in entry:
                raise ProfileError(f"{path}.rule", "the name of the rule that picks the windows", "missing")
        else:
            _check_window_list(path, entry, t0, t1)
    spec = cfg.get("outage_windows")
    if isinstance(spec, dict) and DEFAULT_DATASET_KEY not in spec:   # every dataset a notebook loads needs its outages
        uncovered = [d for d in profile_datasets(cfg) if d not in spec]
        if uncovered:
            raise ProfileError("outage_windows", "an entry for every dataset of the profile, or a "
                               f"'{DEFAULT_DATASET_KEY}' entry", f"none for {', '.join(uncovered)}")


def cross_check(cfg: dict) -> None:
    """The facts that tie keys together and need no data; :class:`ProfileError` naming the key."""
    _check_outage_entries(cfg)
    par = cfg.get("parallel") or {}
    if par.get("backend") == "dask" and not par.get("scheduler") and not os.environ.get(SCHEDULER_ENV):
        raise ProfileError("parallel.scheduler", f"a Dask scheduler address (tcp://host:8786) with backend dask, or "
                           f"{SCHEDULER_ENV}= on the make command line", _fmt(par.get("scheduler")))
    data, tr, ev = cfg.get("data") or {}, cfg.get("train") or {}, cfg.get("evaluate") or {}
    nav = cfg.get("nav") or {}
    ns = nav.get("noise_scale")
    if isinstance(ns, dict) and DEFAULT_DATASET_KEY not in ns:
        raise ProfileError("nav.noise_scale", f"a '{DEFAULT_DATASET_KEY}' entry beside the per-dataset ones", _fmt(ns))
    for key, value in (ns.items() if isinstance(ns, dict) else [(None, ns)] if "noise_scale" in nav else []):
        if value != "auto" and (isinstance(value, bool) or not isinstance(value, (int, float))
                                or not math.isfinite(value) or value <= 0):
            raise ProfileError("nav.noise_scale" + (f".{key}" if key else ""),
                               "a positive number or 'auto' (or per dataset, with a 'default')", _fmt(value))
    seeds = (ev.get("odometer") or {}).get("network_seeds")
    if isinstance(seeds, dict) and DEFAULT_DATASET_KEY not in seeds:
        raise ProfileError("evaluate.odometer.network_seeds", f"a '{DEFAULT_DATASET_KEY}' list beside the per-dataset "
                           "ones", _fmt(seeds))
    band = (nav.get("noise_search") or {}).get("range")
    if band and not band[0] < band[1]:
        raise ProfileError("nav.noise_search.range", "[low, high] with low < high", _fmt(band))
    t0, t1 = data.get("t_start"), data.get("t_end")
    rate = data.get("imu_rate_hz")
    if "window" in tr and rate and t0 is not None and t1 is not None and tr["window"] / rate >= (t1 - t0):
        raise ProfileError("train.window", f"a window shorter than the data ({t1 - t0:g} s at {rate:g} Hz)",
                           f"{tr['window']} samples = {tr['window'] / rate:g} s")
    vp = tr.get("val_position")
    if vp is not None and not (vp in ("start", "middle", "end") or (isinstance(vp, (int, float))
                                                                      and not isinstance(vp, bool) and 0 <= vp <= 1)):
        raise ProfileError("train.val_position", "'start', 'middle', 'end' or a fraction in [0, 1]", _fmt(vp))
    for key, methods in (("train.methods", tr.get("methods")), ("evaluate.methods", ev.get("methods"))):
        bad = [m for m in methods or [] if m not in METHOD_LABELS]
        if bad:
            raise ProfileError(key, f"method ids among {', '.join(METHOD_LABELS)}", _fmt(bad))
    for key, train in (("train", tr), ("evaluate.sweep.train", {**tr, **((ev.get("sweep") or {}).get("train") or {})})):
        size = train.get("size")
        if size is None:
            continue
        for m in tr.get("methods") or []:
            if size not in ((train.get("sizes") or {}).get(m) or {}):
                raise ProfileError(f"{key}.size", f"a size block that train.sizes.{m} defines "
                                   f"({', '.join((train.get('sizes') or {}).get(m) or {}) or 'none'})", _fmt(size))
    sw = ev.get("sweep") or {}
    if "folds" in sw and "n_starts" in sw and sw["folds"] > sw["n_starts"]:
        raise ProfileError("evaluate.sweep.folds", f"at most evaluate.sweep.n_starts = {sw['n_starts']}",
                           _fmt(sw["folds"]))
    # the oracle runs at the sweep's starts (defaults filled in, as bgfn.evaluate.evaluate_config does)
    o_dur = (ev.get("oracle") or {}).get("durations_s", EVALUATE_DEFAULTS["oracle"]["durations_s"])
    s_dur = sw.get("durations_s") or EVALUATE_DEFAULTS["sweep"]["durations_s"]
    if o_dur and max(o_dur) > max(s_dur):
        raise ProfileError("evaluate.oracle.durations_s", f"durations up to evaluate.sweep.durations_s's longest "
                           f"{max(s_dur):g} s (the sweep's starts leave room for no more)", _fmt(o_dur))
    od = ev.get("odometer") or {}
    bars = odometer_datasets(od, sw.get("datasets", EVALUATE_DEFAULTS["sweep"]["datasets"]))
    bad = [d for d in od.get("network_datasets") or [] if d not in bars]
    if bad:
        raise ProfileError("evaluate.odometer.network_datasets", f"drives among the odometer bars' {bars} "
                           "(evaluate.odometer.datasets; null: every one of them)", _fmt(bad))
    en = cfg.get("energy") or {}
    if en.get("dataset") is not None and en["dataset"] not in (tr.get("datasets") or []):
        raise ProfileError("energy.dataset", f"one of train.datasets {tr.get('datasets')} (its networks are "
                           "measured)", _fmt(en["dataset"]))
    if en.get("seed") is not None and en["seed"] not in (tr.get("seeds") or []):
        raise ProfileError("energy.seed", f"one of train.seeds {tr.get('seeds')}", _fmt(en["seed"]))
    _check_variants(cfg)          # last: the profile itself passed, so an error here is the variant's


def _check_variants(cfg: dict) -> None:
    """Every variant's name, and the profile it makes checked as a whole profile (:func:`validate`): an error
    is named ``variants.<name>.<key>``; ``variant_runs.methods`` are method ids (notebook 03 trains those of them
    that ``train:`` trains: :meth:`bgfn.train.variants.VariantPlan.of`)."""
    for name, own in (cfg.get("variants") or {}).items():
        where = f"variants.{name}"
        if not re.match(VARIANT_NAME, str(name)) or name == MAIN_VARIANT:
            raise ProfileError(where, f"a name of letters, digits, '_' or '-' other than {MAIN_VARIANT!r} (the "
                               "profile's own networks)", _fmt(name))
        for key in VARIANT_RUN_KEYS:
            if key in ((own or {}).get("train") or {}):
                raise ProfileError(f"{where}.train.{key}", f"no {key} here: variant_runs.{key} says what every "
                                   "variant trains", "set")
        try:
            validate(variant_config(cfg, name))
        except ProfileError as exc:
            raise ProfileError(f"{where}.{exc.path}", exc.expected, exc.found) from None
    bad = [m for m in (cfg.get("variant_runs") or {}).get("methods") or [] if m not in METHOD_LABELS]
    if bad:
        raise ProfileError("variant_runs.methods", f"method ids among {', '.join(METHOD_LABELS)}", _fmt(bad))
    # a list inherited from a base (smoke's [turin-sim-mpu6000]) may name a drive this profile never loads
    trained = list((cfg.get("train") or {}).get("datasets") or [])
    bad = [d for d in (cfg.get("variant_runs") or {}).get("datasets") or [] if d not in trained]
    if cfg.get("variants") and bad:
        raise ProfileError("variant_runs.datasets", f"drives among train.datasets {trained} (a base's list may name "
                           "drives this profile does not train: set variant_runs: {datasets: null} for all of them, "
                           "or variants: {} for none)", _fmt(bad))


def validate(cfg: dict) -> None:
    """:func:`check` the whole profile against :data:`SCHEMA`, then :func:`cross_check`."""
    check(cfg, SCHEMA, "")
    cross_check(cfg)


def load_profile(profile: str, overrides: dict[str, Any] | None = None,
                 source: str = "notebook parameters") -> dict[str, Any]:
    """``params/<profile>.yaml`` read and merged (:func:`bgfn.config.read_profile`), then checked against the schema;
    with ``overrides`` (a notebook's parameters, ``{"section.key": value}``, None values skipped) set over it
    (:func:`with_overrides`, errors naming ``source``).

    Returns
    -------
    dict
        As :func:`bgfn.config.read_profile`: a fresh copy on every call.

    Raises
    ------
    bgfn.errors.DataError
        As :func:`bgfn.config.read_profile`, and a value that breaks the schema or a cross-field fact: the message
        names the YAML file that set the key (the profile's own or a base), the key path and the value.
    """
    cfg = read_profile(profile)
    try:
        validate(cfg)
    except ProfileError as exc:
        raise DataError(file_setting(profile, exc.path), exc.path, exc.expected, exc.found) from None
    return with_overrides(cfg, overrides, source) if overrides else cfg


def with_overrides(cfg: dict, overrides: dict[str, Any], source: str = "notebook parameters") -> dict:
    """``cfg`` with the non-None ``overrides`` set (:func:`bgfn.config.set_keys`), checked like the file itself.

    The notebooks' papermill parameters (``datasets = None`` ... in their ``parameters`` cell) reach the
    profile through this one function, so a bad parameter fails like a bad profile key.

    Parameters
    ----------
    cfg : dict
        A loaded profile (:func:`load_profile`); not modified.
    overrides : dict
        ``{"section.key": value}`` (dotted paths); None values are skipped (None = keep the profile's).
    source : str
        Named in the error message instead of a file.

    Raises
    ------
    bgfn.errors.DataError
        ``source``, the key path and the value, as for a profile file.
    """
    out = set_keys(cfg, overrides)
    try:
        validate(out)
    except ProfileError as exc:
        raise DataError(source, exc.path, exc.expected, exc.found) from None
    return out


def check_with_drives(profile: str) -> list[str]:
    """The checks that need the data, for ``make``'s ``check-profile`` step: each dataset of the profile loads
    (built and cached when new, as notebook 01 would), no two share a dataset id (the name of their result files,
    :func:`bgfn.data.names.dataset_id`), the outages lie inside every drive of notebooks 02-04,
    the input window is shorter than the GPS-available data, and the outage sweep has its starts.

    Returns
    -------
    list of str
        One line per dataset, what was checked.

    Raises
    ------
    bgfn.errors.DataError
        Naming the profile's file and the key.
    """
    cfg = load_profile(profile)
    path = profile_chain(profile)[0]
    tr, ev = cfg["train"], cfg["evaluate"]
    opts = learning_options(tr)                 # the window and margin notebook 03 uses, defaults filled in
    names = dict.fromkeys(cfg["nav"].get("datasets", []) + tr.get("datasets", []) + ev.get("datasets", [])
                          + (ev.get("sweep") or {}).get("datasets", []))
    unique_ids(list(cfg["data"].get("datasets", [])) + list(names), path)   # result files must not overwrite
    spec = cfg.get("outage_windows")
    lines = []
    for name in names:
        drive = load_drive(name, profile=profile)
        t = drive.imu["time"].to_numpy(float)
        t0, t1 = filter_start(drive, cfg["nav"]), float(t[-1])     # a self-aligned filter starts late
        key = (f"outage_windows.{name if name in spec else DEFAULT_DATASET_KEY}" if isinstance(spec, dict)
               else "outage_windows")
        entry = outage_entry(cfg, name)
        rule = is_rule(entry)
        try:                                    # a rule picks the windows from the drive (the notebooks' reader)
            windows = picked_outages(cfg, drive, name).windows if rule else _windows(entry)
        except DataError as exc:
            raise DataError(path, f"{key}.{exc.field}", f"{exc.expected} in the drive {name}", exc.found) from None
        try:
            check_windows(windows, t0, t1, name)
        except DataError as exc:
            raise DataError(path, key, f"windows inside the drive {name} after the filter's start "
                            f"[{t0:.3f}, {t1:.3f}] s", exc.found) from None
        rate = float(drive.meta.get("imu_rate_hz") or 1.0 / float(t[1] - t[0]))
        window_s = int(opts["window"]) / rate
        margin = float(opts["margin_s"])
        blocked = sum(d + 2 * margin for _, d in windows)
        if window_s >= (t1 - t0) - blocked and (t1 - t0) - sum(d for _, d in windows) > window_s:
            # the outages alone leave room: the margins take it (a short log under a margin made for long drives)
            raise DataError(path, "train.margin_s", f"a margin that leaves training data in {name}: its "
                            f"{t1 - t0:.1f} s less the outages ({sum(d for _, d in windows):g} s) and 2 x "
                            f"{margin:g} s of margin per outage leave {(t1 - t0) - blocked:.1f} s, less than one "
                            f"input window ({window_s:g} s); set train.margin_s to at most "
                            f"{max(0.0, ((t1 - t0) - sum(d for _, d in windows) - window_s) / (2 * len(windows))):.1f} s "
                            f"or record a longer log", f"{margin:g} s")
        if window_s >= (t1 - t0) - blocked:
            raise DataError(path, "train.window", f"a window shorter than the GPS-available data of {name} "
                            f"({(t1 - t0) - blocked:.1f} s outside the outages and their margins)",
                            f"{opts['window']} samples = {window_s:g} s")
        how = "picked by the rule" if rule else "inside"
        lines.append(f"{name}: {t0:.2f}..{t1:.2f} s, outages {how} {[list(w) for w in windows]}, "
                     f"window {window_s:g} s")
    sw = evaluate_config(ev, tr)["sweep"]
    for name in sw["datasets"]:
        drive = load_drive(name, profile=profile)
        try:
            plan = sweep_plan(drive, sw, int(opts["window"]), t_first=filter_start(drive, cfg["nav"]))
        except DataError as exc:
            raise DataError(path, "evaluate.sweep.n_starts/durations_s/warmup_s", f"{exc.expected} in {name}",
                            exc.found) from None
        lines.append(f"{name}: outage sweep of {len(plan)} starts in {sw.get('folds')} folds")
    return lines


def main(argv=None) -> int:
    """``python -m bgfn.profile_schema <profile>``: check a profile, with its data, before anything runs."""
    parser = argparse.ArgumentParser(description=main.__doc__)
    parser.add_argument("profile")
    args = parser.parse_args(argv)
    try:
        lines = check_with_drives(args.profile)
    except DataError as exc:
        print(f"error: profile {args.profile!r}: {exc}", file=sys.stderr)
        return 2
    for line in lines:
        print(f"    profile {args.profile}: {line}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

"""The check of a whole profile before anything runs: its keys (:mod:`bgfn.settings`), the facts that tie keys
together, and the facts that need the drives.

The package's edge: it may import everything it checks, and nothing of the package imports it.
:func:`load_profile` reads the merged profile with every default filled and every key checked
(:func:`bgfn.config.read_profile`), then the cross-field facts (:func:`cross_check`); :func:`with_overrides` does
the same for a notebook's parameters. A bad profile is refused at once, with one message naming the YAML file, the
key path and the value (a misspelt key gets the closest valid one). The checks that need the data (outages inside
the drive, a possible outage sweep) run in :func:`check_with_drives`, the ``make`` step, after the data are fetched.
"""

from __future__ import annotations

import argparse
import difflib
import inspect
import os
import re
import sys
from typing import Any

from bgfn.config import (DEFAULT_DATASET_KEY, MAIN_VARIANT, VARIANT_NAME, VARIANT_RUN_KEYS, file_setting,
                         odometer_datasets, own_settings, profile_chain, read_profile, set_keys, variant_config)
from bgfn.data import load_drive
from bgfn.data.names import dataset_id, profile_datasets, unique_ids, with_dataset_ids
from bgfn.data.imu_errors import EKINOX_D, MPU6000, error_params
from bgfn.data.registry import DATASETS
from bgfn.errors import DataError
from bgfn.io import atomic_write_text
from bgfn.report.run_plan import plan_lines
from bgfn.report.run_words import runner_words
from bgfn.evaluate import evaluate_config
from bgfn.studies.outage_sweep.sweep import sweep_plan
from bgfn.studies.fleet.drives import DRIVES_KEY, folder_platform, platform_refusal
from bgfn.learning import learning_options
from bgfn.nav.baseline import filter_start
from bgfn.nav.outages import check_windows, is_rule, outage_entry, picked_outages, snap_windows
from bgfn.models import MODELS
from bgfn.paper import METHOD_LABELS
from bgfn.parallel import SCHEDULER_ENV, Runner
from bgfn.run_plan import RunPlan, fingerprint, make_plan, plan_json, plan_path, read_plan
from bgfn.settings import MAX_COUNT, Data, Train
from bgfn.settings_check import ProfileError, check_model, complete, fmt, merge

__all__ = ["ProfileError", "check_with_drives", "cross_check", "load_profile", "main", "validate", "with_overrides"]


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
            raise ProfileError(f"{path}[{i}]", "a positive duration, s", fmt([s, d]))
    wins = sorted(_windows(entry))
    for (s0, d0), (s1, d1) in zip(wins[:-1], wins[1:]):
        if s1 < s0 + d0:
            raise ProfileError(path, "windows that do not overlap",
                               f"[{s0:g}, {s0 + d0:g}] overlaps [{s1:g}, {s1 + d1:g}]")
    for i, (s, d) in enumerate(_windows(entry)):
        if (t0 is not None and s < t0) or (t1 is not None and s + d > t1):
            raise ProfileError(f"{path}[{i}]", f"inside the data [{t0}, {t1}] s (data.t_start, data.t_end)",
                               fmt([s, d]))


def _check_outage_entries(cfg: dict) -> None:
    """Each list of windows inside the data, without overlaps; a mapping answers for every dataset (the entries'
    form: :func:`bgfn.settings_check.complete`)."""
    data = cfg.get("data") or {}
    t0, t1 = data.get("t_start"), data.get("t_end")
    if t0 is not None and t1 is not None and t1 <= t0:
        raise ProfileError("data.t_end", f"a time after data.t_start = {t0:g} s", fmt(t1))
    for path, entry in _window_entries(cfg):
        if not isinstance(entry, dict):
            _check_window_list(path, entry, t0, t1)
    spec = cfg.get("outage_windows")
    if isinstance(spec, dict) and DEFAULT_DATASET_KEY not in spec:   # every dataset a notebook loads needs its outages
        uncovered = [d for d in profile_datasets(cfg) if d not in spec]
        if uncovered:
            raise ProfileError("outage_windows", "an entry for every dataset of the profile, or a "
                               f"'{DEFAULT_DATASET_KEY}' entry", f"none for {', '.join(uncovered)}")


def _unknown(path: str, key, known) -> ProfileError:
    """An unknown key at ``path``, with the known ones and the closest of them."""
    close = difflib.get_close_matches(str(key), list(known), n=1, cutoff=0.6)
    hint = f" (did you mean {path.rsplit('.', 1)[0]}.{close[0]}?)" if close else ""
    return ProfileError(path, f"one of the keys {', '.join(sorted(known))}{hint}", "unknown key")


def _check_drive_keys(data: dict) -> None:
    """Each ``data.<drive>`` mapping names a registered drive and only the parameters that drive takes (their types:
    :class:`bgfn.settings.DriveParams`); a CSV folder takes its own from its ``meta.yaml``."""
    for name, section in data.items():
        if name in Data.model_fields:
            continue
        if name not in DATASETS:
            close = difflib.get_close_matches(str(name), list(DATASETS), n=1, cutoff=0.6)
            raise ProfileError(f"data.{name}", "a registered drive's parameters (" + ", ".join(DATASETS) + "; a CSV "
                               "folder's go in its meta.yaml)" + (f" (did you mean data.{close[0]}?)" if close else ""),
                               "a mapping for a drive the data step does not know")
        for key in section or {}:
            if key not in DATASETS[name]:
                raise _unknown(f"data.{name}.{key}", key, DATASETS[name])
        try:                                    # the IMU error keys, as the data step will read them
            error_params(EKINOX_D if "ekinox" in name else MPU6000, (section or {}).get("imu_errors") or {})
        except DataError as exc:
            raise ProfileError(f"data.{name}.imu_errors.{exc.field}", exc.expected, exc.found) from None


def _check_sizes(key: str, sizes: dict) -> None:
    """``train.sizes.<method>.<size>``: every key a keyword of the method's constructor (a misspelt one: the closest),
    a whole number of at least 1 and at most :data:`bgfn.settings.MAX_COUNT` where the constructor takes an int."""
    for method, blocks in (sizes or {}).items():
        if method not in MODELS:
            raise _unknown(f"{key}.sizes.{method}", method, MODELS)
        params = {n: p for n, p in inspect.signature(MODELS[method]).parameters.items() if n != "self"}
        for size, block in (blocks or {}).items():
            where = f"{key}.sizes.{method}.{size}"
            if not isinstance(block, dict):
                raise ProfileError(where, "a mapping of the model's keywords", fmt(block))
            for name, value in block.items():
                if name not in params:
                    raise _unknown(f"{where}.{name}", name, params)
                default = params[name].default
                if isinstance(default, int) and not isinstance(default, bool) and not (
                        isinstance(value, int) and not isinstance(value, bool) and 1 <= value <= MAX_COUNT):
                    raise ProfileError(f"{where}.{name}", f"a whole number from 1 to {MAX_COUNT:,}", fmt(value))


def _check_runner(cfg: dict) -> None:
    """``parallel:`` as :meth:`bgfn.parallel.Runner.of` reads it (the environment's ``JOBS=`` / ``DASK_SCHEDULER=``:
    :func:`check_keys`)."""
    try:
        Runner.of(cfg, environ={})
    except DataError as exc:
        raise ProfileError(f"parallel.{exc.field}", exc.expected, exc.found) from None


def cross_check(cfg: dict) -> None:
    """The facts that tie keys together and need no data; :class:`ProfileError` naming the key."""
    _check_outage_entries(cfg)
    _check_drive_keys(cfg.get("data") or {})
    _check_runner(cfg)
    par = cfg.get("parallel") or {}
    if par.get("backend") == "dask" and not par.get("scheduler") and not os.environ.get(SCHEDULER_ENV):
        raise ProfileError("parallel.scheduler", f"a Dask scheduler address (tcp://host:8786) with backend dask, or "
                           f"{SCHEDULER_ENV}= on the make command line", fmt(par.get("scheduler")))
    data, tr, ev = cfg.get("data") or {}, cfg.get("train") or {}, cfg.get("evaluate") or {}
    nav = cfg.get("nav") or {}
    band = (nav.get("noise_search") or {}).get("range")
    if band and not band[0] < band[1]:
        raise ProfileError("nav.noise_search.range", "[low, high] with low < high", fmt(band))
    t0, t1 = data.get("t_start"), data.get("t_end")
    rate = data.get("imu_rate_hz")
    if "window" in tr and rate and t0 is not None and t1 is not None and tr["window"] / rate >= (t1 - t0):
        raise ProfileError("train.window", f"a window shorter than the data ({t1 - t0:g} s at {rate:g} Hz)",
                           f"{tr['window']} samples = {tr['window'] / rate:g} s")
    for key, methods in (("train.methods", tr.get("methods")), ("evaluate.methods", ev.get("methods"))):
        bad = [m for m in methods or [] if m not in METHOD_LABELS]
        if bad:
            raise ProfileError(key, f"method ids among {', '.join(METHOD_LABELS)}", fmt(bad))
    for key, train in (("train", tr), ("evaluate.sweep.train", merge(tr, (ev.get("sweep") or {}).get("train") or {}))):
        size = train.get("size")
        if size is None:
            continue
        for m in tr.get("methods") or []:
            if size not in ((train.get("sizes") or {}).get(m) or {}):
                raise ProfileError(f"{key}.size", f"a size block that train.sizes.{m} defines "
                                   f"({', '.join((train.get('sizes') or {}).get(m) or {}) or 'none'})", fmt(size))
    sw = ev.get("sweep") or {}
    fold_train = merge(tr, sw.get("train") or {})      # the fold networks' and the odometer networks' train: sections
    _check_sizes("train", tr.get("sizes"))
    for key, train in (("evaluate.sweep.train", fold_train),
                       ("evaluate.odometer.train", merge(fold_train, (ev.get("odometer") or {}).get("train") or {}))):
        check_model(Train, train, key)
        _check_sizes(key, train.get("sizes"))
    if "folds" in sw and "n_starts" in sw and sw["folds"] > sw["n_starts"]:
        raise ProfileError("evaluate.sweep.folds", f"at most evaluate.sweep.n_starts = {sw['n_starts']}",
                           fmt(sw["folds"]))
    o_dur, s_dur = ev["oracle"]["durations_s"], sw["durations_s"]   # the oracle runs at the sweep's starts
    if o_dur and max(o_dur) > max(s_dur):
        raise ProfileError("evaluate.oracle.durations_s", f"durations up to evaluate.sweep.durations_s's longest "
                           f"{max(s_dur):g} s (the sweep's starts leave room for no more)", fmt(o_dur))
    od = ev.get("odometer") or {}
    bars = odometer_datasets(od, sw["datasets"])
    bad = [d for d in od.get("network_datasets") or [] if d not in bars]
    if bad:
        raise ProfileError("evaluate.odometer.network_datasets", f"drives among the odometer bars' {bars} "
                           "(evaluate.odometer.datasets; null: every one of them)", fmt(bad))
    en = cfg.get("energy") or {}
    if en.get("dataset") is not None and en["dataset"] not in (tr.get("datasets") or []):
        raise ProfileError("energy.dataset", f"one of train.datasets {tr.get('datasets')} (its networks are "
                           "measured)", fmt(en["dataset"]))
    if en.get("seed") is not None and en["seed"] not in (tr.get("seeds") or []):
        raise ProfileError("energy.seed", f"one of train.seeds {tr.get('seeds')}", fmt(en["seed"]))
    _check_fleet(cfg)
    _check_variants(cfg)          # last: the profile itself passed, so an error here is the variant's


def _check_fleet(cfg: dict) -> None:
    """A ``fleet:`` section's facts (notebook 11; off while ``fleet.drives`` is empty)."""
    fl = cfg.get("fleet") or {}
    drives = fl.get("drives") or []
    if not drives:
        return
    if fl.get("pieces") and len(drives) != 1:
        raise ProfileError("fleet.drives", "one drive to cut into fleet.pieces", fmt(drives))
    if not fl.get("pieces") and len(drives) < 2:
        raise ProfileError("fleet.drives", "at least 2 drives (or one with fleet.pieces)", fmt(drives))
    refused = platform_refusal({dataset_id(d): folder_platform(d) for d in drives})   # meta.yaml's platform
    if refused is not None:
        raise ProfileError(DRIVES_KEY, *refused)
    if fl.get("protocol") == "named":
        for key in ("train", "test"):
            if not fl.get(key):
                raise ProfileError(f"fleet.{key}", "the drives' names with protocol: named", fmt(fl.get(key)))
        if set(fl["train"]) & set(fl["test"]):
            raise ProfileError("fleet.test", "drives none of fleet.train", fmt(fl["test"]))
    longest = max((cfg.get("evaluate") or {}).get("sweep", {}).get("durations_s") or [0.0])
    if fl.get("curve") and fl.get("curve_duration_s", 0.0) > longest:
        raise ProfileError("fleet.curve_duration_s", f"at most evaluate.sweep.durations_s's longest {longest:g} s",
                           fmt(fl.get("curve_duration_s")))
    methods = (cfg.get("evaluate") or {}).get("odometer", {}).get("methods") or []
    if fl.get("networks") and not methods:
        raise ProfileError("fleet.networks", "evaluate.odometer.methods naming the networks to train", "none")
    if fl.get("curve_networks") and not (fl.get("networks") and fl.get("curve")):
        raise ProfileError("fleet.curve_networks", "fleet.networks and fleet.curve on (the curve's networks are "
                           "the fleet's)", "networks or curve off")
    if fl.get("inputs") and not (fl.get("networks") and set(fl["inputs"]) <= set(methods)):
        raise ProfileError("fleet.inputs", f"networks the fleet trains (fleet.networks on; evaluate.odometer.methods: "
                           f"{fmt(methods)})", fmt(sorted(fl["inputs"])))


def _check_variants(cfg: dict) -> None:
    """Every variant's name, and the profile it makes checked as a whole profile (:func:`validate`): an error
    is named ``variants.<name>.<key>``; ``variant_runs.methods`` are method ids (notebook 03 trains those of them
    that ``train:`` trains: :meth:`bgfn.train.variants.VariantPlan.of`)."""
    for name, own in (cfg.get("variants") or {}).items():
        where = f"variants.{name}"
        if not re.match(VARIANT_NAME, str(name)) or name == MAIN_VARIANT:
            raise ProfileError(where, f"a name of letters, digits, '_' or '-' other than {MAIN_VARIANT!r} (the "
                               "profile's own networks)", fmt(name))
        for key in VARIANT_RUN_KEYS:
            if key in ((own or {}).get("train") or {}):
                raise ProfileError(f"{where}.train.{key}", f"no {key} here: variant_runs.{key} says what every "
                                   "variant trains", "set")
        try:
            validate(variant_config(cfg, name))
        except ProfileError as exc:     # the key as the profile spells it, in the path and in a "did you mean"
            raise ProfileError(f"{where}.{exc.path}", exc.expected.replace("did you mean ", f"did you mean {where}."),
                               exc.found) from None
    bad = [m for m in (cfg.get("variant_runs") or {}).get("methods") or [] if m not in METHOD_LABELS]
    if bad:
        raise ProfileError("variant_runs.methods", f"method ids among {', '.join(METHOD_LABELS)}", fmt(bad))
    # a list inherited from a base (smoke's [turin-sim-mpu6000]) may name a drive this profile never loads
    trained = list((cfg.get("train") or {}).get("datasets") or [])
    bad = [d for d in (cfg.get("variant_runs") or {}).get("datasets") or [] if d not in trained]
    if cfg.get("variants") and bad:
        raise ProfileError("variant_runs.datasets", f"drives among train.datasets {trained} (a base's list may name "
                           "drives this profile does not train: set variant_runs: {datasets: null} for all of them, "
                           "or variants: {} for none)", fmt(bad))


def validate(cfg: dict) -> dict:
    """The whole profile checked (:func:`bgfn.settings_check.complete`, then :func:`cross_check`); with its defaults."""
    out = complete(cfg)
    cross_check(out)
    return out


def load_profile(profile: str, overrides: dict[str, Any] | None = None,
                 source: str = "notebook parameters", planned: bool = True) -> dict[str, Any]:
    """``params/<profile>.yaml`` read and merged (:func:`bgfn.config.read_profile`), then checked against the schema;
    with ``overrides`` (a notebook's parameters, ``{"section.key": value}``, None values skipped) set over it
    (:func:`with_overrides`, errors naming ``source``).

    Returns
    -------
    dict
        As :func:`bgfn.config.read_profile` (a fresh copy on every call), each CSV folder named by its dataset id
        (:func:`bgfn.data.names.with_dataset_ids`): no machine path reaches a table, record or file name.

    Raises
    ------
    bgfn.errors.DataError
        As :func:`bgfn.config.read_profile`; two drives of one id (naming the profile's file); a value that breaks
        the schema or a cross-field fact: the message names the YAML file that set the key (the profile's own or a
        base), the key path and the value.
    """
    cfg = with_dataset_ids(read_profile(profile), profile_chain(profile)[0])   # own logs by id from here on
    try:
        cross_check(cfg)
    except ProfileError as exc:
        raise DataError(file_setting(profile, exc.path), exc.path, exc.expected, exc.found) from None
    if planned:
        cfg = with_plan(profile, cfg)
    return with_overrides(cfg, overrides, source) if overrides else cfg


def with_plan(profile: str, cfg: dict) -> dict:
    """``cfg`` with the run plan's overrides (:mod:`bgfn.run_plan`: what the profile check scaled to the drives or
    switched off), when the check wrote one for this version of the profile.

    Raises
    ------
    bgfn.errors.DataError
        A plan that changes the profile was made for another version of it (edited since the check ran).
    """
    plan = read_plan(profile)
    if plan is None:
        return cfg
    if plan.fingerprint != fingerprint(cfg):
        if not plan.changes:
            return cfg
        raise DataError(plan_path(profile), "fingerprint", f"a run plan made for this version of the profile: run "
                        f"the profile check first (python -m bgfn.profile_schema {profile}; make reproduce runs it)",
                        "a plan for an earlier version")
    try:
        return validate(set_keys(cfg, plan.overrides))
    except ProfileError as exc:
        raise DataError(plan_path(profile), exc.path, exc.expected, exc.found) from None


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
    try:
        out = validate(set_keys(cfg, overrides))
    except ProfileError as exc:
        raise DataError(source, exc.path, exc.expected, exc.found) from None
    return out


def check_keys(profile: str) -> list[str]:
    """The checks that need no data (:func:`load_profile`) and the environment's ``JOBS=`` / ``DASK_SCHEDULER=``
    (``BGFN_JOBS``, ``DASK_SCHEDULER``) over the profile's ``parallel:``: ``make reproduce`` runs them first, before
    the environment's install, the data and anything else (``python -m bgfn.profile_schema --keys``).

    Returns
    -------
    list of str
        What was checked: where the runs go (a ``jobs`` above what this machine takes is capped, and said).

    Raises
    ------
    bgfn.errors.DataError
        Naming the profile's file and key, or the environment variable.
    """
    cfg = load_profile(profile, planned=False)        # the plan is remade by the check with the drives
    return [f"every key checked; independent runs {runner_words(Runner.of(cfg))}"]


def _typed(profile: str, key: str) -> bool:
    """Whether the profile's own file (not a base) sets the dotted ``key`` (a drive by its id, as the loaded profile
    names it: :func:`bgfn.data.names.with_dataset_ids`)."""
    node = with_dataset_ids(own_settings(profile))
    for k in key.split("."):
        if not isinstance(node, dict) or k not in node:
            return False
        node = node[k]
    return True


def check_with_drives(profile: str) -> list[str]:
    """:func:`check_and_plan`'s lines."""
    return check_and_plan(profile)[0]


def check_and_plan(profile: str) -> tuple[list[str], RunPlan]:
    """The checks that need the data, for ``make``'s ``check-profile`` step: each dataset of the profile loads
    (built and cached when new, as notebook 01 would), no two share a dataset id (the name of their result files,
    :func:`bgfn.data.names.dataset_id`), the outages lie inside every drive of notebooks 02-04,
    the input window is shorter than the GPS-available data, and the outage sweep has its starts.

    First the run plan (:func:`bgfn.run_plan.make_plan`): what every notebook needs of the drives, scaled to them or
    switched off; the checks below then run on the profile with the plan laid over it, as the notebooks will read it.

    Returns
    -------
    list of str
        One line per dataset, what was checked (the keys' line is :func:`check_keys`'s, which ``make`` prints
        first: its checks run here again, its line is not repeated).
    RunPlan
        The plan (``main`` writes it to ``results/<profile>/run_plan.json``).

    Raises
    ------
    bgfn.errors.DataError
        Naming the profile's file and the key.
    """
    check_keys(profile)
    lines: list[str] = []
    raw = load_profile(profile, planned=False)
    path = profile_chain(profile)[0]
    loaded: dict = {}

    def load(name):
        if name not in loaded:
            loaded[name] = load_drive(name, profile=profile)
        return loaded[name]

    try:
        plan, refused = make_plan(raw, load, lambda key: _typed(profile, key)), None
    except DataError as exc:           # the checks below may name a more precise cause first
        plan, refused = None, DataError(path, exc.field, f"{exc.expected} in the drive {exc.source}", exc.found)
        if exc.field.startswith("outage_windows."):     # a rule that no scaling fits: its key, as the plan saw it
            raise refused from None
    cfg = validate(set_keys(raw, plan.overrides)) if plan is not None else raw
    tr, ev = cfg["train"], cfg["evaluate"]
    opts = learning_options(tr)                 # the window and margin notebook 03 uses, defaults filled in
    names = dict.fromkeys(cfg["nav"].get("datasets", []) + tr.get("datasets", []) + ev.get("datasets", [])
                          + (ev.get("sweep") or {}).get("datasets", []))
    unique_ids(list(cfg["data"].get("datasets", [])) + list(names), path)   # result files must not overwrite
    spec = cfg.get("outage_windows")
    for name in names:
        drive = load(name)
        t = drive.imu["time"].to_numpy(float)
        t0, t1 = filter_start(drive, cfg["nav"]), float(t[-1])     # a self-aligned filter starts late
        key = (f"outage_windows.{name if name in spec else DEFAULT_DATASET_KEY}" if isinstance(spec, dict)
               else "outage_windows")
        entry = outage_entry(cfg, name)
        rule = is_rule(entry)
        try:                                    # a rule picks the windows from the drive (the notebooks' reader)
            windows = [w.window for w in snap_windows(picked_outages(cfg, drive, name).windows if rule
                                                       else _windows(entry), t)]      # on the IMU epochs
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
        drive = load(name)
        try:
            starts = sweep_plan(drive, sw, int(opts["window"]), t_first=filter_start(drive, cfg["nav"]))
        except DataError as exc:
            raise DataError(path, "evaluate.sweep.n_starts/durations_s/warmup_s", f"{exc.expected} in {name}",
                            exc.found) from None
        lines.append(f"{name}: outage sweep of {len(starts)} starts in {sw.get('folds')} folds")
    if refused is not None:
        raise refused
    return lines, plan


def main(argv=None) -> int:
    """``python -m bgfn.profile_schema <profile>``: check a profile, with its data, before anything runs."""
    parser = argparse.ArgumentParser(description=main.__doc__)
    parser.add_argument("profile")
    parser.add_argument("--keys", action="store_true", help="only what needs no data (before the install and data)")
    args = parser.parse_args(argv)
    plan = None
    try:
        if args.keys:
            lines = check_keys(args.profile)
        else:
            lines, plan = check_and_plan(args.profile)
            atomic_write_text(plan_path(args.profile), plan_json(plan))
    except DataError as exc:
        print(f"error: profile {args.profile!r}: {exc}", file=sys.stderr)
        return 2
    for line in lines + (plan_lines(plan) if plan is not None else []):
        print(f"    profile {args.profile}: {line}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

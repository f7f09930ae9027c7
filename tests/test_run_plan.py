"""The run plan (bgfn.run_plan): what every notebook needs of a log, checked before notebook 01, on own logs of
60 s (a car), 134 s (a walk) and 15 min (a car) through the README's profile (``base: own`` or ``own-walker`` and the
folder): nothing asked that the log cannot hold, scaled or switched off with its reason, and the same plan read by
every notebook through ``load_profile``."""

from __future__ import annotations

import importlib.util

import numpy as np
import pytest

from bgfn import config
from bgfn.data import load_drive
from bgfn.errors import DataError
from bgfn.evaluate import evaluate_config
from bgfn.io import atomic_write_text
from bgfn.nav.outages import outage_windows
from bgfn.profile_schema import check_and_plan, check_with_drives, load_profile
from bgfn.report.run_plan import plan_lines
from bgfn.run_plan import MIN_TRAIN_WINDOWS, PARTS, plan_json, plan_path, read_plan
from bgfn.studies.gallery.logs import walker_log
from bgfn.studies.outage_sweep.sweep import profile_sweep_plan

pytestmark = pytest.mark.usefixtures("repo_untouched")
_spec = importlib.util.spec_from_file_location("demo_log", config.PROJECT_ROOT / "tools" / "demo_log.py")
demo_log = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(demo_log)

#: The three logs: folder name -> (base, writer).
LOGS = {"car-60s": ("own", lambda f: demo_log.demo_log(f, name="car-60s", source="test", duration_s=60.0)),
        "walk-134s": ("own-walker", lambda f: walker_log(f, duration_s=134.0)),
        "car-15min": ("own", lambda f: demo_log.demo_log(f, name="car-15min", source="test", duration_s=900.0))}


class _Logs(dict):
    """The logs, each written the first time a test asks for it."""

    def __init__(self, root):
        super().__init__()
        self.root = root

    def __missing__(self, name):
        LOGS[name][1](self.root / name)
        self[name] = self.root / name
        return self[name]


@pytest.fixture(scope="module")
def logs(tmp_path_factory):
    return _Logs(tmp_path_factory.mktemp("logs"))


def _readme_profile(params, name, folder, extra=""):
    """The README's own-log profile: its base and the folder by absolute path (and ``extra`` lines)."""
    (params / f"mine-{name}.yaml").write_text(f"base: {LOGS[name][0]}\ndatasets: [{folder}]\n{extra}")
    return f"mine-{name}"


@pytest.mark.parametrize("name", list(LOGS))
def test_the_plan_asks_nothing_the_log_cannot_hold(name, logs, params, tmp_path, monkeypatch):
    monkeypatch.setattr(config, "RESULTS_ROOT", tmp_path / "results")
    profile = _readme_profile(params, name, logs[name])
    lines, plan = check_and_plan(profile)                       # the README's profile passes the check
    atomic_write_text(plan_path(profile), plan_json(plan))      # as python -m bgfn.profile_schema writes it
    cfg = load_profile(profile)                                 # every notebook's profile: the plan laid over it
    assert read_plan(profile).overrides == plan.overrides
    drive = load_drive(str(logs[name]), profile=profile)
    t = drive.imu["time"].to_numpy()
    (facts,) = plan.drives.values()
    # notebooks 02-04: the outages the notebooks read are the plan's, on the IMU epochs, after the filter's start
    windows = outage_windows(cfg, drive, str(logs[name]))
    assert [list(w) for w in windows] == [o["run"] for o in facts["outages"]]
    for s, d in windows:
        assert facts["t_first"] <= s and s + d <= t[-1] and d >= 5.0
        assert np.min(np.abs(t - s)) < 1e-9 and np.min(np.abs(t - (s + d))) < 1e-9
    assert facts["train_windows"] >= MIN_TRAIN_WINDOWS and facts["val_windows"] >= 2          # notebook 03
    # notebooks 06-08: the sweep either fits (its starts, the oracle's durations) or is off with all its parts
    sw = evaluate_config(cfg["evaluate"], cfg["train"])["sweep"]
    off = {o["part"] for o in plan.off}
    if sw["datasets"]:
        assert len(profile_sweep_plan(cfg, drive, sw)) == sw["n_starts"]
        assert max(cfg["evaluate"]["oracle"]["durations_s"] or [0.0]) <= max(sw["durations_s"])
        assert not off & set(PARTS)
    else:
        assert "evaluate.sweep.datasets" in off and set(PARTS) <= off
        assert cfg["evaluate"]["odometer"]["datasets"] == []
    # every scaled key and every part switched off is said in notebook 01's words
    words = "\n".join(plan_lines(plan))
    for entry in plan.scaled:
        assert entry["key"] in words
    assert words.count("off: ") == len(plan.off)
    assert str(logs[name]) not in words                          # the drive's own name, not the machine's path
    if name == "car-60s":       # a log of 60 s: outages, margins, sweep durations made for it
        scaled = {e["key"]: e["planned"] for e in plan.scaled}
        assert scaled["outage_windows.default.duration_s"] < 30.0 and scaled["train.margin_s"] < 10.0
        assert cfg["outage_windows"]["default"]["duration_s"] == scaled["outage_windows.default.duration_s"]
        assert max(sw["durations_s"]) < 60.0 or not sw["datasets"]
    if name == "car-15min":     # a log of 15 min holds what own asks: nothing scaled, two 30 s outages
        assert plan.scaled == [] and [d for _, d in windows] == [30.0, 30.0]


def test_a_key_the_user_typed_is_held_or_refused_never_scaled(logs, params, tmp_path, monkeypatch):
    monkeypatch.setattr(config, "RESULTS_ROOT", tmp_path / "results")
    profile = _readme_profile(params, "car-60s", logs["car-60s"],
                              "outage_windows: {default: {rule: cruise_and_manoeuvre, duration_s: 30.0}}\n")
    with pytest.raises(DataError) as err:
        check_with_drives(profile)
    assert err.value.field.startswith("outage_windows.default") and "60.0 s" in str(err.value)
    assert str(err.value.source) == str(params / f"{profile}.yaml")


def test_a_plan_for_an_earlier_version_of_the_profile_is_refused(logs, params, tmp_path, monkeypatch):
    monkeypatch.setattr(config, "RESULTS_ROOT", tmp_path / "results")
    profile = _readme_profile(params, "car-60s", logs["car-60s"])
    _, plan = check_and_plan(profile)
    atomic_write_text(plan_path(profile), plan_json(plan))
    assert load_profile(profile)["train"]["margin_s"] < 10.0
    (params / f"{profile}.yaml").write_text((params / f"{profile}.yaml").read_text() + "seed: 5\n")
    with pytest.raises(DataError, match="run the profile check first") as err:
        load_profile(profile)
    assert str(err.value.source) == str(plan_path(profile))
    assert load_profile(profile, planned=False)["train"]["margin_s"] == 10.0

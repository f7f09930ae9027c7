"""Outage windows picked by a rule (bgfn.nav.outage_rules) and the one reader of the profile's outage_windows
(bgfn.nav.outages.outage_windows) with per-dataset entries."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from bgfn.errors import DataError
from bgfn.nav import outage_rules as R
from bgfn.nav import outages, sim
from bgfn.profile_schema import load_profile, with_overrides
from bgfn.report import evaluation_words, nav_words, training_words

RULE = {"rule": "cruise_and_manoeuvre", "duration_s": 30.0, "step_s": 1.0, "warmup_s": 60.0, "min_speed_mps": 2.0,
        "cruise_max_yaw_rate_dps": 3.0, "manoeuvre_min_yaw_rate_dps": 5.0, "gap_s": 30.0, "min_training_s": 120.0}
#: The simulated drive's known parts: the speed peaks at CRUISE_PEAK_S on a straight, the yaw rate at TURN_PEAK_S.
CRUISE_PEAK_S, TURN_PEAK_S = 240.0, 400.0


def drive_reference(rate_hz: float = 10.0, t0: float = 1000.0) -> pd.DataFrame:
    """A 600 s car drive (times ``t0`` + 0..600 s): 20 s standing, then 8 m/s with gentle weaving (yaw rate
    1 deg/s amplitude), a straight fast part (speed bump to 20 m/s centred at ``CRUISE_PEAK_S``, no turning) and
    a turning part (5 m/s, yaw-rate bump of 20 deg/s centred at ``TURN_PEAK_S``)."""
    t = np.arange(int(600 * rate_hz) + 1) / rate_hz
    ramp = np.clip((t - 20.0) / 10.0, 0.0, 1.0)                          # stands for 20 s, 8 m/s after 30 s
    bump = np.exp(-((t - CRUISE_PEAK_S) / 20.0) ** 2)
    turn = np.exp(-((t - TURN_PEAK_S) / 12.0) ** 2)
    slow = np.exp(-((t - TURN_PEAK_S) / 40.0) ** 8)                      # 5 m/s around the turning part
    speed = ramp * (8.0 + 12.0 * bump - 3.0 * slow)
    calm = (1.0 - np.clip(bump * 4.0, 0.0, 1.0)) * (1.0 - slow)          # no weaving on the straight or turns
    yaw_rate = np.radians(1.0 * np.sin(2 * np.pi * t / 50.0) * calm + 20.0 * turn)
    yaw = 0.3 + np.concatenate([[0.0], np.cumsum(0.5 * (yaw_rate[1:] + yaw_rate[:-1]) * np.diff(t))])
    v = np.stack([speed * np.cos(yaw), speed * np.sin(yaw), np.zeros_like(t)], axis=-1)
    pos = sim.positions_from_velocity(t + t0, v, np.radians(45.0), np.radians(7.6), 250.0)
    return pd.DataFrame({"time": t + t0, "lat": pos[:, 0], "lon": pos[:, 1], "h": pos[:, 2], "v_n": v[:, 0],
                         "v_e": v[:, 1], "v_d": v[:, 2], "roll": 0.0, "pitch": 0.0,
                         "yaw": np.mod(yaw + np.pi, 2 * np.pi) - np.pi})


def drive(name: str = "sim", **kw):
    ref = drive_reference(**kw)
    return SimpleNamespace(name=name, reference=ref, imu=ref[["time"]])


# ----------------------------------------------------------------------------------------------- the rule
def test_the_rule_finds_the_straight_fast_part_and_the_turning_part():
    ref = drive_reference()
    picked = R.pick_windows(RULE, ref, margin_s=30.0)
    # symmetric bumps: the best 30 s windows are centred on their peaks; outage 1 cruising, 2 manoeuvring
    assert picked.windows == [(CRUISE_PEAK_S + 1000.0 - 15.0, 30.0), (TURN_PEAK_S + 1000.0 - 15.0, 30.0)]
    assert picked.kinds == ["cruise", "manoeuvre"]
    cruise, man = picked.scores.iloc[0], picked.scores.iloc[1]
    assert cruise["mean_speed_mps"] > 17.0 and cruise["mean_abs_yaw_rate_dps"] < 0.5
    assert man["mean_abs_yaw_rate_dps"] > 12.0 and man["mean_speed_mps"] == pytest.approx(5.0, abs=0.2)
    # 600 s minus the two windows widened by 30 s on each side (apart: 160 s between their starts)
    assert picked.training_s == pytest.approx(600.0 - 2 * 90.0)
    assert nav_words.picked_outage_lines(picked)[0].startswith("outage 1 (cruise): 30 s from 1225.0 s, mean speed")
    # deterministic, and independent of the reference's rate (the rule works on its own 1 s grid)
    assert R.pick_windows(RULE, ref, margin_s=30.0).windows == picked.windows
    assert R.pick_windows(RULE, drive_reference(rate_hz=100.0), margin_s=30.0).windows == picked.windows


def test_the_cruise_keeps_its_gap_from_the_manoeuvre_and_the_warm_up_is_counted_from_the_filters_start():
    ref = drive_reference()
    # a gap that forbids the fast part's best window: the cruise moves away, at least duration + gap apart
    wide = R.pick_windows({**RULE, "gap_s": 150.0}, ref)
    (c, d), (m, _) = wide.windows
    assert m == TURN_PEAK_S + 1000.0 - 15.0 and abs(c - m) >= d + 150.0
    assert wide.scores["mean_speed_mps"].iloc[0] < 17.0               # not the straight any more
    # the filter starts at the reference's first row (1000 s; it stands until 22.5 s): no window before + warm-up
    late = R.pick_windows({**RULE, "warmup_s": 250.0}, ref)
    assert min(s for s, _ in late.windows) >= 1000.0 + 250.0 - 1e-9
    assert late.thresholds["t_first"] == 1000.0 and late.thresholds["earliest_s"] == 1250.0
    # a self-aligned filter that starts at 1150 s: the warm-up counts from there (alignment included)
    aligned = R.pick_windows({**RULE, "warmup_s": 100.0}, ref, t_first=1150.0)
    assert aligned.thresholds["earliest_s"] == 1250.0 and aligned.windows == late.windows
    assert late.windows[1] == wide.windows[1] or late.windows[1][0] == TURN_PEAK_S + 1000.0 - 15.0
    # a warm-up past the turning part: no manoeuvre left, an error naming the threshold
    with pytest.raises(DataError, match="manoeuvre_min_yaw_rate_dps") as err:
        R.pick_windows({**RULE, "warmup_s": 430.0}, ref, source="sim: profile outage_windows")
    assert err.value.source == "sim: profile outage_windows"


def test_the_manoeuvre_threshold_comes_from_the_drives_own_turn_rates():
    ref = drive_reference()
    # a gentle drive: every yaw rate a fifth (the turning part peaks at 4 deg/s; its best 30 s window ~2.7 deg/s)
    rate = np.radians(0.2 * (1.0 * np.sin(2 * np.pi * (ref["time"] - 1000.0) / 50.0)) + 0.2 * 20.0
                      * np.exp(-((ref["time"] - 1000.0 - TURN_PEAK_S) / 12.0) ** 2))
    t = ref["time"].to_numpy()
    yaw = 0.3 + np.concatenate([[0.0], np.cumsum(0.5 * (rate.to_numpy()[1:] + rate.to_numpy()[:-1]) * np.diff(t))])
    speed = np.hypot(ref["v_n"], ref["v_e"])
    gentle = ref.assign(v_n=speed * np.cos(yaw), v_e=speed * np.sin(yaw))
    with pytest.raises(DataError, match="at most 2"):                   # the paper's car threshold alone: refused
        R.pick_windows({**RULE, "manoeuvre_yaw_rate_percentile": None}, gentle)
    picked = R.pick_windows(RULE, gentle)                                # the drive's own 75th percentile
    motion = R.motion_series(gentle, 1.0, 2.0)
    both = (motion["speed_mps"].to_numpy()[1:] >= 2.0) & (motion["speed_mps"].to_numpy()[:-1] >= 2.0)
    p75 = np.percentile(np.abs(motion["yaw_rate_dps"].to_numpy()[1:][both]), 75.0)
    assert picked.thresholds["percentile_dps"] == pytest.approx(p75) and p75 < 5.0
    assert picked.thresholds["manoeuvre_dps"] == pytest.approx(p75)
    assert picked.thresholds["cruise_dps"] == pytest.approx(min(3.0, p75))   # a cruise turns less than that
    assert abs(picked.windows[1][0] - (TURN_PEAK_S + 1000.0 - 15.0)) <= 1.0   # still the turning part
    # a drive that passes the fixed threshold keeps its windows: the percentile only lowers the bar
    assert R.pick_windows(RULE, ref).windows == R.pick_windows({**RULE, "manoeuvre_yaw_rate_percentile": None},
                                                               ref).windows


def test_the_rule_refuses_what_it_cannot_do():
    ref = drive_reference()
    with pytest.raises(DataError, match="min_training_s") as err:       # too little left for training
        R.pick_windows({**RULE, "min_training_s": 500.0}, ref, margin_s=30.0)
    assert "420.0 s" in str(err.value)
    a = np.radians(2.0) * (ref["time"] - 1000.0)                      # turning 2 deg/s more everywhere
    circling = ref.assign(v_n=ref["v_n"] * np.cos(a) - ref["v_e"] * np.sin(a),
                          v_e=ref["v_n"] * np.sin(a) + ref["v_e"] * np.cos(a))
    assert R.pick_windows({**RULE, "cruise_max_yaw_rate_dps": 2.5}, circling).windows[0][0] == 1225.0
    with pytest.raises(DataError, match="cruise_max_yaw_rate_dps"):    # nothing calm enough
        R.pick_windows({**RULE, "cruise_max_yaw_rate_dps": 1.0}, circling)
    with pytest.raises(DataError, match="min_speed_mps"):              # the car never moves that fast
        R.pick_windows({**RULE, "min_speed_mps": 50.0}, ref)
    with pytest.raises(DataError, match="warmup_s"):
        R.pick_windows({**RULE, "warmup_s": 590.0}, ref)
    with pytest.raises(DataError, match="one of cruise_and_manoeuvre"):
        R.pick_windows({**RULE, "rule": "fastest"}, ref)
    with pytest.raises(DataError, match="unknown key"):
        R.pick_windows({**RULE, "warmup": 10.0}, ref)
    assert R.rule_params({"rule": "cruise_and_manoeuvre"}) == {"rule": "cruise_and_manoeuvre",
                                                               **R.RULE_DEFAULTS["cruise_and_manoeuvre"]}


def test_yaw_rate_from_the_course_hand_computed():
    # a 10 deg/s circle at 5 m/s, standing still for its first 10 s
    t = np.arange(0.0, 60.01, 0.1)
    speed = np.where(t < 10.0, 0.0, 5.0)
    course = np.radians(10.0) * t
    ref = pd.DataFrame({"time": t, "v_n": speed * np.cos(course), "v_e": speed * np.sin(course)})
    m = R.motion_series(ref, 1.0, 2.0)
    assert m["time"].tolist() == list(np.arange(0.0, 61.0))
    # steps with both ends moving: 10 deg/s (wrapped through +-180 deg); standing or its last step: 0
    np.testing.assert_allclose(m["yaw_rate_dps"].to_numpy()[11:], 10.0, atol=1e-9)
    assert (m["yaw_rate_dps"].to_numpy()[:11] == 0.0).all()
    s = R.window_scores(m, 10.0, 1.0).set_index("start_s")
    assert s.loc[0.0, "mean_abs_yaw_rate_dps"] == 0.0 and s.loc[0.0, "mean_speed_mps"] == pytest.approx(5.0 / 11)
    assert s.loc[5.0, "mean_abs_yaw_rate_dps"] == pytest.approx(5 * 10.0 / 10)   # steps 11..15 of 6..15
    assert s.loc[20.0, "mean_abs_yaw_rate_dps"] == pytest.approx(10.0) and s.index[-1] == 50.0


def test_training_time_is_the_span_outside_the_widened_windows():
    assert R.training_time(0.0, 100.0, [(10.0, 10.0), (60.0, 10.0)], 5.0) == pytest.approx(100 - 20 - 20)
    assert R.training_time(0.0, 100.0, [(10.0, 10.0), (30.0, 10.0)], 5.0) == pytest.approx(100 - 40)  # overlap
    assert R.training_time(0.0, 100.0, [(2.0, 10.0)], 5.0) == pytest.approx(100 - 17)                # clipped


# ----------------------------------------------------------------------------------------------- the reader
def test_the_reader_takes_the_datasets_entry_or_the_default():
    prof = {"profile": "p", "outage_windows": {"default": [[1100.0, 30.0]], "other": [[1200.0, 20.0]],
                                               "sim": dict(RULE)}, "train": {"margin_s": 30.0}}
    assert outages.outage_windows(prof) == [(1100.0, 30.0)]
    assert outages.outage_windows(prof, dataset="turin") == [(1100.0, 30.0)]
    assert outages.outage_windows(prof, dataset="other") == [(1200.0, 20.0)]
    assert outages.default_windows(prof) == [(1100.0, 30.0)]
    d = drive()
    assert outages.outage_windows(prof, d) == R.pick_windows(RULE, d.reference).windows      # drive.name
    assert outages.outage_windows(prof, d, "other") == [(1200.0, 20.0)]
    with pytest.raises(DataError, match="a rule picks the windows") as err:
        outages.outage_windows(prof, dataset="sim")
    assert err.value.field == "outage_windows.sim"
    # the rule's training check uses train.margin_s (here 200 s leaves too little)
    with pytest.raises(DataError, match="min_training_s"):
        outages.outage_windows({**prof, "train": {"margin_s": 200.0}}, d)
    lines = nav_words.describe_windows(prof, d)
    assert lines[0].startswith("sim: outages (start, duration) s [[1225.0, 30.0], [1385.0, 30.0]] (rule")
    assert lines[1].startswith("  outage 1 (cruise)") and lines[2].startswith("  outage 2 (manoeuvre)")
    assert nav_words.describe_windows(prof, d, "other")[0].endswith("(listed in the profile)")
    # without a default a dataset the mapping does not name is an error naming the key
    with pytest.raises(DataError, match="'default' entry") as err:
        outages.outage_windows({"profile": "p", "outage_windows": {"sim": [[1100.0, 30.0]]}}, dataset="x")
    assert err.value.field == "outage_windows.x"
    assert outages.default_windows({"outage_windows": {"default": dict(RULE)}}) is None


def test_a_rule_in_a_profile_file_is_checked_with_the_schema(params):
    from bgfn.settings import OutageRule

    assert set(OutageRule.model_fields) == {"rule", *R.RULE_DEFAULTS["cruise_and_manoeuvre"]}
    def load(text):
        (params / "mine.yaml").write_text(f"profile: mine\nbase: smoke\ndescription: v\n{text}\n")
        return load_profile("mine")

    cfg = load("outage_windows: {sim: {rule: cruise_and_manoeuvre, gap_s: 10.0}}")      # merged over smoke's
    assert cfg["outage_windows"]["sim"]["gap_s"] == 10.0 and "default" in cfg["outage_windows"]
    assert load("outage_windows: [[138906.0, 30.0]]")["outage_windows"] == [[138906.0, 30.0]]   # a plain list
    for text, key, words in (
            ("outage_windows: {sim: {rule: cruise_and_manoeuvre, warmup: 10.0}}", "outage_windows.sim.warmup",
             "did you mean"),
            ("outage_windows: {sim: {rule: fastest}}", "outage_windows.sim.rule", "'cruise_and_manoeuvre'"),
            ("outage_windows: {sim: {gap_s: 10.0}}", "outage_windows.sim.rule", "missing"),
            ("outage_windows: {sim: {rule: cruise_and_manoeuvre, duration_s: -30.0}}",
             "outage_windows.sim.duration_s", "-30"),
            ("outage_windows: {default: [[138906.0, -30.0]]}", "outage_windows.default[0]", "-30"),
            ("outage_windows: {default: 3}", "outage_windows.default", "a list")):
        with pytest.raises(DataError) as err:
            load(text)
        assert err.value.field == key and words in str(err.value), str(err.value)
    # a mapping without a default must name every dataset of the profile
    (params / "quick.yaml").write_text((params / "quick.yaml").read_text().replace("  default: [[", "  turin: [["))
    with pytest.raises(DataError, match="none for turin-sim-ekinox"):
        load_profile("smoke")                             # smoke takes its outages from quick


def test_check_with_drives_applies_the_rule_to_each_drive(params, monkeypatch):
    from bgfn import profile_schema
    from bgfn.profile_schema import check_with_drives

    monkeypatch.setattr(profile_schema, "load_drive", lambda name, profile=None: SimpleNamespace(
        name=name, reference=drive_reference(), imu=drive_reference()[["time"]], meta={"imu_rate_hz": 10.0}))
    path = params / "mine.yaml"
    head = ("profile: mine\nbase: smoke\ndescription: v\ndata: {t_start: null, t_end: null}\n"
            "nav: {datasets: [sim]}\ntrain: {datasets: [sim]}\n"
            "evaluate: {datasets: [sim], sweep: {datasets: []}}\nvariant_runs: {datasets: null}\n")
    path.write_text(head + "outage_windows: {sim: {rule: cruise_and_manoeuvre}}\n")
    (line,) = [line for line in check_with_drives("mine") if line.startswith("sim: ")]
    assert "outages picked by the rule [[1225.0, 30.0], [1385.0, 30.0]]" in line
    path.write_text(head + "outage_windows: {sim: {rule: cruise_and_manoeuvre, min_training_s: 1000.0}}\n")
    with pytest.raises(DataError) as err:
        check_with_drives("mine")
    assert err.value.source == str(path) and err.value.field == "outage_windows.sim.min_training_s"
    assert "in the drive sim" in str(err.value)
    path.write_text(head + "outage_windows: {sim: [[1590.0, 30.0]]}\n")             # past the drive's end
    with pytest.raises(DataError) as err:
        check_with_drives("mine")
    assert err.value.field == "outage_windows.sim" and "inside the drive sim" in str(err.value), str(err.value)


# ----------------------------------------------------------------------------------------------- the callers
def test_training_and_evaluation_take_each_datasets_outages():
    from bgfn import evaluate as ev
    from bgfn import train as T
    from bgfn.profile_schema import load_profile

    smoke = T.TrainingPlan.of(load_profile("smoke"))                   # the shipped mapping: every Turin dataset the default
    default = outages.default_windows(smoke.cfg)
    assert smoke.per_dataset and smoke.outage_windows == default == [(138906.0, 30.0), (139170.0, 30.0)]
    assert smoke.windows_of("turin-sim-mpu6000") == default
    fixed = T.TrainingPlan.of(load_profile("smoke"), outage_windows=[(1.0, 2.0)])
    assert not fixed.per_dataset and fixed.windows_of("rtklib-drive0708") == [(1.0, 2.0)]
    cfg = {"profile": "p", "description": "d", "train": {"margin_s": 30.0},
           "outage_windows": {"default": [[1100.0, 30.0]], "sim": dict(RULE)}}
    plan = T.TrainingPlan("p", cfg, ["turin", "sim"], ["mlp"], [0], [(1100.0, 30.0)], per_dataset=True)
    d = drive()
    assert plan.windows_of("sim", d) == [(1225.0, 30.0), (1385.0, 30.0)]
    assert plan.windows_of("turin") == [(1100.0, 30.0)]
    assert "turin: [(1100.0, 30.0)]; sim: rule cruise_and_manoeuvre (picked from the drive)" in training_words.plan_text(plan)
    # notebook 04's setup: the default list, and a line for each dataset with its own entry
    prof = with_overrides(load_profile("smoke"), {"evaluate.datasets": ["turin-sim-ekinox", "sim", "other"]})
    prof["outage_windows"] = {**prof["outage_windows"], "sim": dict(RULE), "other": [[138800.0, 10.0]]}
    setup = ev.evaluation_setup(with_overrides(prof, {"evaluate.sweep.datasets": []}))
    assert setup.windows == default
    assert evaluation_words.setup_lines(setup)[3] == (f"outages (start, duration) s: {[list(w) for w in default]}; sim: rule "
                                   "cruise_and_manoeuvre (picked from the drive); other: [[138800.0, 10.0]]")


def test_the_shipped_smoke_profile_is_planned_unchanged(params):
    """The run plan (bgfn.run_plan) of a shipped profile changes nothing; its real drive keeps the rule's windows."""
    from bgfn.profile_schema import check_and_plan

    lines, plan = check_and_plan("smoke")
    assert plan.overrides == {} and plan.scaled == [] and plan.off == []
    # one line per drive: the keys' line is the first step's (make prints it once, before this check)
    assert not any("every key checked" in line for line in lines) and lines
    assert plan.drives["rtklib-drive0708"]["outages"] == [{"asked": [243538.0, 30.0], "run": [243538.0, 30.0]},
                                                          {"asked": [243627.0, 30.0], "run": [243627.0, 30.0]}]

"""The GNSS-IMU clock and the reference checked against the GNSS (bgfn.data.time_offset, bgfn.data.reference_check,
bgfn.nav.reference_attitude): logs with a known GNSS latency, an 18 s offset, a reference that is the GNSS, a
reference attitude from another IMU, and the shipped real drive."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from bgfn import config
from bgfn.data import Drive, load_drive, write_csv_drive
from bgfn.data import imu_errors as ie
from bgfn.data import reference_check as rc
from bgfn.data.time_offset import OffsetEstimate, decide_clock
from bgfn.errors import DataError
from bgfn.nav import baseline, sim
from bgfn.nav.reference_attitude import check_attitude
from bgfn.studies.gallery.logs import walker_log

sys.path.insert(0, str(config.PROJECT_ROOT / "tools"))
import demo_log  # noqa: E402

T0 = 243000.0
LEVER = [-0.4, 0.0, -1.0]


def _set_meta(folder: Path, **keys) -> None:
    meta = yaml.safe_load((folder / "meta.yaml").read_text()) or {}
    (folder / "meta.yaml").write_text(yaml.safe_dump({**meta, **keys}))


def _clock_log(folder: Path, latency: float, auto: bool = True) -> Path:
    """240 s of the demo trajectory: a quiet IMU at 100 Hz, 1 Hz fixes of 2 cm at an antenna 0.4 m behind and 1 m
    above the IMU, stamped ``latency`` s late; the reference at 5 Hz with attitude."""
    truth = sim.demo_trajectory(240.0, 100.0)
    truth["time"] += T0
    imu = sim.imu_from_trajectory(truth)
    cols = [c for c in imu.columns if c != "time"]
    rng = np.random.default_rng(1)
    imu[cols] = imu[cols].to_numpy() + rng.standard_normal((len(imu), 6)) * ([2e-4] * 3 + [2e-3] * 3)
    gnss = sim.gnss_from_trajectory(truth, 1.0, 0.02, 0.04, LEVER, seed=2)
    gnss["time"] = gnss["time"] + latency
    drive = Drive("clock", truth.iloc[::20].reset_index(drop=True), imu, gnss,
                  {"lever_arm_m": LEVER, "imu_errors": ie.error_params("ekinox-d"), "source": "test"})
    write_csv_drive(drive, folder)
    if auto:
        _set_meta(folder, gnss_latency_s="auto")
    return folder


@pytest.mark.parametrize("latency", [0.0, 0.25, -0.1])
def test_a_known_latency_is_recovered_within_its_std_and_applied_only_when_it_holds(tmp_path, latency):
    d = load_drive(_clock_log(tmp_path / "log", latency))
    o = d.meta["gnss_offset"]
    # both methods recover the latency within 3 of their own std (the turn rates on a 0.05 s grid)
    assert o["turn_rate_s"] is not None and abs(o["turn_rate_s"] - latency) <= 3 * o["turn_rate_std_s"]
    assert abs(o["reference_lag_s"] - latency) <= 3 * o["reference_std_s"] + 0.01
    assert abs(o["combined_s"] - latency) <= 3 * o["combined_std_s"] + 0.01       # they agree: their mean
    assert o["applied_s"] >= 0.0                                 # never a latency the key refuses
    if latency == 0.25:                                          # significant, confirmed, better: applied
        assert o["status"] == "applied" and o["applied_s"] == o["combined_s"]
        assert o["rms_with_m"] <= o["rms_without_m"]
    elif latency == 0.0:                                         # within its std: nothing applied
        assert o["status"] == "not_significant" and o["applied_s"] == 0.0
    else:                                                        # found, and refused as the key refuses it typed
        assert o["status"] == "refused_by_key" and o["applied_s"] == 0.0
    # what is left against the reference after the shift: no lag worth a warning, offsets of centimetres
    chk = d.meta["reference_check"]
    assert not chk["exceeds"] and chk["cause"] is None and not chk["equals_gnss"]
    assert abs(chk["along_median_m"]) <= 12.0 * abs(latency - o["applied_s"]) + 0.2      # speed 5-11 m/s


def test_the_applied_latency_never_widens_the_along_track_error(tmp_path):
    """The same log 0.25 s late loaded with the latency estimated and with none: the fixes' along-track spread
    against the reference is smaller with what was applied."""
    auto = load_drive(_clock_log(tmp_path / "auto", 0.25))
    plain = load_drive(_clock_log(tmp_path / "plain", 0.25, auto=False))
    assert plain.meta["gnss_offset"]["status"] == "not_asked" and plain.meta["gnss_offset"]["applied_s"] == 0.0

    def spread(d):
        off = rc.fix_offsets(d.reference, d.gnss, d.meta["lever_arm_m"])
        return float(off["along_m"].std())
    assert spread(auto) < 0.5 * spread(plain)


def test_a_negative_latency_is_refused_as_the_key_refuses_it_and_reported(tmp_path):
    d = load_drive(_clock_log(tmp_path / "log", -0.4))
    o = d.meta["gnss_offset"]
    assert o["status"] == "refused_by_key" and o["applied_s"] == 0.0
    assert o["turn_rate_s"] == pytest.approx(-0.4, abs=3 * o["turn_rate_std_s"])


def test_the_rule_needs_significance_agreement_and_no_worse_along_track_error():
    lag = rc.Lag(0.30, 0.01, 200, 1.0, 0.2)
    est = OffsetEstimate(0.30, 0.9, 200, 0.05)
    assert decide_clock(est, lag, True, lambda s: 1.0 - s).status == "applied"
    assert decide_clock(est, lag, True, lambda s: 1.0 + s).status == "worse"               # checked, not assumed
    assert decide_clock(est, None, True).status == "unconfirmed"                            # no second method
    assert decide_clock(est, rc.Lag(0.0, 0.01, 200, 1.0, 1.0), True).status == "disagrees"  # the car of the issue
    assert decide_clock(OffsetEstimate(0.01, 0.9, 200, 0.05), rc.Lag(0.01, 0.01, 200, 1.0, 1.0),
                        True).status == "not_significant"
    weak = decide_clock(OffsetEstimate(0.5, 0.8, 200, 0.3), lag, True, lambda s: 1.0 - s)   # a broad peak that agrees
    assert weak.status == "applied" and weak.applied_s == pytest.approx(0.30, abs=0.001)
    assert decide_clock(OffsetEstimate(float("nan"), 0.2, 10), None, True).status == "not_estimable"
    typed = decide_clock(est, lag, False)
    assert typed.status == "not_asked" and typed.applied_s == 0.0 and np.isnan(typed.gross_s)
    gross = decide_clock(OffsetEstimate(float("nan"), 0.1, 200), rc.Lag(18.0, 0.02, 200, 50.0, 1.0), True)
    assert gross.applied_s == 0.0 and gross.gross_s == 18.0 and gross.gross_method == "reference"



def test_the_clock_decision_is_numbers_and_its_sentence_is_made_in_report():
    """The drive keeps the decision's numbers and codes (meta["gnss_offset"]); report words them: the estimate as
    found, and with gnss_latency_s: auto what was taken off and why."""
    from bgfn.report.data_checks import clock_offset_line

    lag, est = rc.Lag(0.30, 0.01, 200, 1.0, 0.2), OffsetEstimate(0.30, 0.9, 200, 0.05)
    applied = {**decide_clock(est, lag, True, lambda s: 1.0 - s).record()}
    assert all(not isinstance(v, str) or v in ("applied", "reference") for v in applied.values())   # no sentence
    assert clock_offset_line(applied, "car", "car") == (
        "car: GNSS latency 0.30 s taken off (gnss_latency_s: auto, applied); estimated: GNSS-IMU clock offset: the "
        "fixes' stamps are +0.30 s late against the IMU's (turn rates correlate 0.90 over 200 moving fixes); "
        "platform car")
    typed = decide_clock(est, lag, False).record()
    assert clock_offset_line(typed) == ("GNSS-IMU clock offset: the fixes' stamps are +0.30 s late against the "
                                        "IMU's (turn rates correlate 0.90 over 200 moving fixes)")
    none = decide_clock(OffsetEstimate(float("nan"), float("nan"), 10), None, False).record()
    assert clock_offset_line(none, "walk") == ("walk: GNSS-IMU clock offset: not estimable (10 moving fixes, best "
                                               "correlation none of the turn rates)")

@pytest.mark.parametrize("auto", [False, True])
def test_an_18_s_offset_on_gentle_turns_is_one_error_naming_the_cause(tmp_path, auto):
    """The demo log's turns are too gentle for the turn rates (not estimable): the reference check sees the 18 s."""
    folder = demo_log.demo_log(tmp_path / "log", name="car", source="test")
    gnss = pd.read_csv(folder / "gnss.csv")
    gnss.assign(time=gnss["time"] + 18.0).to_csv(folder / "gnss.csv", index=False)
    if auto:
        _set_meta(folder, gnss_latency_s="auto")
    with pytest.raises(DataError) as err:
        load_drive(folder)
    assert err.value.source == str(folder / "gnss.csv") and "imu.csv" in str(err.value)
    assert "along-track offsets against reference.csv" in str(err.value) and "18 s apart" in str(err.value)


def _walk(tmp_path, reference_is_gnss: bool) -> Path:
    folder = walker_log(tmp_path / "walk")
    _set_meta(folder, gnss_latency_s="auto")
    if reference_is_gnss:         # the fixes written from the reference itself (a walker's phone as its own truth)
        ref, gnss = pd.read_csv(folder / "reference.csv"), pd.read_csv(folder / "gnss.csv")
        at = ref.set_index(np.round(ref["time"] * 100).astype(int))
        rows = at.loc[np.round(gnss["time"] * 100).astype(int)]
        gnss.assign(**{c: rows[c].to_numpy() for c in ("lat", "lon", "h")}).to_csv(folder / "gnss.csv", index=False)
    return folder


def test_a_walk_says_not_estimable_and_applies_nothing(tmp_path):
    d = load_drive(_walk(tmp_path, reference_is_gnss=False))
    o = d.meta["gnss_offset"]
    assert o["status"] == "not_estimable" and o["applied_s"] == 0.0 and o["turn_rate_s"] is None
    assert not d.meta["reference_equals_gnss"]


def test_a_reference_equal_to_the_gnss_is_flagged_and_its_rms_is_no_accuracy(tmp_path):
    from bgfn.report.tables import kf_table

    d = load_drive(_walk(tmp_path, reference_is_gnss=True))
    assert d.meta["reference_equals_gnss"] and d.meta["reference_check"]["cause"] == "equals_gnss"
    assert d.meta["gnss_offset"]["reference_lag_s"] is None       # such a reference says nothing of the clock
    kf = {"datasets": {"walk": {"rms": {"north": 0.05, "east": 0.05, "down": 0.1, "horizontal": 0.07},
                                "reference_equals_gnss": True, "gnss_updates": 100},
                       "car": {"rms": {"horizontal": 2.0}, "gnss_updates": 100}}}
    t = kf_table(kf)
    assert np.isnan(t.loc["walk", "RMS horizontal (m)"]) and t.loc["car", "RMS horizontal (m)"] == 2.0
    assert t.loc["walk", "reference"] == "the GNSS itself" and t.loc["car", "reference"] == "independent"


def _demo_drive(rest_s: float = 0.0) -> Drive:
    ref = sim.demo_trajectory(120.0, 100.0, rest_s=rest_s)
    gnss = sim.gnss_from_trajectory(ref, 1.0, 0.5, 1.0, [0.0, 0.0, 0.0], seed=4)
    return Drive("demo", ref, sim.imu_from_trajectory(ref), gnss,
                 {"lever_arm_m": [0.0, 0.0, 0.0], "imu_errors": ie.error_params("ekinox-d")})


def test_a_reference_yaw_off_the_course_is_not_the_initial_attitude():
    drive = _demo_drive()
    cfg = baseline.nav_config({"noise_scale": 1.0})
    good = baseline.prepare_filter(drive, cfg)
    assert good.alignment is None and good.reference_attitude["usable"]          # the reference's first row
    assert abs(good.reference_attitude["yaw_minus_course_deg"][0]) < 1.0
    turned = Drive(drive.name, drive.reference.assign(yaw=drive.reference["yaw"] + np.radians(30.0)), drive.imu,
                   drive.gnss, drive.meta)
    setup = baseline.prepare_filter(turned, cfg)
    assert setup.reference_attitude == {**setup.reference_attitude, "usable": False, "reason": "yaw_vs_course"}
    assert setup.reference_attitude["yaw_minus_course_deg"][0] == pytest.approx(30.0, abs=1.0)
    assert setup.alignment is not None                                            # aligned itself instead
    true_yaw = np.interp(setup.initial.time, drive.reference["time"], np.unwrap(drive.reference["yaw"]))
    assert abs(np.degrees(np.angle(np.exp(1j * (setup.alignment.yaw - true_yaw))))) < 3.0
    assert baseline.filter_start(turned, {"noise_scale": 1.0}) == setup.initial.time > drive.reference["time"][0]
    record = setup.record()["reference_attitude"]
    assert record["reason"] == "yaw_vs_course"


def test_a_reference_level_off_the_imus_own_at_rest_is_refused():
    drive = _demo_drive(rest_s=20.0)
    assert check_attitude(drive.reference, drive.imu)["level_minus_imu_deg"] == pytest.approx([0.0, 0.0], abs=0.05)
    tilted = drive.reference.assign(roll=drive.reference["roll"] + np.radians(15.0))
    out = check_attitude(tilted, drive.imu)
    assert not out["usable"] and out["reason"] == "level_vs_imu"
    assert out["level_minus_imu_deg"][0] == pytest.approx(15.0, abs=0.1)


def _rtklib_mirror():
    return next((f for f in (config.PROJECT_ROOT / "data" / "raw",
                             config.PROJECT_ROOT.parent / "shared" / "data" / "rtklib-drive0708")
                 if (f / "imu_1934.csv").is_file()), None)


def test_the_shipped_real_drive_matches_its_reference_and_its_clock_is_left_alone(tmp_path):
    """rtklib-drive0708: the fixes (a degraded copy of the RTK solution) sit on the reference within centimetres of
    median and a few hundredths of a second of lag; through the CSV path with ``gnss_latency_s: auto`` the clock is
    not moved (or by less than 0.05 s)."""
    mirror = _rtklib_mirror()
    if mirror is None:
        pytest.skip("the rtklib-drive0708 files are not available (data/raw or ../shared/data/rtklib-drive0708)")
    drive = load_drive("rtklib-drive0708", profile="quick", mirror=mirror, download=False)
    chk = rc.check_reference(drive.reference, drive.gnss, drive.meta["lever_arm_m"])
    assert abs(chk.lag_s) < 0.05 and chk.lag_std_s < 0.1 and not chk.exceeds and chk.cause is None
    assert abs(chk.along_median_m) < 0.5 and abs(chk.cross_median_m) < 0.5 and not chk.equals_gnss
    folder = write_csv_drive(drive, tmp_path / "car")
    _set_meta(folder, gnss_latency_s="auto")
    o = load_drive(folder).meta["gnss_offset"]
    assert o["status"] != "applied" or abs(o["applied_s"]) < 0.05
    assert abs(o["reference_lag_s"]) < 0.05


def test_fixes_off_the_reference_draw_one_warning_naming_the_likely_cause(tmp_path):
    """0.45 s late (a typed latency of 0; within the load's 0.5 s) puts the fixes about 3.6 m behind: a latency; a
    lever arm 5 m off puts them 5 m ahead whatever the speed: a lever arm or a datum. The words come from report."""
    from bgfn.report.data_checks import reference_lines, reference_warning

    late = load_drive(_clock_log(tmp_path / "late", 0.45, auto=False))
    checks = rc.drive_checks(late)
    assert checks["reference"]["cause"] == "latency" and checks["reference"]["along_median_m"] < -3.0
    assert abs(checks["reference"]["lag_s"] - 0.45) <= 3 * checks["reference"]["lag_std_s"] + 0.01
    text = reference_warning("late", checks)
    assert "clock offset" in text and "gnss_latency_s" in text
    assert rc.drive_checks(late, tolerance_m=5.0)["reference"]["cause"] is None        # the profile's tolerance
    folder = _clock_log(tmp_path / "lever", 0.0, auto=False)
    _set_meta(folder, lever_arm_m=[LEVER[0] - 5.0, LEVER[1], LEVER[2]])
    lever = load_drive(folder)
    checks = rc.drive_checks(lever)
    assert checks["reference"]["cause"] == "lever_arm_or_datum"
    assert checks["reference"]["along_median_m"] == pytest.approx(5.0, abs=0.2)
    assert "lever_arm_m" in reference_warning("lever", checks)
    lines = reference_lines("lever", checks)          # the offsets, then the attitude (checked, still usable)
    assert f"along track median {checks['reference']['along_median_m']:+.2f} m" in lines[0]
    assert "used as the filter's initial attitude" in lines[1]

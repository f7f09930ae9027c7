"""The gallery's logs and the fleet: the phone log (the car drive's first 240 s, its IMU turned and its clock early,
both stated in meta.yaml) prepared as the car log is, on the shipped real drive; a walker refused in a fleet."""

from __future__ import annotations

import numpy as np
import pytest
from synthetic_fleet import fleet_drive

from bgfn import config
from bgfn.data import load_drive
from bgfn.errors import DataError
from bgfn.settings import defaults
from bgfn.studies.fleet import drives as fd
from bgfn.studies.fleet import gallery as FG
from bgfn.studies.gallery import logs as G

FLEET = defaults("fleet")


@pytest.fixture(scope="module")
def check(tmp_path_factory):
    """The gallery's car and phone logs of the shipped drive, written, loaded and prepared with the fleet's
    defaults."""
    mirror = next((f for f in (config.PROJECT_ROOT / "data" / "raw",
                               config.PROJECT_ROOT.parent / "shared" / "data" / "rtklib-drive0708")
                   if (f / "imu_1934.csv").is_file()), None)
    if mirror is None:
        pytest.skip("the rtklib-drive0708 files are not available (data/raw or ../shared/data/rtklib-drive0708)")
    tmp = tmp_path_factory.mktemp("gallery")
    recorded = load_drive(FG.RECORDED, data_dir=tmp / "data", mirror=mirror, download=False)
    return FG.gallery_check(recorded, tmp / "logs", FLEET)


def test_the_phone_prepared_is_the_car_prepared_over_the_same_span(check):
    """The same samples: the loader turns the phone's axes back and moves its rows by the stated clock, so after
    the preparation every number and channel agrees to float rounding (1e-9 of the channel's size; the rows' times
    to 1 us, against the 0.08 s clock and 10 ms rows). A mounting applied twice or a clock of the wrong sign would
    differ by the signal itself (a quarter turn swaps x and y; 0.16 s of driving)."""
    assert check.facts["phone_mounting_deg"] == G.PHONE_MOUNTING_DEG
    assert check.facts["phone_imu_offset_s"] == G.PHONE_IMU_OFFSET_S
    prep = check.preparation.set_index("role")
    car, phone = prep.loc["car_span"], prep.loc["phone"]
    assert [phone[f"mounting_{a}_deg"] for a in ("roll", "pitch", "yaw")] == G.PHONE_MOUNTING_DEG   # as recorded
    assert [car[f"mounting_{a}_deg"] for a in ("roll", "pitch", "yaw")] == [0.0, 0.0, 0.0]
    assert car["standstill_s"] == phone["standstill_s"] > 3.0          # the drive starts standing
    for key in ("tilt_roll_deg", "tilt_pitch_deg", "accel_scale", "gyro_bias_x_dps", "gyro_bias_y_dps",
                "gyro_bias_z_dps", "speed_max_mps", "rate_hz", "cutoff_hz"):
        assert phone[key] == pytest.approx(car[key], rel=1e-9, abs=1e-12), key
    assert check.facts["rows"] == check.facts["car_rows"] and check.facts["max_time_diff_s"] < 1e-6
    assert check.facts["same_span_agrees"]                  # what the page's sentence says rests on this
    assert check.facts["span_s"] == pytest.approx(G.PHONE_DURATION_S, abs=0.02)
    for r in check.agreement.itertuples():
        assert r.same_span_max_diff <= 1e-9 * max(1.0, r.rms), r.channel
    # the speed labels: the same reference, checked against the GNSS speed on the car only (the phone's fixes carry
    # no velocity) and kept whole on both
    assert bool(car["label_checked"]) and not bool(phone["label_checked"])
    assert car["label_kept_share"] == phone["label_kept_share"] == 1.0


def test_the_whole_car_log_differs_from_the_phone_by_its_levelling_alone(check):
    """As a fleet holds them, the whole car log is levelled from all its standstills, the phone from those of its
    240 s: the road's slope where each stood differs, so the prepared channels differ by the tilt (at rest, g times
    the pitch difference on x); once the two levellings, scales and gyro biases are taken out, nothing is left but
    rounding (1e-6, a millionth of g) more than 1 s from the phone's ends (the zero-phase filter's transient)."""
    prep = check.preparation.set_index("role")
    d_pitch = np.radians(prep.loc["car_whole", "tilt_pitch_deg"] - prep.loc["phone", "tilt_pitch_deg"])
    agree = check.agreement.set_index("channel")
    assert prep.loc["car_whole", "standstill_s"] > prep.loc["phone", "standstill_s"]
    assert agree.loc["accel_x", "whole_log_max_diff"] >= 0.9 * FLEET["gravity_mps2"] * abs(np.sin(d_pitch)) > 0.01
    assert (agree["whole_log_rest_max_diff"] <= 1e-6).all()
    assert agree.loc["speed", "whole_log_max_diff"] == 0.0            # one reference, no stretch left out


@pytest.fixture(scope="module")
def walk(tmp_path_factory):
    """The gallery's walker, 60 s (its first stop inside), as a CSV folder."""
    return G.walker_log(tmp_path_factory.mktemp("walker") / "walk", duration_s=60.0)


def test_a_walker_in_a_fleet_is_refused_at_the_profile_check(params, walk):
    from bgfn.profile_schema import load_profile

    for name, body in (("mixed", f"fleet: {{drives: [rtklib-drive0708, {walk}]}}"),
                       ("walkers", f"fleet: {{drives: [{walk}], pieces: 3}}")):
        (params / f"{name}.yaml").write_text(f"profile: {name}\nbase: smoke\ndescription: x\n{body}\n")
        with pytest.raises(DataError) as err:
            load_profile(name)
        assert err.value.source == str(params / f"{name}.yaml") and err.value.field == "fleet.drives"
        assert "drive 'walk' with platform: walker" in str(err.value) and "non-holonomic constraint" in str(err.value)
        assert "rtklib-drive0708" not in err.value.found                 # the car is not the one refused


def test_a_walker_in_a_fleet_is_refused_before_any_preparation(walk):
    """Where the profile check could not read the platform (the drives handed over, or a loader of its own), the
    loaded drives' platforms are checked before anything is prepared."""
    walker = load_drive(walk)
    car = fleet_drive("drive 1", duration=60.0, seed=1)
    with pytest.raises(DataError, match=r"fleet\.drives.*drive 'walk' with platform: walker"):
        fd.prepare_fleet([car, walker], FLEET)
    loaded = []

    def loader(name, profile=None):
        loaded.append(name)
        return walker if name == "w" else car
    with pytest.raises(DataError, match="drive 'walk' with platform: walker"):
        fd.fleet_drives({"drives": ["c", "w"]}, loader=loader)
    with pytest.raises(DataError, match="drive 'walk' with platform: walker"):
        fd.fleet_drives({"drives": [str(walk)], "pieces": 3}, loader=lambda n, profile=None: pytest.fail("loaded"))
    assert fd.platform_refusal({"a": "car", "b": None}) is None      # a platform not known yet: the loader's to say
    assert fd.platform_refusal({"o": "other"}) is not None            # no motion model: no NHC either


def test_the_gallery_check_is_said_as_one_drive_and_a_walk_not_a_fleet(check):
    from bgfn.report.fleet_words import gallery_lines, gallery_tables

    lines = gallery_lines(check)
    prep = check.preparation.set_index("role")
    d_pitch = prep.loc["car_whole", "tilt_pitch_deg"] - prep.loc["phone", "tilt_pitch_deg"]
    assert "one drive and a walk, not a fleet" in lines[0] and "a fleet refuses it (fleet.drives" in lines[0]
    assert "undoes a phone's mounting and clock" in lines[1] and "(0, 0, -90) deg" in lines[0]
    assert f"{d_pitch:+.2f} deg in pitch" in lines[2]
    numbers, agreement = gallery_tables(check)
    assert list(numbers.columns) == ["car log, over the phone's span", "phone log", "car log, whole drive"]
    assert len(agreement) == 7 and numbers.loc["mounting_yaw_deg", "phone log"] == G.PHONE_MOUNTING_DEG[2]

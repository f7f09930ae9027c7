"""Standalone-INS drift over the sweep's starts (bgfn.studies.ins_fidelity.ins_drift), on a small synthetic drive."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from bgfn import evaluate as ev, studies
from bgfn.profile_schema import load_profile, with_overrides
from bgfn.data import Drive
from bgfn.report import ins_fidelity_words
from synthetic_drive import demo_drive



def _drive(name: str, imu: str, seed: int = 3) -> Drive:
    """The demo trajectory with a tactical (``ekinox-d``) or a consumer MEMS (``mpu6000``) IMU."""
    return demo_drive(name, 150.0, 5.0, seed, imu=imu, overrides=None)


@pytest.fixture(scope="module")
def cfg():
    return with_overrides(load_profile("smoke"), {
        "evaluate.sweep.n_starts": 3, "evaluate.sweep.folds": 1, "evaluate.sweep.durations_s": [5.0, 10.0],
        "evaluate.sweep.warmup_s": 20.0})


@pytest.fixture(scope="module")
def runs(cfg):
    return studies.ins_fidelity.ins_drift_runs(cfg, [_drive("calm", "ekinox-d"), _drive("rough", "mpu6000")])


def test_every_start_duration_and_method_once_and_prefixes_never_exceed_the_whole_run(cfg, runs):
    starts = studies.ins_fidelity.drift_starts(cfg, _drive("calm", "ekinox-d"))
    # the sweep's starts: evenly spread from the warm-up on, room for the longest duration at the end
    assert len(starts) == 3 and starts[0] >= 20.0 and starts[-1] + 10.0 <= 150.0
    assert np.diff(starts) == pytest.approx([starts[1] - starts[0]] * 2, abs=0.1)
    assert len(runs) == 2 * 3 * 2 * 2                     # drives x starts x durations x (INS, INS+NHC)
    assert set(runs["method"]) == {"INS", "INS+NHC"} and sorted(runs["start_s"].unique()) == starts
    wide = runs.pivot_table(index=["dataset", "start_s", "method"], columns="duration_s", values="max_h_m")
    assert (wide[10.0] >= wide[5.0]).all()                # the 5 s run is the 10 s run's prefix


def test_a_consumer_mems_imu_drifts_further_than_a_tactical_one_and_the_summary_is_the_median(runs):
    summary = studies.ins_fidelity.drift_summary(runs)
    assert list(summary.columns) == list(studies.ins_fidelity.DRIFT_COLUMNS) and (summary["n_starts"] == 3).all()
    level = summary.set_index(["dataset", "duration_s", "method"])["median_max_h_m"]
    assert level[("rough", 10.0, "INS")] > 2.0 * level[("calm", 10.0, "INS")]
    sel = runs[(runs["dataset"] == "rough") & (runs["duration_s"] == 10.0) & (runs["method"] == "INS")]
    assert level[("rough", 10.0, "INS")] == pytest.approx(np.median(sel["max_h_m"]))


def test_sentences_put_the_stand_in_beside_the_recorded_drive():
    summary = pd.DataFrame({"dataset": ["sim", "real", "sim", "real"], "test": ["field", "real"] * 2,
                            "duration_s": [30.0] * 4, "method": ["INS", "INS", "INS+NHC", "INS+NHC"],
                            "n_starts": [20, 18, 20, 18], "median_max_h_m": [10.0, 40.0, 4.0, 6.0],
                            "q25_max_h_m": [0.0] * 4, "q75_max_h_m": [0.0] * 4})
    lines = ins_fidelity_words.drift_sentences(summary, stand_in="sim", recorded="real")
    assert lines == ["30 s outages, median max horizontal error over up to 20 starts: INS 10.0 m on the stand-in "
                     "sim, 40.0 m on the recorded drive real (4.0 times); INS+NHC 4.0 m on the stand-in sim, 6.0 m "
                     "on the recorded drive real (1.5 times)",
                     "The stand-in's standalone INS drifts outside a factor 1.5 of the recorded drive's at 30 s (4.00) "
                     "(recorded over stand-in)."]
    assert ins_fidelity_words.drift_sentences(summary, stand_in="sim", recorded="absent") == []
    # INS 1.4 times (within 1.5): the verdict turns; INS+NHC plays no part in it
    summary.loc[1, "median_max_h_m"] = 14.0
    assert ins_fidelity_words.drift_sentences(summary, stand_in="sim", recorded="real")[-1] == (
        "The stand-in's standalone INS drifts within a factor 1.5 of the recorded drive's at every duration.")


def test_the_drives_give_the_same_rows_spread_over_two_processes(cfg, runs):
    from bgfn.parallel import Runner

    lines = []
    two = studies.ins_fidelity.ins_drift_runs(cfg, [_drive("calm", "ekinox-d"), _drive("rough", "mpu6000")], report=lines.append,
                            runner=Runner(2))
    assert two.to_csv(index=False) == runs.to_csv(index=False)            # row for row, the drives' order kept
    assert len(lines) == 2 and all(line.startswith("[INS drift] ") and "3 starts x 2 durations" in line
                                   for line in lines)

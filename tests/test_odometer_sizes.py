"""The odometers at another model size, recorded from another machine (bgfn.studies.odometer.sizes) and read by the
verdict's odometer answer (bgfn.report.odometer_verdict.size_sentence)."""

import json

import numpy as np
import pandas as pd
import pytest

from bgfn import config
from bgfn.__main__ import main
from bgfn.config import SHARED_TABLES
from bgfn.errors import DataError
from bgfn.studies.odometer import sizes as S
from bgfn.studies.odometer.bars import NETWORK_COLUMNS, SUMMARY_COLUMNS
from bgfn.report.odometer_verdict import OdometerInputs, size_sentence

DURATIONS = (30.0, 60.0)


def _summary(nhc: dict, odo: dict, mlp: dict, p_odo: float = 0.01, p_mlp: float = 0.2) -> pd.DataFrame:
    rows = []
    for d in DURATIONS:
        rows += [{"dataset": "car", "duration_s": d, "method": "INS+NHC", "sigma_mps": np.nan, "max_h_m": nhc[d],
                  "ratio_to_nhc": 1.0, "speed_rmse_mps": np.nan, "coverage_2sigma": np.nan, "runs": 20,
                  "p_vs_nhc": np.nan},
                 {"dataset": "car", "duration_s": d, "method": "BGFN-ODO", "sigma_mps": np.nan, "max_h_m": odo[d],
                  "ratio_to_nhc": odo[d] / nhc[d], "speed_rmse_mps": 2.0 + d / 100, "coverage_2sigma": 0.7,
                  "runs": 60, "p_vs_nhc": p_odo},
                 {"dataset": "car", "duration_s": d, "method": "MLP-ODO", "sigma_mps": np.nan, "max_h_m": mlp[d],
                  "ratio_to_nhc": mlp[d] / nhc[d], "speed_rmse_mps": 3.0, "coverage_2sigma": 0.8, "runs": 60,
                  "p_vs_nhc": p_mlp},
                 {"dataset": "car", "duration_s": d, "method": "ORACLE-SPEED", "sigma_mps": 0.5, "max_h_m": 1.0,
                  "ratio_to_nhc": 0.1, "speed_rmse_mps": 0.5, "coverage_2sigma": 0.95, "runs": 20, "p_vs_nhc": 1e-4}]
    return pd.DataFrame(rows, columns=list(SUMMARY_COLUMNS))


def _finished_run(root, profile: str, summary: pd.DataFrame) -> None:
    """What `python -m bgfn odometers --profile <profile>` leaves under results/<profile>/."""
    tables = root / profile / "tables"
    tables.mkdir(parents=True)
    summary.to_csv(tables / SHARED_TABLES["odometer_summary"], index=False)
    nets = pd.DataFrame([{"dataset": "car", "method": "BGFN-ODO", "fold": 0, "seed": 0, "lr": 5e-4, "epochs": 60,
                          "val_rmse_mps": 1.5, "calibration": 1.2, "outage_speed_rmse_mps": 2.7,
                          "outage_coverage_2sigma": 0.7}], columns=list(NETWORK_COLUMNS))
    nets.to_csv(tables / SHARED_TABLES["odometer_networks"], index=False)
    (root / profile / S.RUN_FACTS).write_text(json.dumps(
        {"profile": profile, "size": "paper", "inputs": "band_frames", "epochs_max": 1000, "batch_size": 8,
         "device": "GPU X", "wall_s": 100.0, "date": "2026-01-01", "commit": "abc1234"}))


def test_record_keeps_a_run_without_the_oracle_grid_and_replaces_only_its_own_profile(monkeypatch, tmp_path):
    monkeypatch.setattr(config, "RESULTS_ROOT", tmp_path / "results")
    measured, nets = tmp_path / "sizes.csv", tmp_path / "sizes_networks.csv"
    with pytest.raises(DataError, match="odometer_run.json.*python -m bgfn odometers --profile paper"):
        S.record("paper", measured=measured, measured_networks=nets)   # nothing has run: one clear error
    assert not measured.exists()
    nhc = {30.0: 10.0, 60.0: 20.0}
    _finished_run(tmp_path / "results", "paper", _summary(nhc, {30.0: 15.0, 60.0: 40.0}, {30.0: 12, 60.0: 30}))
    _finished_run(tmp_path / "results", "full", _summary(nhc, {30.0: 11.0, 60.0: 25.0}, {30.0: 12, 60.0: 30}))
    S.record("full", "other", measured=measured, measured_networks=nets)
    S.record("paper", "first", measured=measured, measured_networks=nets)
    S.record("paper", "again", measured=measured, measured_networks=nets)          # replaces paper's rows
    table = pd.read_csv(measured)
    assert list(table.columns) == [*S.RUN_COLUMNS, *SUMMARY_COLUMNS, "note"]
    assert sorted(table.groupby("profile").size().items()) == [("full", 6), ("paper", 6)]   # 3 rows x 2 durations
    assert "ORACLE-SPEED" not in set(table["method"])
    paper = table[table["profile"] == "paper"]
    assert set(paper["note"]) == {"again"} and set(paper["device"]) == {"GPU X"} and set(paper["commit"]) == {"abc1234"}
    assert paper.set_index(["method", "duration_s"]).loc[("BGFN-ODO", 60.0), "max_h_m"] == 40.0
    assert len(pd.read_csv(nets)) == 2


def test_the_run_facts_name_the_commit_given_by_the_environment_first(monkeypatch, tmp_path):
    monkeypatch.setattr(config, "RESULTS_ROOT", tmp_path)
    monkeypatch.setenv("BGFN_COMMIT", "feed123")     # a copy on another machine: its git, if any, is not ours
    cfg = {"evaluate": {"sweep": {"train": {"size": "paper"}},
                        "odometer": {"train": {"optimizer": {"epochs": 1000, "batch_size": 8}}, "correlation": False}}}
    cfg["evaluate"]["odometer"]["inputs"] = "imu"
    facts = json.loads(S.write_run_facts("paper", cfg, 0.0, "1 job").read_text())
    assert (facts["commit"], facts["size"], facts["inputs"], facts["epochs_max"], facts["batch_size"],
            facts["correlation"]) == ("feed123", "paper", "imu", 1000, 8, False)


def test_the_command_line_records_only_a_finished_run(monkeypatch, tmp_path, capsys):
    monkeypatch.setattr(config, "RESULTS_ROOT", tmp_path)
    assert main(["odometers", "--profile", "paper", "--record"]) == 2
    assert "odometer_run.json" in capsys.readouterr().err


def _here(nhc):
    return OdometerInputs(None, _summary(nhc, {30.0: 12.0, 60.0: 30.0}, {30.0: 12, 60.0: 30})
                          .assign(speed_rmse_mps=2.5), None)


def _sized(nhc, odo, mlp, **kw):
    s = _summary(nhc, odo, mlp, **kw)
    s = s[s["method"] != "ORACLE-SPEED"]
    return pd.concat([pd.DataFrame({"profile": "paper-odometer", "size": "paper", "inputs": "imu", "epochs_max": 1000,
                                    "batch_size": 8, "device": "GPU X", "wall_s": 100.0, "date": "2026-01-01",
                                    "commit": "abc1234"}, index=s.index), s], axis=1)


def test_the_size_sentence_pairs_only_the_same_windows_and_says_whether_a_network_wins():
    nhc = {30.0: 10.0, 60.0: 20.0}
    here = _here(nhc)
    assert size_sentence(here, DURATIONS) == ""                                   # nothing recorded
    here.sized = _sized(nhc, {30.0: 15.0, 60.0: 40.0}, {30.0: 12.0, 60.0: 30.0})
    text = size_sentence(here, DURATIONS)
    assert text.startswith(" Is it the model size? At the paper size, reading the raw IMU samples (profile "
                           "`paper-odometer`: up to 1000 epochs, "
                           "batch 8; run on GPU X on 2026-01-01 at commit abc1234")
    # recorded without a correlation column: fused as white, and the sentence says so
    assert ("in the same windows as here (fused as white errors, R = std^2: recorded before "
            "`evaluate.odometer.correlation`), INS+NHC 10.0/20.0 m, BGFN-ODO 15.0/40.0 m") in text
    assert "speed RMSE 2.60 m/s at 60 s against 2.50 m/s here" in text
    # the best of the 2 learned odometers recorded: Holm over BGFN-ODO's 0.01 and MLP-ODO's 0.2 (0.02, 0.2)
    assert text.endswith("its best network at 60 s, MLP-ODO (30.0 m), does not beat INS+NHC significantly (best of 2, "
                         "Holm-corrected p 0.2, raw 0.2).")
    # other windows (INS+NHC 5 % off), and a network that beats INS+NHC there
    here.sized = _sized({30.0: 10.5, 60.0: 21.0}, {30.0: 8.0, 60.0: 15.0}, {30.0: 12.0, 60.0: 30.0}, p_odo=0.001)
    here.sized = here.sized.assign(correlation=True)                          # fused with its correlation
    text = size_sentence(here, DURATIONS)
    assert "in its own windows, INS+NHC 10.5/21.0 m" in text
    assert text.endswith("its best network at 60 s, BGFN-ODO (15.0 m), beats INS+NHC (best of 2, Holm-corrected p "
                         "0.002, raw 0.001).")

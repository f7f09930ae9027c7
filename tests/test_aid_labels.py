"""The tables' rows are named by the aids that ran: a walker's ``INS+ZUPT`` (no NHC ran), a car's ``INS+NHC`` byte
for byte as before; the code reads them back with its own keys."""

from __future__ import annotations

import json

import pandas as pd
import pytest

from bgfn import row_labels
from bgfn.config import RUN_RECORDS
from bgfn.data import load_drive
from bgfn.data.platforms import recorded_platforms, write_ran_table
from bgfn.io import atomic_write_csv
from bgfn.nav import baseline
from bgfn.nav.outages import outage_windows
from bgfn.profile_schema import load_profile
from bgfn.report.reading import read_csv
from bgfn.studies.gallery import logs as G

WALKER, CAR, OTHER = ("ZUPT",), ("NHC", "ZUPT"), ()


def test_a_label_names_the_aids_that_ran_and_reads_back_as_the_codes_key():
    assert row_labels.ran_label("INS+NHC", WALKER) == "INS+ZUPT" and row_labels.ran_label("BGFN+NHC", WALKER) == "BGFN+ZUPT"
    assert row_labels.ran_label("INS+NHC+HOLD", WALKER) == "INS+ZUPT+HOLD"
    assert row_labels.ran_label("INS+NHC_east_m", WALKER) == "INS+ZUPT_east_m"        # a column of the paper layout
    assert row_labels.ran_label("INS+NHC", OTHER) == "INS+no aid" and row_labels.ran_label("INS", WALKER) == "INS"
    assert row_labels.ran_label("INS+NHC", CAR) == "INS+NHC"                            # NHC ran: the project's label
    for label in ("INS+NHC", "BGFN+NHC", "AT-LSTM+NHC", "Transformer+NHC", "INS+NHC+HOLD", "MLP+NHC_north_m"):
        for aids in (WALKER, OTHER, CAR):
            assert row_labels.key_label(row_labels.ran_label(label, aids)) == label
    # text that is no written row label stays as it is
    for text in ("NHC+ZUPT", "ORACLE-SPEED+WALK", "the +ZUPT rows", "RIDGE-ODO", "BGFN-ODO-ENS"):
        assert row_labels.key_label(text) == text


def _rows(datasets) -> pd.DataFrame:
    return pd.DataFrame({"dataset": datasets, "method": ["INS", "INS+NHC", "BGFN+NHC", "INS+NHC+HOLD"][:len(datasets)],
                         "max_h_m": [10.25, 4.5, 3.125, 7.0][:len(datasets)]})


def test_a_cars_table_is_written_byte_for_byte_as_before(tmp_path):
    out = tmp_path / "results"
    (out / "tables").mkdir(parents=True)
    (out / RUN_RECORDS["kf_baseline"]).write_text(json.dumps(
        {"datasets": {"rtklib-drive0708": {"constraints": {"platform": "car"}}}}))
    frame = _rows(["rtklib-drive0708"] * 4)
    assert row_labels.ran_labels(frame, CAR) is frame           # nothing copied or touched
    write_ran_table(out / "tables" / "ran.csv", frame, out, float_format="%.4f")
    atomic_write_csv(out / "tables" / "plain.csv", frame, float_format="%.4f")
    assert (out / "tables" / "ran.csv").read_bytes() == (out / "tables" / "plain.csv").read_bytes()
    # before notebook 02 recorded anything, a drive reads as the default platform (a car)
    (out / RUN_RECORDS["kf_baseline"]).unlink()
    write_ran_table(out / "tables" / "unrecorded.csv", frame, out, float_format="%.4f")
    assert (out / "tables" / "unrecorded.csv").read_bytes() == (out / "tables" / "plain.csv").read_bytes()


def test_a_table_of_a_walk_and_a_drive_names_each_rows_aids_and_reads_back(tmp_path):
    out = tmp_path / "results"
    (out / "tables").mkdir(parents=True)
    (out / RUN_RECORDS["kf_baseline"]).write_text(json.dumps(
        {"datasets": {"walk": {"constraints": {"platform": "walker"}}, "car": {"constraints": None}}}))
    assert recorded_platforms(out) == {"walk": "walker", "car": "car"}
    frame = pd.concat([_rows(["walk"] * 4), _rows(["car"] * 4)], ignore_index=True)
    path = write_ran_table(out / "tables" / "mixed.csv", frame, out, float_format="%.4f")
    written = pd.read_csv(path)
    assert list(written["method"]) == ["INS", "INS+ZUPT", "BGFN+ZUPT", "INS+ZUPT+HOLD",
                                       "INS", "INS+NHC", "BGFN+NHC", "INS+NHC+HOLD"]
    assert "+NHC" not in path.read_text().split("\ncar,")[0]          # no NHC on any row of the walk
    pd.testing.assert_frame_equal(read_csv(path), frame)               # the report reads the code's keys


@pytest.fixture(scope="module")
def walk_baseline(tmp_path_factory):
    folder = G.walker_log(tmp_path_factory.mktemp("walk") / "my walk")
    drive = load_drive(folder)
    cfg = load_profile("own-walker")
    return baseline.run_baseline(drive, baseline.nav_config(cfg["nav"]), outage_windows(cfg, drive, str(folder)))


def test_a_walkers_baseline_tables_say_zupt_where_no_nhc_ran(walk_baseline, tmp_path):
    b = walk_baseline
    assert b.constraints["platform"] == "walker" and b.constraints["zupt_epochs"] > 0
    assert "INS+NHC" in set(b.outage_table["method"])                  # the code's key, as everywhere
    baseline.save_baseline(b, tmp_path, "walk")
    tables = tmp_path / "tables"
    for name in ("kf_outage_metrics_walk.csv", "kf_outage_errors_walk.csv", "kf_outage_max_errors_walk.csv"):
        text = (tables / name).read_text()
        assert "+NHC" not in text and "INS+ZUPT" in text, name
    assert "INS+ZUPT_east_m" in pd.read_csv(tables / "kf_outage_max_errors_walk.csv").columns
    metrics = read_csv(tables / "kf_outage_metrics_walk.csv")
    assert list(metrics["method"]) == list(b.outage_table["method"])   # read back with the code's keys


def test_the_results_pages_sweep_table_names_a_walkers_rows_by_its_zupt(tmp_path):
    from types import SimpleNamespace

    from bgfn.config import SHARED_TABLES
    from bgfn.report.sections import sweep_section

    out = tmp_path / "results"
    (out / "tables").mkdir(parents=True)
    (out / RUN_RECORDS["kf_baseline"]).write_text(json.dumps(
        {"datasets": {"walk": {"constraints": {"platform": "walker"}}, "car": {"constraints": {"platform": "car"}}}}))
    summary = pd.DataFrame([{"dataset": d, "duration_s": 10.0, "method": m, "n": 4, "n_starts": 4, "median_m": 5.0,
                             "ci_lo_m": 4.0, "ci_hi_m": 6.0} for d in ("walk", "car") for m in ("INS", "INS+NHC")])
    path = write_ran_table(out / "tables" / SHARED_TABLES["sweep_summary"], summary, out, float_format="%.4f")
    res = SimpleNamespace(profile="p", out=out, sweep=read_csv(path), sweep_pairs=None, evaluation=None,
                          sweep_record=None, current={}, table=lambda name: out / "tables" / name)
    shown = sweep_section(res)[0].data                                   # the table the page styles
    assert sorted(shown.index) == [("car", "INS"), ("car", "INS+NHC"), ("walk", "INS"), ("walk", "INS+ZUPT")]


def test_a_walk_that_notebook_02_did_not_run_is_named_by_its_own_meta(tmp_path):
    folder = G.walker_log(tmp_path / "my walk")                  # meta.yaml: platform walker
    out = tmp_path / "results"
    (out / "tables").mkdir(parents=True)
    frame = _rows([str(folder)] * 4)
    path = write_ran_table(out / "tables" / "walk.csv", frame, out)
    assert list(pd.read_csv(path)["method"]) == ["INS", "INS+ZUPT", "BGFN+ZUPT", "INS+ZUPT+HOLD"]


# --------------------------------------------------------------------- what the notebooks display and print
def test_a_walkers_displayed_frames_and_sentences_name_the_aids_that_ran(walk_baseline):
    from bgfn.report.aid_words import ran_frame, ran_lines
    from bgfn.report.nav_words import baseline_aid_lines

    platforms = {"walk": "walker", "car": "car"}
    frame = pd.concat([_rows(["walk"] * 4), _rows(["car"] * 4)], ignore_index=True)
    shown = ran_frame(frame, platforms)                                 # rows by their dataset column
    assert list(shown["method"]) == ["INS", "INS+ZUPT", "BGFN+ZUPT", "INS+ZUPT+HOLD",
                                     "INS", "INS+NHC", "BGFN+NHC", "INS+NHC+HOLD"]
    wide = frame.set_index(["dataset", "method"])                       # rows by their index level
    assert list(ran_frame(wide, platforms).index) == [(d, m) for d, m in zip(shown["dataset"], shown["method"])]
    layout = baseline.ins_layout(walk_baseline.outage_table, "walk")   # notebook 02's layout: +NHC in the columns
    assert any("+NHC" in str(c) for c in layout.columns.to_flat_index())
    shown = ran_frame(layout, "walker")
    assert not any("+NHC" in str(c) for c in shown.columns.to_flat_index())
    assert any("INS+ZUPT" in str(c) for c in shown.columns.to_flat_index())
    assert shown.to_numpy().tobytes() == layout.to_numpy().tobytes()   # the numbers as they were
    for car in (frame, layout):
        assert ran_frame(car, "car") is car and ran_frame(car, {"car": "car"}) is car   # a car's display untouched
    lines = ["walk, 10 s: INS+NHC 4.5 m, BGFN+NHC 3.1 m", "walk-2 (real test): INS+NHC 1 m", "car, BGFN+NHC 2 m",
             "every drive: INS+NHC"]
    assert ran_lines(lines, {**platforms, "walk-2": "car"}) == [
        "walk, 10 s: INS+ZUPT 4.5 m, BGFN+ZUPT 3.1 m", "walk-2 (real test): INS+NHC 1 m", "car, BGFN+NHC 2 m",
        "every drive: INS+NHC"]                                          # a line of no one drive: mixed, as it is
    assert ran_lines(["every drive: INS+NHC"], {"walk": "walker"}) == ["every drive: INS+ZUPT"]
    (aids,) = baseline_aid_lines(walk_baseline)                        # notebooks 02 and 09 print it
    assert "INS+ZUPT rows' aids" in aids and "+NHC" not in aids


def test_the_sweep_setup_line_names_the_rows_of_the_drives_platforms():
    from bgfn.report.sweep_words import describe_sweep_setup

    cfg = load_profile("smoke")
    ecfg = {**cfg["evaluate"], "methods": ["bgfn"], "nhc_rows": True}
    car = describe_sweep_setup(cfg["train"], ecfg, ["rtklib-drive0708"])
    assert car == describe_sweep_setup(cfg["train"], ecfg, ["rtklib-drive0708"], {"rtklib-drive0708": "car"})
    assert car[-1].endswith("rows INS+NHC, BGFN+NHC")                 # a car's line as before
    walk = describe_sweep_setup(cfg["train"], ecfg, ["walk"], {"walk": "walker"})
    assert walk[1:-1] == car[1:-1] and "+NHC" not in walk[-1] and walk[-1].endswith("rows INS+ZUPT, BGFN+ZUPT")
    both = describe_sweep_setup(cfg["train"], ecfg, ["walk", "car"], {"walk": "walker", "car": "car"})
    assert both[-2:] == [car[-1], walk[-1]]

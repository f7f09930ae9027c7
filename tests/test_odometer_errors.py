"""A learned odometer's speed error split into an offset per outage and a fluctuation (bgfn.studies.odometer.errors),
and the verdict's sentence on it."""

import numpy as np
import pandas as pd
import pytest

from bgfn.studies.odometer.errors import ERROR_COLUMNS, error_parts_table, offset_bar_mps, plot_error_parts
from bgfn.report.odometer_words import error_parts_lines
from bgfn.report.odometer_verdict import OdometerInputs, fusion_words, offset_sentence


def _series():
    """Two 60 s outages on a 1 Hz grid; an odometer off by +1 m/s in the first and -1 m/s in the second (offsets
    only), one whose error flips sign every epoch (fluctuation only), NaN outside the outages."""
    t = np.arange(0.0, 300.0)
    truth = 10.0 + np.sin(t / 20.0)
    inside = ((t > 50) & (t <= 110)) | ((t > 200) & (t <= 260))
    first = t <= 150
    offset = np.where(inside, truth + np.where(first, 1.0, -1.0), np.nan)
    flip = np.where(inside, truth + np.where(t % 2 == 0, 0.5, -0.5), np.nan)
    ones = np.where(inside, 1.0, np.nan)
    return {"time": t, "truth": truth, "outages": [(50.0, 60.0), (200.0, 60.0)],
            "tracks": {"OFF-ODO": (offset, ones), "FLIP-ODO": (flip, ones)}}


def test_an_offset_per_outage_and_a_fluctuation_by_hand():
    table = error_parts_table("d", _series(), [30.0, 120.0])
    assert list(table.columns) == list(ERROR_COLUMNS) and len(table) == 4
    off = table[(table["method"] == "OFF-ODO") & (table["duration_s"] == 30.0)].iloc[0]
    # +1 and -1: RMS offset 1, nothing around it; rho = 1 at lags 1 ... 10 s (30 epochs: >= 20 pairs) -> 21
    assert off["offset_rms_mps"] == pytest.approx(1.0) and off["fluctuation_mps"] == pytest.approx(0.0, abs=1e-12)
    assert off["outage_correlation"] == pytest.approx(21.0) and off["outages"] == 2
    flip = table[(table["method"] == "FLIP-ODO") & (table["duration_s"] == 30.0)].iloc[0]
    # +-0.5 every other epoch: no offset, a fluctuation of 0.5, rho_1 = -1: white or better, kappa 1
    assert flip["offset_rms_mps"] == pytest.approx(0.0, abs=1e-12) and flip["fluctuation_mps"] == pytest.approx(0.5)
    assert flip["outage_correlation"] == 1.0 and flip["speed_rmse_mps"] == pytest.approx(0.5)
    # a duration past the outages' end scores what they have (60 epochs each)
    long = table[(table["method"] == "OFF-ODO") & (table["duration_s"] == 120.0)].iloc[0]
    assert long["offset_rms_mps"] == pytest.approx(1.0)
    line = error_parts_lines(table)[0]
    assert line.startswith("d, the first 30 s of each outage:") and "OFF-ODO 1.00 and 0.00 m/s (kappa 21.0)" in line
    assert error_parts_table("d", None, [30.0]).empty and error_parts_lines(table.iloc[:0]) == []


def test_the_offset_bar_and_the_verdicts_sentence():
    assert offset_bar_mps(20.4, 60.0) == pytest.approx(0.34)
    summary = pd.DataFrame([{"dataset": "d", "duration_s": 60.0, "method": "INS+NHC", "sigma_mps": np.nan,
                             "max_h_m": 30.0}])
    errors = pd.DataFrame([{"dataset": "d", "method": "BGFN-ODO", "duration_s": 60.0, "outages": 20,
                            "speed_rmse_mps": 2.5, "offset_rms_mps": 1.3, "fluctuation_mps": 2.0,
                            "outage_correlation": 4.0}])
    networks = pd.DataFrame({"method": ["BGFN-ODO"] * 3 + ["MLP-ODO"], "correlation": [5.0, 7.0, 9.0, 1.0]})
    odo = OdometerInputs(None, summary, None, errors=errors, networks=networks)
    text = offset_sentence(odo, 60.0)
    assert "BGFN-ODO's speed is off by 1.30 m/s on average" in text
    assert "more than 0.50 m/s costs as much as INS+NHC's whole 30.0 m in 60 s" in text     # 30 m / 60 s
    assert "fluctuates by 2.00 m/s" in text and "one in 4.0 epochs, against 7.0 on its validation windows" in text
    assert offset_sentence(odo, 30.0) == "" and offset_sentence(OdometerInputs(None, summary, None), 60.0) == ""


def test_a_recorded_run_says_how_its_odometers_were_fused():
    assert fusion_words(True) == "" and fusion_words(np.bool_(True)) == ""
    assert fusion_words(False) == " (fused as white errors, R = std^2)"
    assert "recorded before" in fusion_words(np.nan) and "recorded before" in fusion_words(None)


def test_the_figure_has_a_panel_per_duration_and_the_bar_where_it_is_known():
    table = error_parts_table("d", _series(), [30.0, 60.0])
    fig = plot_error_parts(table, "d", {60.0: offset_bar_mps(30.0, 60.0)})
    axes = fig.axes
    assert len(axes) == 2 and [len(ax.patches) for ax in axes] == [4, 4]         # 2 odometers x (offset, fluctuation)
    dashed = [[ln for ln in ax.get_lines() if ln.get_linestyle() == "--"] for ax in axes]
    assert [len(d) for d in dashed] == [0, 1] and dashed[1][0].get_ydata()[0] == pytest.approx(0.5)

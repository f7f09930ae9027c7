"""A learned odometer's predicted std against its speed error (bgfn.studies.odometer.uncertainty)."""

import numpy as np
import pytest

from bgfn.report.odometer_words import uncertainty_lines
from bgfn.studies.odometer.uncertainty import ranks_errors, uncertainty_table


def _series(informative: bool):
    rng = np.random.default_rng(0)
    n = 400
    truth = np.full(n, 10.0)
    std = np.linspace(0.2, 2.0, n)                                   # a std that changes from epoch to epoch
    scale = std if informative else std[::-1]                        # errors of size std, or of the reverse
    speed = truth + scale * rng.standard_normal(n)
    speed[:5] = np.nan                                               # outside the outages
    ridge = (truth + rng.standard_normal(n), np.full(n, 1.0))        # one std for all epochs: nothing to rank
    return {"truth": truth, "tracks": {"NET-ODO": (speed, std), "RIDGE-ODO": ridge}}


def test_an_informative_std_ranks_the_errors_and_a_reversed_one_does_not():
    good = uncertainty_table("d", _series(True))
    assert set(good["method"]) == {"NET-ODO"}                        # the constant std is left out
    assert list(good["group"]) == [1, 2, 3, 4] and good["epochs"].sum() == 395
    assert good["std_lo_mps"].is_monotonic_increasing
    rmse = good["speed_rmse_mps"].to_numpy()
    # errors of std s in each quarter: RMSE ~ the quarter's typical s (0.2-0.65 m/s ... 1.55-2.0 m/s)
    assert rmse[0] == pytest.approx(0.44, abs=0.1) and rmse[-1] == pytest.approx(1.8, abs=0.25)
    assert ranks_errors(good) and good["corr_abs_error_std"].iloc[0] > 0.3
    assert all(good["coverage_2sigma"] > 0.85)                       # each speed within 2 of its own sigma
    bad = uncertainty_table("d", _series(False))
    assert not ranks_errors(bad) and bad["corr_abs_error_std"].iloc[0] < -0.3
    assert bad["coverage_2sigma"].iloc[0] < 0.5                      # smallest std, largest errors
    line = uncertainty_lines(bad)[0]
    assert line.startswith("NET-ODO, d: its predicted std does not rank its errors in the outages")
    assert "the quarter of its epochs with the smallest std (0.22-" in line   # the first 5 epochs lie outside
    assert uncertainty_lines(good)[0].startswith("NET-ODO, d: its predicted std ranks its errors")


def test_no_series_or_no_varying_std_gives_an_empty_table():
    assert uncertainty_table("d", None).empty
    assert uncertainty_table("d", {"truth": np.ones(3), "tracks": {"R": (np.ones(3), np.ones(3))}}).empty
    assert uncertainty_lines(uncertainty_table("d", None)) == []

"""Beyond the paper: many outage starts and durations instead of two, and what the increments must achieve.

Two outages cannot rank methods. The sweep (:mod:`~bgfn.studies.outage_sweep.sweep`) spreads outage starts over a
drive, trains each fold's networks without its outages and evaluates every method in them, with bootstrap
intervals and paired tests; the oracle (:mod:`~bgfn.studies.outage_sweep.oracle`) replaces a network by the true
increments plus noise (:mod:`~bgfn.studies.outage_sweep.increments`) to find the accuracy at which a pseudo-GPS fix
beats INS+NHC; :mod:`~bgfn.studies.outage_sweep.variant_outages` trains and evaluates the learning-problem variants
(velocity inputs, a leaky protocol) in the paper's two outages.
"""

from bgfn.studies.outage_sweep.increments import AntennaTruth, increment_errors, increment_rmse
from bgfn.studies.outage_sweep.oracle import (BREAKEVEN_COLUMNS, ORACLE_COLUMNS, NoSweepStarts, OracleIncrements,
                                              OracleResult, breakeven_table, crossing_sigma, curve_at, method_levels,
                                              oracle_interval_table, oracle_runs, oracle_table, oracle_windows,
                                              plot_oracle, run_oracle)
from bgfn.studies.outage_sweep.sweep import (pairs_style, profile_sweep_plan, run_sweep, run_sweeps, sweep_comparisons,
                                             sweep_interval_table, sweep_plan, sweep_summary, sweep_train_config)
from bgfn.studies.outage_sweep.variant_outages import (NO_VARIANT, VARIANT_COLUMNS, VARIANT_METRICS,
                                                       load_variant_network, variant_pivot, variant_runs, variant_table)

__all__ = [
    "AntennaTruth", "increment_errors", "increment_rmse", "BREAKEVEN_COLUMNS", "ORACLE_COLUMNS", "NoSweepStarts",
    "OracleIncrements", "OracleResult", "breakeven_table", "crossing_sigma", "curve_at", "method_levels",
    "oracle_interval_table", "oracle_runs", "oracle_table", "oracle_windows", "plot_oracle", "run_oracle",
    "pairs_style", "profile_sweep_plan",
    "run_sweep", "run_sweeps", "sweep_comparisons", "sweep_interval_table", "sweep_plan", "sweep_summary",
    "sweep_train_config", "NO_VARIANT", "VARIANT_COLUMNS", "VARIANT_METRICS", "load_variant_network",
    "variant_pivot", "variant_runs", "variant_table",
]

"""GPS-outage evaluation of the hybrid GPS/INS structure (paper Sec. 3.1 prediction mode, Sec. 4 Tables 1-2).

Protocol (notebook 04, the ``evaluate:`` section of a profile):

1. **GPS-aided run.** The 15-state loosely coupled filter (:mod:`bgfn.nav.filter`, the ``nav:`` section's
   settings) runs over the whole drive with every GNSS fix; its state is saved at every outage start
   (:func:`navigation_context`). Before an outage start everything the methods see comes from this causal run
   (a filter state at ``t`` has used the fixes up to ``t`` only). Its trajectory inside the outage is the
   **GPS** row: the lower bound, the solution had GNSS not been lost.
2. **Prediction mode** (:func:`run_outages`), from the saved state at the outage start, no GNSS inside:

   - **INS**: the filter only predicts (strapdown + covariance), its bias estimates held;
   - **MLP / AT-LSTM / BGFN / Transformer**: at each pseudo-GNSS epoch ``t_k = start + k / fusion_rate_hz``
     the filter is propagated to ``t_k``; the network predicts the GNSS position increments
     ``delta_p_gps`` (north, east) of every GNSS interval ending in ``(t_{k-1}, t_k]`` from windows of the
     ``N`` latest IMU samples (Eq. eq21: roll, pitch, yaw of *the navigation solution being computed* in
     this run -- the hybrid's own attitude, pre-outage samples from the GPS-aided run -- and the raw
     specific force and angular rate); the increments are accumulated into the pseudo-GPS position
     ``P_GPS(k) = P_GPS0 + sum_i delta_p_gps_i`` (Eq. pred-gps, :func:`pseudo_gps_positions`) with
     ``P_GPS0`` the filter's antenna position at the outage start, and fused as a north/east antenna
     position fix with the standard deviation of ``pseudo_gps.std_m`` (height not fused: the networks
     predict 2-D increments). Nothing inside the outage reads GNSS or the reference.

   - **INS+NHC**, **<METHOD>+NHC** (beyond the paper, ``nhc_rows``): the same runs with the vehicle
     constraints of :mod:`bgfn.nav.constraints` fused as well (non-holonomic constraints, and a zero-velocity
     update whenever the IMU's stillness detector fires; ``ctx.constraints``, their vehicle frame estimated by
     the GPS-aided run up to the start): the learning-free aid a learned one must beat, or add to.

   The increments have the length the networks were trained on: the drive's GNSS epoch interval (0.2 s for
   the 5 Hz Ekinox fixes, 1 s for the 1 Hz u-blox-like receiver); ``fusion_rate_hz`` must divide the GNSS
   rate. Runs that share a network advance in lockstep so that one forward pass serves all of them.
3. **Metrics** (:func:`window_metrics`): errors = solution minus reference at the IMU position, local NED
   metres; per outage max |east|, max |north| (paper Tables 1-2), horizontal RMSE, horizontal error at the
   end, max horizontal error.

The networks of the two tables are those of notebook 03 (``results/<profile>/models/<dataset>/
<method>_seed<k>.pt``; trained here with the same code when missing). The main tables report, per
method and metric, the **median over the training seeds** (``seed_aggregate``); the per-seed values are
written beside them.

Outage sweep (:func:`run_sweep`, beyond the paper): ``n_starts`` outage starts spread evenly over the drive,
split into ``folds`` contiguous blocks; the networks of fold ``k`` are trained (cached under
``models/<dataset>/fold<k>/``) with the outages of fold ``k`` (longest duration, plus the ``train.margin_s``
margin) excluded by :func:`bgfn.learning.split_windows`, and evaluated on them only. Each start is run once
for the longest duration; since the runs are causal the first ``d`` seconds of it *are* the run of a
``d``-second outage (same start state, same pseudo fixes), so the metrics of every duration come from its
prefix. :func:`sweep_summary` gives per method and duration the median max horizontal error with a cluster
(by start) bootstrap interval, :func:`sweep_comparisons` how often BGFN beats each baseline with the
Wilcoxon signed-rank test on the (start, seed) pairs.

Modules, in the order of the protocol:

- :mod:`bgfn.evaluate.config` -- method names and labels, table columns, the ``evaluate:`` defaults, notebook
  04's parameters over them (:func:`evaluation_setup`);
- :mod:`bgfn.evaluate.hybrid` -- Eq. pred-gps, the GPS-aided run, the outage runs, their metrics;
- :mod:`bgfn.evaluate.networks` -- notebook 03's checkpoints (trained here when missing);
- :mod:`bgfn.evaluate.tables` -- the paper's Tables 1-2 and their files;
- :mod:`bgfn.evaluate.claims` -- ours beside the paper's: its layout, reductions against INS, its quoted claims;
- :mod:`bgfn.evaluate.plots` -- the paper's outage figures and the sweep's box plots;
- :mod:`bgfn.evaluate.sensitivity` -- the tables again with each network's validation std for its pseudo fixes;
- :mod:`bgfn.evaluate.sweep` -- the outage sweep and its statistics;
- :mod:`bgfn.evaluate.increments` -- the true increments of a drive, a run's increment error;
- :mod:`bgfn.evaluate.oracle` -- the oracle rows: true increments plus noise, the break-even accuracy;
- :mod:`bgfn.evaluate.nees` -- the filter's consistency in the outages: NEES of the horizontal position at each
  window's end against its covariance, per method and duration (``tables/outage_nees.csv``);
- :mod:`bgfn.evaluate.imu_twin` -- is the stand-in's IMU as rough as a real one: the recorded drive against its
  trajectory twin (the same road with the stand-in's simulated IMU), their effective gyro bias instability;
- :mod:`bgfn.evaluate.odometers` -- the bars a learned odometer must clear: INS+NHC, the held speed, RIDGE-ODO and
  an oracle speed, fused as a forward-speed measurement (beyond the paper);
- :mod:`bgfn.evaluate.record` -- ``outage_evaluation.json``, the record notebook 06 reads;
- :mod:`bgfn.evaluate.variants` -- the learning-problem variants of notebook 03 in the two outages.

Everything public is re-exported here: ``from bgfn import evaluate as ev; ev.evaluate_dataset(...)``.
"""

from bgfn.evaluate.claims import REDUCTION_COLUMNS, claim_lines, ours_above_paper, paper_table_title, reduction_table
from bgfn.evaluate.config import (COLORS, EVALUATE_DEFAULTS, FIGURE_METHODS, METRIC_COLUMNS, REAL_IMU_DATASETS,
                                  SWEEP_COLUMNS, TABLE_COLUMNS, TABLE_FILES, TABLE_METHODS, EvaluationSetup,
                                  choose_datasets, evaluate_config, evaluation_setup)
from bgfn.evaluate.hybrid import (NavContext, OutageRun, gps_run, navigation_context, pseudo_gps_positions, run_outages,
                                  window_metrics)
from bgfn.evaluate.increments import AntennaTruth, increment_errors, increment_rmse
from bgfn.evaluate.imu_twin import (TWIN_COLUMNS, effective_instability, implied_setting, settle_setting,
                                    twin_check, twin_lines, twin_section)
from bgfn.evaluate.ins_drift import (DRIFT_COLUMNS, DRIFT_RUN_COLUMNS, drift_sentences, drift_starts, drift_summary,
                                     ins_drift_runs, plot_ins_drift)
from bgfn.evaluate.networks import ensure_models, load_model
from bgfn.evaluate.nees import (NEES_COLUMNS, consistency_scan, nees_lines, nees_section, nees_summary,
                                scan_lines)
from bgfn.evaluate.odometers import (ODOMETER_COLUMNS, ODOMETER_METHODS, OdometerSection, odometer_lines,
                                     odometer_rows, odometer_summary, odometer_table, run_odometer_bars,
                                     run_odometer_section)
from bgfn.evaluate.oracle import (BREAKEVEN_COLUMNS, ORACLE_COLUMNS, OracleIncrements, OracleResult, breakeven_table,
                                  crossing_sigma, curve_at, describe_oracle, method_levels, oracle_interval_table,
                                  oracle_runs, oracle_table, oracle_windows, plot_oracle, run_oracle)
from bgfn.evaluate.plots import outage_figures, plot_gps_row, plot_outage, plot_sweep_boxes
from bgfn.evaluate.record import RECORD_FILE, evaluation_record, write_evaluation_record
from bgfn.evaluate.sensitivity import (SENSITIVITY_COLUMNS, Sensitivity, pseudo_std_sensitivity, save_sensitivity,
                                       sensitivity_table)
from bgfn.evaluate.sweep import (describe_sweep, describe_sweep_setup, describe_sweep_size, profile_sweep_plan,
                                 pairs_style, run_sweep, run_sweeps, sweep_comparisons, sweep_interval_table, sweep_plan,
                                 sweep_summary, sweep_train_config)
from bgfn.evaluate.tables import (TableResult, aggregate_seeds, describe_tables, error_reduction, error_series,
                                  evaluate_dataset, fix_error_table, representative_seeds, run_tables,
                                  save_table_result, table_file, table_paths)
from bgfn.evaluate.variants import (NO_VARIANT, VARIANT_COLUMNS, VARIANT_METRICS, load_variant_network, variant_pivot,
                                    variant_runs, variant_table)

__all__ = [
    "TWIN_COLUMNS", "effective_instability", "implied_setting", "settle_setting", "twin_check", "twin_lines",
    "twin_section", "NEES_COLUMNS", "consistency_scan", "nees_lines", "nees_section", "nees_summary", "scan_lines", "ODOMETER_COLUMNS", "ODOMETER_METHODS", "OdometerSection", "odometer_lines", "odometer_rows", "odometer_summary",
    "odometer_table", "run_odometer_bars", "run_odometer_section",
    "DRIFT_COLUMNS", "DRIFT_RUN_COLUMNS", "drift_sentences", "drift_starts", "drift_summary", "ins_drift_runs",
    "plot_ins_drift", "outage_figures",
    "AntennaTruth", "BREAKEVEN_COLUMNS", "ORACLE_COLUMNS", "OracleIncrements", "OracleResult", "breakeven_table",
    "crossing_sigma", "curve_at", "describe_oracle", "increment_errors", "increment_rmse", "method_levels",
    "oracle_interval_table", "oracle_runs", "oracle_table", "oracle_windows", "plot_oracle", "run_oracle",
    "COLORS", "EVALUATE_DEFAULTS", "FIGURE_METHODS", "METRIC_COLUMNS", "REAL_IMU_DATASETS", "RECORD_FILE",
    "REDUCTION_COLUMNS", "SENSITIVITY_COLUMNS", "SWEEP_COLUMNS", "TABLE_COLUMNS", "TABLE_FILES",
    "TABLE_METHODS", "EvaluationSetup", "NavContext", "OutageRun", "Sensitivity", "TableResult",
    "aggregate_seeds", "choose_datasets", "claim_lines", "describe_sweep", "describe_sweep_setup",
    "describe_sweep_size", "describe_tables", "ensure_models", "error_reduction", "error_series",
    "evaluate_config", "evaluate_dataset", "evaluation_record", "evaluation_setup", "fix_error_table",
    "gps_run", "load_model", "navigation_context", "ours_above_paper", "paper_table_title",
    "plot_gps_row", "plot_outage", "plot_sweep_boxes", "pseudo_gps_positions", "pseudo_std_sensitivity",
    "reduction_table", "representative_seeds", "run_outages", "run_sweep", "run_sweeps", "run_tables",
    "save_sensitivity", "save_table_result", "sensitivity_table", "sweep_comparisons", "sweep_interval_table", "pairs_style",
    "profile_sweep_plan", "sweep_plan", "sweep_summary", "sweep_train_config", "table_file", "table_paths",
    "window_metrics",
    "write_evaluation_record",
    # the learning-problem variants (notebook 03)
    "NO_VARIANT", "VARIANT_COLUMNS", "VARIANT_METRICS", "load_variant_network", "variant_runs", "variant_table", "variant_pivot",
]

"""The paper's GPS-outage evaluation: the hybrid GPS/INS structure in prediction mode (Sec. 3.1, Tables 1-2).

The 15-state filter runs over each drive with every GNSS fix and saves its state at each outage start; from there
each method runs the outage without GNSS: INS predicts only, a network's increments are summed into a pseudo-GPS
fix (Eq. pred-gps) and fused like a GNSS fix; the ``+NHC`` rows add the vehicle constraints. Metrics per outage:
max |east|, max |north| (the paper's tables), horizontal RMSE and final error; the median over training seeds.
Modules, in the order of the protocol: ``setup``, ``hybrid``, ``networks``, ``tables`` (Tables 1-2), ``claims``
(ours beside the paper's), ``pseudo_std``, ``plots``, ``record``. The studies beyond the paper are in
:mod:`bgfn.studies`.
"""

from bgfn.evaluate.claims import REDUCTION_COLUMNS, ours_above_paper, reduction_table
from bgfn.evaluate.setup import (COLORS, EVALUATE_DEFAULTS, FIGURE_METHODS, METRIC_COLUMNS, REAL_IMU_DATASETS,
                                  SWEEP_COLUMNS, TABLE_COLUMNS, TABLE_FILES, TABLE_METHODS, EvaluationSetup,
                                  OwnOutages, RealImuChoice, choose_datasets, evaluate_config, evaluation_setup)
from bgfn.evaluate.hybrid import (NavContext, OutageRun, gps_run, navigation_context, pseudo_gps_positions, run_outages,
                                  window_metrics)
from bgfn.evaluate.networks import ensure_models, load_model
from bgfn.evaluate.pseudo_std import (SENSITIVITY_COLUMNS, Sensitivity, pseudo_std_sensitivity, save_sensitivity,
                                      sensitivity_table)
from bgfn.evaluate.plots import outage_figures, plot_gps_row, plot_outage, plot_sweep_boxes
from bgfn.evaluate.record import RECORD_FILE, evaluation_record, write_evaluation_record
from bgfn.evaluate.tables import (TableResult, aggregate_seeds, error_reduction, error_series,
                                  evaluate_dataset, fix_error_table, OUTAGE_RUNS_CACHE, outage_result,
                                  outage_results, representative_seeds, run_tables, save_table_result, table_file, table_paths)

__all__ = [
    "REDUCTION_COLUMNS", "ours_above_paper", "reduction_table", "COLORS",
    "EVALUATE_DEFAULTS", "FIGURE_METHODS", "METRIC_COLUMNS", "REAL_IMU_DATASETS", "SWEEP_COLUMNS", "TABLE_COLUMNS",
    "TABLE_FILES", "TABLE_METHODS", "EvaluationSetup", "OwnOutages", "RealImuChoice", "choose_datasets",
    "evaluate_config", "evaluation_setup",
    "NavContext", "OutageRun", "gps_run", "navigation_context", "pseudo_gps_positions", "run_outages",
    "window_metrics", "ensure_models", "load_model", "outage_figures", "plot_gps_row", "plot_outage",
    "plot_sweep_boxes", "RECORD_FILE", "evaluation_record", "write_evaluation_record", "TableResult",
    "aggregate_seeds", "error_reduction", "error_series", "evaluate_dataset", "fix_error_table",
    "SENSITIVITY_COLUMNS", "Sensitivity", "pseudo_std_sensitivity", "save_sensitivity", "sensitivity_table",
    "OUTAGE_RUNS_CACHE", "outage_result", "outage_results", "representative_seeds", "run_tables", "save_table_result", "table_file", "table_paths",
]

"""Training of BGFN and the baselines (paper Sec. 4.1: BPTT, batch 8, 1000 epochs on a GPU), kept apart from the
networks (:mod:`bgfn.models`) and the learning problem (:mod:`bgfn.learning`).

Modules, one concept each (every public name is re-exported here): ``options`` (the ``train:`` settings),
``loop`` (:func:`train_model`, one run with early stopping, checkpoint, card and resume), ``memory``,
``objectives`` (the increments or a learned odometer's speed), ``trained`` (:func:`load_trained`), ``tasks``
(independent runs over a :class:`bgfn.parallel.Runner`), ``lr_search``, ``profile`` (:class:`TrainingPlan`: a
profile's runs), ``runs`` (:func:`train_profile`), ``variants``, ``recheck``, ``tables``, ``plots``, ``estimate``
(the paper profile's training time here), ``speed`` (timing for ``make bench``), ``checkpoints``. The command line
``python -m bgfn train --profile ...`` is the package's edge (:mod:`bgfn.__main__`).
"""

from bgfn.learning import REFERENCES, VAL_POSITIONS
from bgfn.train.estimate import measure_paper_step, paper_training_estimate
from bgfn.train.loop import set_seed, train_model
from bgfn.train.memory import keep_freed_memory
from bgfn.train.lr_search import (LR_SEARCH_COLUMNS, LR_SEARCH_DEFAULTS, LR_SEARCH_FILE, chosen_learning_rates,
                                  lr_search_options, next_learning_rate, search_learning_rates,
                                  search_profile_learning_rates, search_profile_rates, search_train_config,
                                  selected_train_configs, tuned_train_config, with_selected_lr)
from bgfn.train.options import (OPTIMIZER_DEFAULTS, even_subset, method_lr, optimizer_options, size_config,
                                train_subsection)
from bgfn.train.plots import plot_motion_coverage, plot_training_curves, plot_val_predictions
from bgfn.train.profile import (TrainingDataset, TrainingPlan, ins_attitude, prepare_datasets, prepare_learning_data,
                                train_dataset, train_datasets, training_runs, val_position_table,
                                val_position_tables)
from bgfn.train.recheck import (RECHECK_COLUMNS, capped_runs, first_per_method, recheck_all_windows,
                                recheck_table)
from bgfn.train.runs import train_profile
from bgfn.train.tables import (TIMING_COLUMNS, cards_table, summary_table, timing_table,
                               training_metrics, windows_table, without_timing)
from bgfn.train.tasks import TrainingRun, expected_cost, run_summary, train_run, train_runs
from bgfn.train.trained import TrainedModel, checkpoint_predictions, load_trained, pick_device, predict_normalized
from bgfn.train.variants import (VARIANT_RUN_DEFAULTS, VariantPlan, variant_options, train_variants,
                                 variant_cards_table, variant_learning_data, variant_runs, variant_train_section,
                                 wall_time_by_variant)

__all__ = [
    "measure_paper_step", "paper_training_estimate",
    # options
    "OPTIMIZER_DEFAULTS", "train_subsection", "optimizer_options", "method_lr", "size_config", "even_subset",
    # the loop and a trained network
    "set_seed", "train_model", "keep_freed_memory", "pick_device", "predict_normalized", "TrainedModel", "load_trained",
    "checkpoint_predictions",
    # learning-rate search
    "LR_SEARCH_DEFAULTS", "LR_SEARCH_FILE", "LR_SEARCH_COLUMNS", "lr_search_options", "search_learning_rates",
    "next_learning_rate", "search_train_config", "with_selected_lr", "tuned_train_config",
    "search_profile_learning_rates", "selected_train_configs", "chosen_learning_rates", "search_profile_rates",
    # independent runs
    "TrainingRun", "train_run", "train_runs", "run_summary", "expected_cost",
    # a profile's training
    "TrainingPlan", "TrainingDataset", "prepare_datasets", "prepare_learning_data", "ins_attitude",
    "val_position_table", "val_position_tables", "train_dataset", "train_datasets", "training_runs", "train_profile",
    # tables and figures
    "REFERENCES", "VAL_POSITIONS", "TIMING_COLUMNS", "cards_table", "summary_table", "without_timing",
    "timing_table", "windows_table", "training_metrics", "plot_training_curves",
    "plot_val_predictions", "plot_motion_coverage",
    # runs that never learned, trained again on all windows
    "RECHECK_COLUMNS", "capped_runs", "first_per_method", "recheck_all_windows", "recheck_table",
    # input and protocol variants
    "VARIANT_RUN_DEFAULTS", "VariantPlan", "variant_options", "variant_train_section", "variant_learning_data",
    "train_variants", "variant_runs", "variant_cards_table", "wall_time_by_variant",
]

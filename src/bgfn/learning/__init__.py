"""The learning problem of BGFN: IMU/INS windows -> GPS position increment (the paper's O_INS - Delta P_GPS model).

Inputs (Eq. eq21): per IMU sample the INS attitude and the raw specific force and angular rate (9 channels), in
windows of the ``N`` (paper: 200) latest samples. Target (Eq. eq8-1): ``delta_p_gps``, the (north, east) change of
the GNSS position between consecutive epochs, m. By default a window ends at the epoch its increment ends at
(``alignment: ending``, causal at a pseudo-GNSS epoch), its yaw unwrapped, its target in NED
(:data:`LEARNING_DEFAULTS` names the options). Training windows come from GPS-available time only, outside the
evaluation outages widened by ``margin_s`` and apart from one held-out validation block; the normalization from
the training windows only. Modules (every public name re-exported here): ``inputs``, ``targets``, ``windows``,
``split``, ``normalize``, ``references``, ``coverage``, ``data``, ``synthetic``; beyond the paper, ``odometry``
(IMU windows -> forward speed, and its ridge baseline).
"""

from bgfn.learning.coverage import (VAL_POSITIONS, motion_in_windows, motion_of_windows, motion_sets, unseen_fraction,
                                    val_position_coverage)
from bgfn.learning.data import (LEARNING_DEFAULTS, LearningData, all_windows, build_learning_data, inner_split,
                                learning_options, split_summary)
from bgfn.learning.inputs import (ANGULAR_RATE_CHANNELS, ATTITUDE_CHANNELS, CHANNELS, DERIVED_CHANNELS, EXTRA_START,
                                  IMU_CHANNELS, SPECIFIC_FORCE_CHANNELS, YAW_CHANNEL, YAW_ENCODINGS, encode_yaw,
                                  heading_velocity, sample_features, with_derived_channels, wrap_angle)
from bgfn.learning.normalize import Normalizer
from bgfn.learning.references import REFERENCES, reference_columns, reference_rmse, rmse
from bgfn.learning.split import PROTOCOLS, block_label, forbidden_intervals, merged_spans, overlaps, split_windows
from bgfn.learning.synthetic import synthetic_tables
from bgfn.learning.targets import (TARGET_FRAMES, TARGETS, from_target_frame, gnss_increments, ins_increments,
                                   position_increment, screen_increments, to_target_frame)
from bgfn.learning.windows import ALIGNMENTS, WindowSet, make_windows, prediction_windows

__all__ = [
    # inputs (Eq. eq21)
    "CHANNELS", "ATTITUDE_CHANNELS", "IMU_CHANNELS", "SPECIFIC_FORCE_CHANNELS", "ANGULAR_RATE_CHANNELS",
    "EXTRA_START", "DERIVED_CHANNELS", "YAW_CHANNEL", "YAW_ENCODINGS", "wrap_angle", "heading_velocity",
    "with_derived_channels", "sample_features", "encode_yaw",
    # targets (Eq. eq8-1)
    "TARGETS", "TARGET_FRAMES", "position_increment", "gnss_increments", "ins_increments", "screen_increments",
    "to_target_frame", "from_target_frame",
    # windows
    "ALIGNMENTS", "WindowSet", "make_windows", "prediction_windows",
    # split, normalization
    "PROTOCOLS", "forbidden_intervals", "overlaps", "merged_spans", "split_windows", "block_label", "Normalizer",
    # references, coverage
    "rmse", "REFERENCES", "reference_rmse", "reference_columns", "VAL_POSITIONS", "motion_of_windows",
    "motion_in_windows", "motion_sets", "unseen_fraction", "val_position_coverage",
    # all together
    "LEARNING_DEFAULTS", "LearningData", "learning_options", "all_windows", "build_learning_data", "inner_split",
    "split_summary", "synthetic_tables",
]

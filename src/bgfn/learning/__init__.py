"""The learning problem of BGFN: IMU/INS windows -> GPS position increment (paper's O_INS - Delta P_GPS model).

Inputs (Eq. eq21): per IMU sample the 9 channels ``[roll, pitch, yaw, fx, fy, fz, wx, wy, wz]`` -- the attitude
of the INS/KF solution (interpolated to the IMU times) and the raw IMU specific force and angular rate; a
window holds the ``N`` (paper: 200) most recent samples at 100 Hz, i.e. those with ``time <= t_end``.

Target (Eq. eq8-1): ``delta_p_gps`` = (north, east) change of the GNSS position between two consecutive GNSS
epochs, in metres, from the latitude/longitude differences and the WGS84 curvature radii at the mid-point::

    dN = (lat_b - lat_a) (R_M + h),   dE = (lon_b - lon_a) (R_N + h) cos(lat)

Alignment of window and target (``alignment``):

- ``'ending'`` (default): the window ends at GNSS epoch ``t_b`` and the target is the increment
  ``t_a -> t_b`` into that epoch. The IMU samples of the increment interval lie inside the window, as in
  Eq. (eq8-1) where Delta P_GPS is the double integral of the IMU output over the interval; the paper's
  "predicts Delta P^{k+1} from the preceding k IMU observations" with the IMU step k+1 being the GNSS epoch.
  It is causal: at a pseudo-GNSS epoch ``t_b`` of an outage the IMU data up to ``t_b`` exist.
- ``'next'``: the window ends at ``t_a`` and the target is ``t_a -> t_b`` (a forecast of the next interval).

Yaw wrap-around (``yaw_encoding``; all keep 9 channels):

- ``'unwrap'`` (default): yaw unwrapped along the window and anchored so that the window's last sample is the
  wrapped value in (-pi, pi]. A window never holds a 2 pi jump; the absolute heading (which the north/east
  target needs) is kept. Two windows at headings just either side of +-pi still differ by about 2 pi.
- ``'relative'``: yaw minus the window's last yaw, wrapped to (-pi, pi]: no jump at all, but the absolute
  heading is lost (only useful with a target in a heading-aligned frame; not the paper's).
- ``'raw'``: the wrapped yaw as given.

Target frame (``target_frame``):

- ``'ned'`` (default, the paper's Eq. eq21 output): the network outputs (dN, dE) directly.
- ``'heading'``: the network outputs the increment in the frame of the window's last INS yaw
  (along-track, cross-track), rotated back to (dN, dE) with that yaw after prediction. Not the paper's; it
  spares every model learning cos/sin of the heading. The reported errors are always in north/east metres.

Training data come only from GPS-available time (:func:`split_windows`): a window whose input span or
target interval touches an evaluation outage widened by ``margin_s`` is dropped; validation is one held-out
block of time (``val_fraction`` of the windows at ``val_position``) and training windows overlapping that block
are dropped too, so no training window shares an IMU sample or GNSS epoch with a validation window.
Normalization statistics (:class:`Normalizer`) come from the training windows only.

Modules, one concept each (every public name is re-exported here):

- :mod:`bgfn.learning.inputs`: the nine channels of Eq. (eq21), their named slices, derived channels, yaw encoding;
- :mod:`bgfn.learning.targets`: delta_p_gps of Eq. (eq8-1), INS increments, screening, target frame;
- :mod:`bgfn.learning.windows`: :class:`WindowSet`, the windows of a drive and of an outage (Eq. pred-gps);
- :mod:`bgfn.learning.split`: outage exclusion and the validation block;
- :mod:`bgfn.learning.normalize`: :class:`Normalizer`;
- :mod:`bgfn.learning.references`: the validation RMSE and the zero / last-increment / INS-increment references;
- :mod:`bgfn.learning.coverage`: headings and speeds seen in training, validation and the outages;
- :mod:`bgfn.learning.data`: :class:`LearningData`, the learning options, the tuning split;
- :mod:`bgfn.learning.synthetic`: a toy drive for tests and examples;
- :mod:`bgfn.learning.odometry`: beyond the paper, the odometer problem (IMU-only windows -> forward speed) and
  its ridge baseline.
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

"""Every key of a profile (``params/<profile>.yaml``): its type, unit, default and meaning, in one typed definition.

One pydantic model per section. The defaults are the project's decided settings (the measurements that decided
them: ``benchmarks/MEASUREMENTS.md``, "Settings decided by A/B"; where they differ from the paper: the book's
deviations page); a profile lists only what it changes. :mod:`bgfn.settings_check` lays a merged profile over
:func:`defaults` and checks it against :class:`Profile`; the cross-field facts and the checks against the drives
live at the package's edge (:mod:`bgfn.profile_schema`).
"""

from __future__ import annotations

import copy
from typing import Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict, Field

Pos = Annotated[float, Field(gt=0)]
NonNeg = Annotated[float, Field(ge=0)]
Fraction = Annotated[float, Field(gt=0, lt=1)]
Seed = Annotated[int, Field(ge=0)]
MAX_COUNT, MAX_JOBS = 1_000_000, 1024     # the most of any count (epochs ...) and of runs at a time: no typo runs for ever
Count = Annotated[int, Field(ge=1, le=MAX_COUNT)]
Vec3, NonNeg3 = (Annotated[list[t], Field(min_length=3, max_length=3)] for t in (float, NonNeg))
Names = Annotated[list[str], Field(min_length=1)]
Seeds = Annotated[list[Seed], Field(min_length=1)]
Method = Literal["mlp", "at_lstm", "bgfn", "transformer"]
METHODS = ["bgfn", "transformer", "at_lstm", "mlp"]
DRIVES = ["turin-sim-ekinox", "turin-sim-mpu6000", "rtklib-drive0708"]
#: The entry of a per-dataset setting that holds for every dataset it does not name.
DEFAULT_DATASET_KEY = "default"


def _f(default, doc: str, **kw):
    """A field: its default (a copy for lists and mappings) and its one-line description."""
    if isinstance(default, (list, dict)):
        return Field(default_factory=lambda: copy.deepcopy(default), description=doc, **kw)
    return Field(default, description=doc, **kw)


class Section(BaseModel):
    """A section: exact types (no coercion), every key known, finite numbers."""

    model_config = ConfigDict(strict=True, extra="forbid", allow_inf_nan=False, populate_by_name=True)


class Parallel(Section):
    jobs: Annotated[int, Field(ge=1, le=MAX_JOBS)] | None = _f(None, "runs at a time here (null: its cores); JOBS=n wins")
    backend: Literal["loky", "dask"] = _f("loky", "loky: processes here | dask: a dask.distributed cluster")
    scheduler: str | None = _f(None, "the Dask scheduler's address with backend dask (tcp://host:8786)")


class OutageRule(Section):
    """Outages picked from a drive by a rule (bgfn.nav.outage_rules): one cruise, one manoeuvre (the paper's choice)."""

    rule: Literal["cruise_and_manoeuvre"] = Field(description="the rule that picks the windows")
    duration_s: Pos = _f(30.0, "each outage, s (the paper's 30 s)")
    step_s: Pos = _f(1.0, "grid of the speed and yaw-rate series and of the starts, s")
    warmup_s: NonNeg = _f(60.0, "no start earlier after the filter's start (its alignment included), s")
    min_speed_mps: NonNeg = _f(2.0, "slower counts as standing (the course is no heading), m/s")
    cruise_max_yaw_rate_dps: NonNeg = _f(3.0, "a cruise window's mean |yaw rate| at most, deg/s")
    manoeuvre_min_yaw_rate_dps: NonNeg = _f(5.0, "the manoeuvre window's mean |yaw rate| at least, deg/s (or the "
                                            "drive's percentile below, when lower)")
    manoeuvre_yaw_rate_percentile: Annotated[float, Field(gt=0, le=100)] | None = _f(
        75.0, "the drive's own manoeuvre threshold: this percentile of its |yaw rate| while moving, deg/s, when "
        "below manoeuvre_min_yaw_rate_dps (null: the fixed value alone)")
    gap_s: NonNeg = _f(30.0, "between the two outages at least, s")
    min_training_s: NonNeg = _f(120.0, "GPS time left to training outside the outages +- train.margin_s, s")


class DriveParams(Section):
    """A registered drive's parameters (``data.<name>``; defaults: bgfn.data.registry.DATASETS)."""

    seed: Seed = Field(None, description="seed of the drive's simulated errors")
    imu_rate_hz: Pos = Field(None, description="IMU rate, Hz")
    gnss_rate_hz: Pos = Field(None, description="GNSS fixes per second, Hz")
    gnss_white_std_m: NonNeg3 = Field(None, description="white GNSS noise std (N, E, D), m")
    gnss_correlated_std_m: NonNeg3 = Field(None, description="Gauss-Markov GNSS error std (N, E, D), m")
    lever_arm_m: Vec3 = Field(None, description="GNSS antenna in the IMU's body frame (x, y, z), m")
    smoothing_degree: Annotated[int, Field(ge=1, le=5)] = Field(None, description="degree of the truth's splines")
    position_sigma_m: Pos = Field(None, description="truth smoothing of the reference position, m")
    attitude_sigma_rad: Pos = Field(None, description="truth smoothing of the attitude, rad")
    gnss_correlated_tau_s: Pos = Field(None, description="its correlation time, s")
    imu_errors: dict[str, Any] = Field(None, description="overrides of the IMU error profile's keys")
    imu_time_offset_s: Annotated[float, Field(ge=-1.0, le=1.0)] = Field(None, description="added to the IMU's time, s")
    t_start: float | None = Field(None, description="crop start, s (the drive's own clock)")
    t_end: float | None = Field(None, description="crop end, s")


class Data(Section):
    """Notebook 01: the drives built, tabulated and plotted; other keys name a drive and hold its parameters."""

    model_config = ConfigDict(extra="allow")
    datasets: Names = _f(DRIVES, "drives built by notebook 01 (bgfn.data.DATASETS or CSV folders)")
    seed: Seed | None = _f(None, "seed of every simulated IMU/GNSS error draw (null: the profile's seed)")
    imu_rate_hz: Pos = _f(100.0, "IMU and truth rate, Hz")
    smoothing_degree: Annotated[int, Field(ge=1, le=5)] = _f(5, "degree of the truth's smoothing splines")
    position_sigma_m: Pos = _f(0.05, "truth smoothing of the 1 Hz reference position, m (s = n sigma^2)")
    attitude_sigma_rad: Pos = _f(0.002, "truth smoothing of the attitude, rad")
    t_start: float | None = _f(None, "crop of the Turin drive, s GPS time of week (null: whole drive)")
    t_end: float | None = _f(None, "end of that crop, s")
    imu_plot_start_tow: float | None = _f(138840.0, "notebook 01's IMU plot starts here, s GPS time of week")
    imu_plot_duration_s: Pos = _f(20.0, "and lasts this long, s")
    reference_tolerance_m: Pos = _f(3.0, "fixes off the reference by a median beyond this: a warning, m")


class Init(Section):
    position_std_m: Pos = _f(1.0, "P0 horizontal position std, m")
    height_std_m: Pos = _f(3.0, "P0 height std, m")
    velocity_std_mps: Pos = _f(0.1, "P0 velocity std, m/s")
    level_std_deg: Pos = _f(0.5, "P0 roll and pitch std, deg")
    azimuth_std_deg: Pos = _f(2.0, "P0 heading std, deg")


class Alignment(Section):
    """Where the filter starts (bgfn.nav.alignment): reference | gnss (self-alignment) | auto."""

    mode: Literal["reference", "gnss", "auto"] = _f("auto", "auto: the reference's attitude when it passes its check")
    speed_threshold_mps: Pos = _f(3.0, "the heading needs the GNSS course above this horizontal speed, m/s")
    heading_time_s: Pos = _f(10.0, "... for this long, s")
    level_time_s: Pos = _f(5.0, "a drive that starts moving: level from f - dv/dt over this span, s")
    still_window_s: Pos = _f(1.0, "rest at the start: blocks this long whose IMU spread is tested, s")
    still_min_s: NonNeg = _f(5.0, "rest for at least this long, s")
    still_accel_std_mps2: Pos = _f(0.3, "rest: specific-force std below, m/s^2")
    still_gyro_std_dps: Pos = _f(5.0, "rest: angular-rate std below (engine vibration at idle passes), deg/s")
    level_std_deg: Pos = _f(1.0, "P0 floor of the aligned roll and pitch, deg")
    azimuth_std_deg: Pos = _f(2.0, "P0 floor of the aligned heading, deg")
    velocity_std_mps: Pos = _f(0.2, "P0 floor of the aligned velocity, m/s")
    reference_tolerance_deg: Pos = _f(10.0, "auto: reference yaw vs course, level vs the IMU's at rest within, deg")


class NoiseSearch(Section):
    """``nav.noise_scale: auto``: the factor whose GPS-aided run has mean NIS = its dof (bgfn.nav.tuning)."""

    range: Annotated[list[Pos], Field(min_length=2, max_length=2)] = _f([0.1, 1000.0], "[low, high] of the factor")
    max_runs: Count = _f(8, "filter runs at most")
    tolerance: Pos = _f(0.1, "|log(NIS / dof)| <= log(1 + tolerance)")
    bias_walk: bool = _f(False, "the factor scales the bias driving noise too")


class Nhc(Section):
    """Non-holonomic constraints of a car (bgfn.nav.constraints): lateral and vertical velocity ~ 0."""

    std_mps: Pos = _f(0.1, "std of the constraint, m/s")
    rate_hz: Pos = _f(1.0, "constraint updates per second, Hz")
    mounting: Literal["estimate", "none"] = _f("estimate", "vehicle frame from the GPS-aided solution | none: body")
    mounting_min_speed_mps: NonNeg = _f(5.0, "epochs of the mounting estimate faster than this, m/s")
    mounting_weight: Literal["heading", "equal"] = _f("heading", "epoch weights: inverse heading variance | equal")


class Zupt(Section):
    """Zero-velocity updates when the IMU is still (bgfn.nav.constraints)."""

    std_mps: Pos = _f(0.05, "std of the update, m/s")
    window_s: Pos = _f(2.0, "trailing IMU window tested for rest, s")
    accel_ratio: NonNeg = _f(1.5, "specific-force std below this times the at-rest std (0: never)")
    gyro_ratio: NonNeg = _f(1.5, "angular-rate std below this times the at-rest std (0: never)")
    max_speed_mps: NonNeg = _f(2.0, "and the filter's speed below, m/s")


class Nav(Section):
    """Notebook 02: strapdown INS and the 15-state loosely coupled Kalman filter."""

    datasets: Names = _f(DRIVES, "drives of the KF baseline")
    init: Init = _f({}, "P0 when the filter starts at the reference's first row (bgfn.nav.state)")
    alignment: Alignment = _f({}, "the filter's start")
    bias_model: Literal["random_walk", "gauss_markov"] = _f("random_walk", "bias states' model")
    noise_scale: Any = _f({"default": 1.0, "rtklib-drive0708": "auto"},
                          "factor on Q's white-noise densities: > 0 or 'auto', or per dataset with a default")
    noise_search: NoiseSearch = _f({}, "how 'auto' finds the factor")
    innovation_gate: Fraction | None = _f(None, "chi-square probability of the GNSS gate (null: every fix)")
    ins_tuning: Literal["shipped", "navego"] = _f("shipped", "IMU bias modelling: shipped | NaveGo v1.4's")
    nhc: Nhc = _f({}, "the +NHC rows' non-holonomic constraints")
    zupt: Zupt = _f({}, "the +NHC rows' zero-velocity updates")
    constraints_in_gps_run: bool = _f(False, "the GPS-aided run applies the constraints too (false: the paper's)")


class Optimizer(Section):
    """Optimization of every method (bgfn.train); the defaults are the paper's Sec. 4.1."""

    epochs: Count = _f(1000, "epochs at most (paper: 1000)")
    batch_size: Count = _f(8, "windows per batch (paper: 8)")
    lr: Pos = _f(1.0e-3, "learning rate (train.lr per method wins)")
    weight_decay: NonNeg = _f(1.0e-2, "AdamW weight decay")
    schedule: Literal["plateau", "cosine", "none"] = _f("plateau", "plateau: ReduceLROnPlateau on the val. loss")
    lr_factor: Fraction = _f(0.5, "the plateau's factor")
    lr_patience: Annotated[int, Field(ge=0)] = _f(5, "the plateau's patience, epochs")
    min_lr: NonNeg = _f(1.0e-5, "lowest learning rate")
    patience: Count = _f(20, "early stopping: epochs without a better validation loss")
    min_delta: NonNeg = _f(1.0e-4, "relative improvement that counts as better")
    grad_clip: NonNeg = _f(1.0, "max global gradient norm (0: off)")
    max_train_windows: Count | None = _f(None, "evenly spaced subsample of the training windows (null: all)")
    max_val_windows: Count | None = _f(None, "... of the validation windows (null: all)")
    eval_batch_size: Count = _f(64, "windows per evaluation batch")
    num_threads: Count | None = _f(None, "torch CPU threads (null: torch's default)")


class LrSearch(Section):
    """Learning rate per method from a grid, on a tuning split inside the training windows (bgfn.train.lr_search)."""

    grid: list[Pos] | None = _f([1.0e-3, 3.0e-3, 1.0e-2, 3.0e-2], "rates tried (null: train.lr)")
    fraction: Fraction = _f(0.2, "share of the training windows that tunes")
    seed: Seed = _f(0, "seed of the tuning runs")
    extend: Annotated[int, Field(ge=0)] = _f(2, "rates tried one grid step past an edge that wins")
    epochs: Count | None = _f(None, "budget of one tuning run (null: the optimizer's)")
    patience: Count | None = _f(None, "its early-stopping patience (null: the optimizer's)")
    max_train_windows: Count | None = _f(None, "its training windows at most (null: the optimizer's)")
    max_val_windows: Count | None = _f(None, "its tuning windows at most (null: the optimizer's)")


_TOKEN_SIZES = {"smoke": {"dim": 16, "ffn_dim": 16, "depth": 1, "heads": 2, "time_steps": 2, "kernel_size": 3},
                "quick": {"dim": 32, "ffn_dim": 32, "depth": 1, "heads": 4, "time_steps": 2, "kernel_size": 3},
                "paper": {"dim": 256, "ffn_dim": 256, "depth": 4, "heads": 8, "time_steps": 4, "kernel_size": 3}}
_SIZES = {"bgfn": _TOKEN_SIZES, "transformer": copy.deepcopy(_TOKEN_SIZES),      # the same sizes, not the same dict
    "at_lstm": {"smoke": {"hidden": 8, "layers": 1}, "quick": {"hidden": 32, "layers": 1},
                "paper": {"hidden": 128, "layers": 2}},
    "mlp": {"smoke": {"n_recent": 1, "hidden": 16, "layers": 2}, "quick": {"n_recent": 1, "hidden": 64, "layers": 2},
            "paper": {"n_recent": 1, "hidden": 128, "layers": 3}},
}


class Train(Section):
    """Notebook 03: the learning problem (bgfn.learning, Eq. eq21 inputs, delta_p_gps targets) and its training."""

    datasets: Names = _f(DRIVES, "drives the networks train on")
    methods: Names = _f(METHODS, "method ids trained (bgfn, transformer, at_lstm, mlp)")
    seeds: Seeds = _f([0], "torch/numpy seeds of the runs (<method>_seed<k>.pt)")
    attitude_source: Literal["kf", "reference"] = _f("kf", "inputs' attitude: the INS/KF's (paper) | the truth's")
    window: Annotated[int, Field(ge=2)] = _f(200, "N IMU samples per input window (paper: 200 at 100 Hz)")
    alignment: Literal["ending", "next"] = _f("ending", "the window ends at the increment's end epoch | its start")
    yaw_encoding: Literal["unwrap", "relative", "raw"] = _f("unwrap", "yaw unwrapped along the window (9 channels)")
    target_frame: Literal["ned", "heading"] = _f("ned", "paper: (dN, dE) | along/cross-track of the last INS yaw")
    extra_channels: list[str] = _f([], "INS columns appended to the 9 inputs (not the paper's)")
    epoch_stride: Count = _f(1, "keep every k-th GNSS increment")
    margin_s: NonNeg = _f(30.0, "training never touches an outage +- this margin, s")
    protocol: Literal["honest", "leaky"] = _f("honest", "honest: outages +- margin never train | leaky: nothing out")
    val_fraction: Fraction = _f(0.2, "held-out block of GPS-available time")
    val_position: Any = _f("middle", "'start' | 'middle' | 'end' | a fraction in [0, 1]")
    target_screen_sigma: Pos | None = _f(10.0, "drop windows whose increment departs > this robust std (null: keep)")
    optimizer: Optimizer = _f({}, "the optimization, the same for every method")
    lr: dict[str, Pos] = _f({m: 1.0e-3 for m in METHODS}, "learning rate per method (lr_search replaces them)")
    lr_search: LrSearch = _f({}, "the learning-rate search")
    recheck_all_windows: bool = _f(False, "a run that never improved is trained again on all windows")
    recheck_runs: Literal["first", "all"] = _f("first", "which of those: the lowest seed per dataset and method | all")
    size: str = _f("paper", "which block of train.sizes is trained (smoke | quick | paper)")
    sizes: dict[str, dict[str, dict[str, Any]]] = _f(_SIZES, "model constructor keywords per method and size")


class Variant(Section):
    train: dict[str, Any] | None = _f(None, "train: keys merged over the profile's")


class VariantRuns(Section):
    datasets: Names | None = _f(None, "drives every variant trains on (null: train.datasets)")
    methods: Names | None = _f(None, "methods every variant trains (null: train.methods)")
    seeds: Seeds = _f([0], "seeds every variant trains")


class PseudoGps(Section):
    """Prediction mode, Eq. pred-gps: accumulated increments fused as position fixes."""

    std_m: Any = _f(None, "std of a pseudo fix per horizontal axis, m (null: the drive's median GNSS std)")
    std_growth_m_per_s: NonNeg = _f(0.0, "added std per second of outage, m/s")
    fusion_rate_hz: Pos = _f(1.0, "pseudo fixes per second (must divide the GNSS rate), Hz")


class Sweep(Section):
    """Beyond the paper: many outage starts, k-fold (fold k's networks never see fold k's outages)."""

    datasets: list[str] = _f(["rtklib-drive0708"], "drives of the sweep (the real drive: the decisive test)")
    n_starts: Count = _f(20, "outage starts per drive")
    durations_s: Annotated[list[Pos], Field(min_length=1)] = _f([10.0, 30.0, 60.0, 120.0], "outage durations, s")
    folds: Count = _f(2, "folds of the starts")
    seeds: Seeds = _f([0, 1, 2], "network seeds per fold")
    warmup_s: NonNeg = _f(60.0, "no start in the drive's first seconds (convergence, input window), s")
    train: dict[str, Any] | None = _f({}, "train: keys merged over the profile's for the fold networks (null: none)")
    n_boot: Count = _f(2000, "bootstrap replicates of the median's interval (whole starts resampled)")
    level: Fraction = _f(0.95, "the interval's level")
    boot_seed: Seed = _f(0, "the bootstrap's seed")


class Oracle(Section):
    """Beyond the paper: pseudo-GPS from the true increments plus white noise (bgfn.studies.outage_sweep.oracle)."""

    sigmas_m: list[NonNeg] = _f([0.0, 0.05, 0.1, 0.2, 0.5, 1.0, 2.0, 5.0, 10.0], "noise std per increment, m")
    seeds: Seeds = _f([0, 1], "noise draws per sigma > 0")
    durations_s: list[Pos] = _f([30.0, 60.0], "sweep durations it runs (at most the sweep's longest), s")


class NeesScan(Section):
    """Beyond the paper, notebook 08: the INS NEES against the filter's gyro bias instability (studies.ins_fidelity)."""

    gyro_bias_dps: Annotated[list[Pos], Field(min_length=2)] = _f(
        [0.005, 0.01, 0.02, 0.03, 0.05, 0.1, 0.2, 0.3], "instabilities scanned on a recorded drive, deg/s")
    twin_gyro_bias_dps: Annotated[list[Pos], Field(min_length=2)] | None = _f(
        None, "those its trajectory twins scan (null: gyro_bias_dps), deg/s")
    twin_seeds: Seeds = _f([1, 2, 3], "seeds of the twins' simulated IMU")


#: What an odometer network reads (bgfn.learning.odometry.ODOMETER_INPUTS).
OdometerInput = Literal["imu", "band_frames"]


class Odometer(Section):
    """Beyond the paper: the bars a learned odometer (speed + std, fused with the NHC rows) must clear."""

    datasets: list[str] | None = _f(DRIVES, "drives of the bars (null: the sweep's; []: none)")
    methods: list[Method] = _f(METHODS, "the networks as odometers (<METHOD>-ODO; []: none)")
    network_datasets: list[str] | None = _f(None, "drives whose networks train as odometers (null: every bar drive)")
    network_seeds: Any = _f([0], "seeds per fold: a list, or per drive with a default")
    paper_outages: bool = _f(True, "also each drive's two evaluation outages, as one more fold")
    window_s: Annotated[float, Field(ge=0.5)] = _f(2.0, "RIDGE-ODO's IMU window (its 0.5 Hz band needs 2 s), s")
    sigmas_mps: list[Pos] = _f([0.05, 0.1, 0.2, 0.5, 1.0, 2.0], "the oracle speed's noise std, m/s")
    walk_mps_per_sqrt_s: NonNeg = _f(0.02, "ORACLE-SPEED+WALK's random walk, m/s per sqrt(s) (0: no such rows)")
    seeds: Seeds = _f([0], "noise draws of the oracle speed")
    hold_std_mps: Pos = _f(1.0, "std of the speed held from the outage start, m/s")
    ridge_alpha: Pos = _f(1.0, "ridge penalty on the standardized band energies")
    gate_probability: Fraction | None = _f(0.999, "chi-square gate of the speed row, 1 dof (null: none)")
    lr_search: bool = _f(False, "each network's rate per fold from train.lr_search (false: train.lr)")
    inputs: OdometerInput | dict[str, OdometerInput] = _f(
        "band_frames", "networks read band frames | the raw IMU samples; or per network with a default")
    val_blocks: Count = _f(4, "validation blocks spread over the drive")
    curve_folds: list[Count] = _f([2, 4, 10, 20], "RIDGE-ODO refitted in each of these numbers of folds")
    ensemble: bool = _f(True, "each network's seeds also as one equal-weight ensemble (<METHOD>-ODO-ENS)")
    ensemble_recalibrate: bool = _f(False, "scale the ensemble's std once more to NIS = 1 on validation")
    correlation: bool = _f(True, "fuse with R = kappa std^2, kappa from the errors' autocorrelation (false: std^2)")
    correlation_max_lag_s: Pos = _f(10.0, "longest lag of that autocorrelation, s")
    calibration_blocks: bool = _f(True, "every other validation block calibrates the std, the others stop training")
    train: dict[str, Any] | None = _f({"optimizer": {"epochs": 60, "patience": 15}},
                                      "train: keys merged over the sweep's for the networks (null: none)")


class Evaluate(Section):
    """Notebook 04: the paper's two 30 s outages (Tables 1-2) and the studies beyond them."""

    datasets: Names = _f(DRIVES, "drives of the outage tables")
    real_imu: bool = _f(False, "NaveGo's recorded IMU files when present")
    methods: Names = _f(METHODS, "method ids evaluated")
    seeds: Seeds | None = _f(None, "networks of notebook 03 evaluated (null: train.seeds)")
    seed_aggregate: Literal["median", "first"] = _f("median", "tables: median over the seeds | the first seed")
    pseudo_gps: PseudoGps = _f({}, "the networks' pseudo-GPS fixes")
    series_rate_hz: Pos = _f(10.0, "decimation of the saved error series, Hz")
    train_missing: bool = _f(True, "a missing notebook-03 network is trained here")
    nhc_rows: bool = _f(True, "also INS+NHC and every network with the vehicle constraints")
    sweep: Sweep = _f({}, "the outage sweep")
    oracle: Oracle = _f({}, "the oracle pseudo-GPS")
    odometer: Odometer = _f({}, "the learned odometer's bars")
    nees_scan: NeesScan = _f({}, "notebook 08's NEES scan and its trajectory twins")


class Fleet(Section):
    """Beyond the paper: several drives of one vehicle, the learned odometer trained on some and tested on the others
    (bgfn.studies.fleet; notebook 11). Off while ``drives`` is empty."""

    drives: list[str] = _f([], "built-in dataset keys or own-log folders of one vehicle ([]: no fleet)")
    pieces: Annotated[int, Field(ge=2)] | None = _f(None, "cut the one drive of drives into this many contiguous "
                                                          "pieces, a stand-in labelled pieces of one drive (null: none)")
    protocol: Literal["leave_one_out", "named"] = _f("leave_one_out", "each drive tested on the others | train/test")
    train: list[str] = _f([], "protocol named: the training drives (names as the fleet's table shows them)")
    test: list[str] = _f([], "protocol named: the test drives")
    rate_hz: Pos | None = _f(None, "one sample rate for the fleet (null: the lowest of its drives), Hz")
    bandwidth_fraction: Fraction = _f(0.8, "every drive low-passed at this fraction of that rate's Nyquist")
    stationary_max_speed_mps: Pos = _f(0.05, "reference speed under which the vehicle stands, m/s")
    stationary_min_s: Pos = _f(3.0, "shortest standstill that levels, scales and de-biases a drive, s")
    gravity_mps2: Pos = _f(9.80665, "the specific force's norm at a standstill (accelerometer scale), m/s^2")
    label_max_diff_mps: Pos = _f(0.5, "reference and GNSS speed disagree beyond this, m/s")
    label_disagree: Literal["drop", "gnss"] = _f("drop", "a disagreeing stretch: left out | labelled from GNSS")
    label_min_s: NonNeg = _f(2.0, "a disagreement shorter than this is noise, not a stretch, s")
    out_of_range_share: Fraction = _f(0.1, "an outage is out of range when more of its epochs than this share lie "
                                           "outside the training drives' speeds")
    networks: bool = _f(False, "the odometer networks too (evaluate.odometer.methods; false: RIDGE-ODO only)")
    inputs: dict[Method, Literal["imu", "band_frames"]] = _f({}, "per network, what it reads where not "
                                                                 "evaluate.odometer.inputs, e.g. {bgfn: imu}")
    curve: bool = _f(True, "the learning curve (1 .. N-1 training drives)")
    curve_networks: bool = _f(False, "the networks in the learning curve too, with networks (each training set "
                                     "trains them again; false: RIDGE-ODO's curve only)")
    curve_max_combinations: Count = _f(10, "learning curve: every combination of training drives, else this many "
                                           "drawn per size")
    curve_seed: Seed = _f(0, "the draw of those combinations")
    curve_duration_s: Pos = _f(60.0, "the curve's median max error at this sweep duration, s")


class Energy(Section):
    """Notebook 05: synaptic-operation energy, 45 nm (Horowitz 2014)."""

    e_mac_pj: Pos = _f(4.6, "one 32-bit float multiply-accumulate, pJ (3.7 + 0.9)")
    e_ac_pj: Pos = _f(0.9, "one 32-bit float accumulate = one synaptic operation, pJ")
    dataset: str | None = _f(None, "networks of this drive (null: the first of train.datasets where a BGFN learned)")
    seed: Seed | None = _f(None, "checkpoint seed (null: the median val. RMSE among the trained BGFNs)")
    allow_untrained: bool = _f(False, "accept a BGFN whose best epoch is 0")
    max_windows: Count | None = _f(128, "validation windows that give the firing rates (null: all)")
    batch_size: Count = _f(32, "windows per forward pass")
    sweep_time_steps: Annotated[list[Count], Field(min_length=1)] = _f([1, 2, 4, 8, 16], "T_s of the analytic sweep")
    sweep_max_rate: Annotated[float, Field(gt=0, le=1)] = _f(0.5, "firing rates 0..this of the rate sweep")
    crosscheck_windows: Count = _f(8, "windows counted by SpikingJelly's operation counter")
    crosscheck_tolerance_pct: Pos = _f(5.0, "|E_ours / E_spikingjelly - 1| allowed, %")


class Profile(Section):
    """A whole profile, merged over its ``base:`` chain and the defaults."""

    profile: str = Field(description="the file's name")
    description: str = Field(description="one line on what the profile runs")
    seed: Seed = Field(description="the profile's seed")
    datasets: Names | None = _f(None, "one list for the datasets of every notebook (bgfn.config.DATASET_KEYS)")
    parallel: Parallel = _f({}, "where the independent runs go (no result depends on it)")
    outage_windows: Any = Field(description="[[start, duration], ...] s, or per dataset a list or a rule")
    data: Data = _f({}, "notebook 01")
    nav: Nav = _f({}, "notebook 02")
    train: Train = _f({}, "notebook 03")
    variants: dict[str, Variant] = _f({}, "named train: overrides trained beside the main networks")
    variant_runs: VariantRuns = _f({}, "which networks every variant trains")
    evaluate: Evaluate = _f({}, "notebook 04")
    energy: Energy = _f({}, "notebook 05")
    fleet: Fleet = _f({}, "beyond the paper: a fleet of drives (notebook 11)")


#: Top-level keys without a default: every profile chain sets them.
REQUIRED: tuple[str, ...] = tuple(k for k, f in Profile.model_fields.items() if f.is_required())


def defaults_of(model: type[BaseModel]) -> dict:
    """The defaults of ``model`` as plain data (mappings of sections, keys spelt as in YAML; required keys left out)."""
    out = {}
    for name, field in model.model_fields.items():
        if field.is_required():
            continue
        out[field.alias or name] = field.get_default(call_default_factory=True)
    for name, field in model.model_fields.items():
        key = field.alias or name
        sub = field.annotation
        if isinstance(sub, type) and issubclass(sub, BaseModel) and out.get(key) == {}:
            out[key] = defaults_of(sub)
    return out


_DEFAULTS: dict | None = None


def defaults(path: str = "") -> dict:
    """The defaults of the section at dotted ``path`` (``""``: every section; ``"nav.alignment"``), a fresh copy."""
    global _DEFAULTS
    if _DEFAULTS is None:
        _DEFAULTS = {k: v for k, v in defaults_of(Profile).items() if k != "datasets"}   # a file's own list, spread on read
    out = _DEFAULTS
    for key in [k for k in path.split(".") if k]:
        out = out[key]
    return copy.deepcopy(out)

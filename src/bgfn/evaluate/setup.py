"""Names, defaults and configuration of the outage evaluation (a profile's ``evaluate:`` section), and the
setup of one evaluation run: notebook 04's parameters over that section, the datasets chosen, the outages."""

from __future__ import annotations

import copy
from dataclasses import dataclass, field
from typing import Any, Sequence

from bgfn import settings
from bgfn.data import acquire
from bgfn.errors import DataError
from bgfn.nav import outages
from bgfn.paper import METHOD_LABELS, TESTS, nhc_label
from bgfn.parallel import Runner

#: The standalone INS and the networks, each also with the vehicle constraints (``+NHC``, bgfn.nav.constraints).
_AIDED: tuple[str, ...] = ("INS", "MLP", "AT-LSTM", "BGFN", "Transformer")
#: Rows of the outage tables, in order: the paper's filter, the same with the vehicle constraints, then GPS.
TABLE_METHODS: tuple[str, ...] = _AIDED + tuple(nhc_label(m) for m in _AIDED) + ("GPS",)
#: Rows with one value per outage whatever the training seed (no network).
SEEDLESS_METHODS: tuple[str, ...] = ("INS", nhc_label("INS"), "GPS")
#: Methods of the paper's figures (and ours with the constraints, dashed) and their colours (red, yellow, black,
#: blue; a ``+NHC`` row takes its method's colour).
FIGURE_METHODS: tuple[str, ...] = ("INS", "MLP", "AT-LSTM", "BGFN", nhc_label("INS"), nhc_label("BGFN"))
_BASE_COLORS: dict[str, str] = {"INS": "red", "MLP": "goldenrod", "AT-LSTM": "black", "BGFN": "blue",
                                "Transformer": "tab:purple"}
COLORS: dict[str, str] = {**_BASE_COLORS, **{nhc_label(m): c for m, c in _BASE_COLORS.items()}, "GPS": "tab:green"}
#: Columns of the outage tables (``tables/outage_dataset.csv``, ``outage_field.csv``).
METRIC_COLUMNS: tuple[str, ...] = ("max_east_m", "max_north_m", "rmse_h_m", "final_h_m")
TABLE_COLUMNS: tuple[str, ...] = ("outage", "method") + METRIC_COLUMNS
#: Columns of ``tables/outage_sweep.csv``; ``increment_rmse_m``: a network's predicted delta_p_gps against the true
#: ones inside the outage, RMSE per horizontal axis (:func:`bgfn.studies.outage_sweep.increments.increment_rmse`; NaN for INS, GPS);
#: ``nees_h``: the horizontal NEES at the window's end against the filter's own covariance (:mod:`bgfn.studies.ins_fidelity.nees`).
SWEEP_COLUMNS: tuple[str, ...] = ("dataset", "start_s", "duration_s", "method", "seed", "fold", "max_east_m",
                                  "max_north_m", "max_h_m", "rmse_h_m", "final_h_m", "increment_rmse_m", "nees_h")
#: The paper's test -> our outage table file (``results/<profile>/tables/``).
TABLE_FILES: dict[str, str] = {test: spec["file"] for test, spec in TESTS.items()}
#: Simulated dataset -> the dataset with NaveGo's recorded IMU, and the file it needs.
REAL_IMU_DATASETS: dict[str, tuple[str, str]] = {"turin-sim-ekinox": ("navego-ekinox", "ekinox_imu.mat"),
                                                 "turin-sim-mpu6000": ("navego-mpu6000", "mpu6000_imu.mat")}

#: Defaults of the ``evaluate:`` section, every key of it (their home, with each key's meaning:
#: :class:`bgfn.settings.Evaluate`).
EVALUATE_DEFAULTS: dict[str, Any] = settings.defaults("evaluate")


def merge_checked(base: dict, upd: dict, where: str, strict: bool = True) -> dict:
    """``base`` updated with ``upd`` recursively (the ``train`` key replaced whole). Unlike
    :func:`bgfn.config.merge_sections` it checks the keys: with ``strict`` an unknown key of ``upd`` raises a
    DataError naming ``where``."""
    out = copy.deepcopy(base)
    for key, value in (upd or {}).items():
        if strict and key not in out:
            raise DataError(f"params {where}", key, f"one of {sorted(out)}", "unknown key")
        if isinstance(out.get(key), dict) and isinstance(value, dict) and key != "train":
            out[key] = merge_checked(out[key], value, f"{where}.{key}", strict)
        else:
            out[key] = copy.deepcopy(value)
    return out


def evaluate_config(section: dict | None, train_section: dict | None = None) -> dict:
    """``EVALUATE_DEFAULTS`` updated with a profile's ``evaluate:`` section (unknown keys raise).

    ``seeds: null`` takes ``train.seeds``. Checks the sweep sizes and the seed aggregate.
    """
    cfg = merge_checked(EVALUATE_DEFAULTS, section or {}, "evaluate")
    if cfg["seeds"] is None:
        cfg["seeds"] = list((train_section or {}).get("seeds") or [0])
    if cfg["seed_aggregate"] not in ("median", "first"):
        raise DataError("params evaluate", "seed_aggregate", "'median' or 'first'", repr(cfg["seed_aggregate"]))
    unknown = [m for m in cfg["methods"] if m not in METHOD_LABELS]
    if unknown:
        raise DataError("params evaluate", "methods", f"ids among {sorted(METHOD_LABELS)}", repr(unknown))
    sw = cfg["sweep"]
    if int(sw["n_starts"]) < 1 or int(sw["folds"]) < 1 or int(sw["folds"]) > int(sw["n_starts"]):
        raise DataError("params evaluate.sweep", "n_starts/folds", "1 <= folds <= n_starts",
                        f"{sw['n_starts']} starts, {sw['folds']} folds")
    if not sw["durations_s"] or min(sw["durations_s"]) <= 0:
        raise DataError("params evaluate.sweep", "durations_s", "positive durations, s", repr(sw["durations_s"]))
    return cfg


@dataclass(frozen=True)
class RealImuChoice:
    """What ``real_imu`` chose for one simulated dataset (:func:`choose_datasets`).

    Attributes
    ----------
    asked : str
        The profile's dataset (simulated IMU).
    twin : str
        The dataset with NaveGo's recorded IMU (:data:`REAL_IMU_DATASETS`).
    file : str
        The recorded IMU's file.
    origin : str or None
        Where the file was found (:func:`bgfn.data.acquire.resolve`); None: absent, ``asked`` stands in.
    """

    asked: str
    twin: str
    file: str
    origin: str | None

    @property
    def used(self) -> str:
        """The dataset evaluated."""
        return self.twin if self.origin is not None else self.asked


def choose_datasets(datasets: Sequence[str], real_imu: bool) -> tuple[list[str], list[RealImuChoice]]:
    """The datasets to evaluate: with ``real_imu`` the NaveGo recorded-IMU twin when its file is present.

    Returns
    -------
    names : list of str
    choices : list of RealImuChoice
        One per dataset that has a recorded-IMU twin (none without ``real_imu``).
    """
    names, choices = [], []
    for d in datasets:
        if not real_imu or d not in REAL_IMU_DATASETS:
            names.append(d)
            continue
        real, fname = REAL_IMU_DATASETS[d]
        res = acquire.resolve(fname, download=False)
        choices.append(RealImuChoice(d, real, fname, res.origin if res.path is not None else None))
        names.append(choices[-1].used)
    return names, choices


@dataclass(frozen=True)
class OwnOutages:
    """A dataset of the tables whose outages are not the profile's default list: a ``rule`` that picks them from
    the drive (its name), else its own ``windows`` ``[[start, duration], ...]``, s."""

    dataset: str
    rule: str | None = None
    windows: list | None = None


@dataclass
class EvaluationSetup:
    """What one run of notebook 04 evaluates (:func:`evaluation_setup`).

    Attributes
    ----------
    profile : str
    description : str
        The profile's one-line description.
    config : dict
        :func:`evaluate_config` of the profile's section with the notebook's parameters.
    datasets : list of str
        Datasets of the two tables (``tab-out1-exin``, ``tab-real``), after the real-IMU choice
        (:func:`choose_datasets`).
    choices : list of RealImuChoice
        What ``real_imu`` chose for the table datasets (empty without it).
    sweep_datasets : list of str
    sweep_choices : list of RealImuChoice
        The same for the outage sweep.
    windows : list of (float, float)
        The evaluation outages ``(start, duration)``, s, of the profile's one list or ``default`` entry
        (:func:`bgfn.nav.outages.default_windows`; empty when that is a rule); each dataset's own are in its
        :class:`~bgfn.evaluate.tables.TableResult` (``windows``).
    own_outages : list of OwnOutages
        The datasets of the tables whose entry differs from ``windows``: its list, or the rule that picks them.
    runner : bgfn.parallel.Runner
        Where the independent runs of the sweep and the oracle go (the profile's ``parallel:`` section).
    """

    profile: str
    description: str
    config: dict
    datasets: list[str]
    choices: list[RealImuChoice]
    sweep_datasets: list[str]
    sweep_choices: list[RealImuChoice]
    windows: list = field(default_factory=list)
    own_outages: list[OwnOutages] = field(default_factory=list)
    runner: Runner = field(default_factory=Runner)


#: Notebook 04's parameters and the profile keys they set (:func:`bgfn.profile_schema.with_overrides`, in the
#: notebook's first cell; ``sweep_datasets`` ``[]`` skips the sweep).
PARAMETER_KEYS = {"real_imu": "evaluate.real_imu", "datasets": "evaluate.datasets", "methods": "evaluate.methods",
                  "seeds": "evaluate.seeds", "sweep_datasets": "evaluate.sweep.datasets"}


def evaluation_setup(cfg: dict) -> EvaluationSetup:
    """Notebook 04's configuration over a profile: the evaluate section with its defaults, the datasets, the outages.

    Parameters
    ----------
    cfg : dict
        The checked profile (:func:`bgfn.profile_schema.load_profile`), the notebook's parameters set over it
        (:data:`PARAMETER_KEYS`).

    Returns
    -------
    EvaluationSetup
    """
    ecfg = evaluate_config(cfg.get("evaluate"), cfg.get("train"))
    names, choices = choose_datasets(ecfg["datasets"], ecfg["real_imu"])
    sweep_names, sweep_choices = choose_datasets(ecfg["sweep"]["datasets"], ecfg["real_imu"])
    default = outages.default_windows(cfg) or []
    own = []
    for name in names:                     # datasets whose outages are not the default list
        entry = outages.outage_entry(cfg, name)
        if outages.is_rule(entry):
            own.append(OwnOutages(name, rule=entry["rule"]))
        elif outages.outage_windows(cfg, dataset=name) != default:
            own.append(OwnOutages(name, windows=[list(w) for w in outages.outage_windows(cfg, dataset=name)]))
    return EvaluationSetup(cfg["profile"], cfg["description"], ecfg, names, choices, sweep_names,
                           sweep_choices, default, own, Runner.of(cfg))

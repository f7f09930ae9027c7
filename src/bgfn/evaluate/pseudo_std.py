"""How much the pseudo-fix standard deviation matters (beyond the paper, which does not state it).

The tables fuse a pseudo-GPS fix (Eq. pred-gps) like a GNSS fix (``pseudo_gps.std_m: null``: the drive's median
GNSS std). The sensitivity run fuses it with each network's own held-out accuracy instead
(``std_m: validation``: validation RMSE of one increment per axis times ``sqrt(k)`` after ``k`` accumulated
increments, :func:`bgfn.evaluate.hybrid.run_outages`), for the same networks (the first training seed only, to
save time) in the same outages, without the ``+NHC`` rows. INS and GPS do not fuse pseudo fixes, so their rows
do not change.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from bgfn.evaluate.tables import TableResult, aggregate_seeds, evaluate_dataset, table_file
from bgfn.io import atomic_write_csv

#: Columns of :attr:`Sensitivity.table`: max errors (m) with the tables' pseudo std, then with the validation std.
SENSITIVITY_COLUMNS: tuple[str, ...] = ("outage", "method", "max_east_m", "max_north_m",
                                        "max_east_m (validation std)", "max_north_m (validation std)")


@dataclass
class Sensitivity:
    """The pseudo-std sensitivity run of one dataset.

    Attributes
    ----------
    seed : int
        The training seed whose networks were run.
    alternative : TableResult
        Every method with ``pseudo_gps.std_m: validation``.
    table : DataFrame
        :data:`SENSITIVITY_COLUMNS`, per outage and method (:func:`sensitivity_table`).
    """

    seed: int
    alternative: TableResult
    table: pd.DataFrame


def sensitivity_table(result: TableResult, alternative: TableResult, seed: int) -> pd.DataFrame:
    """Max east/north errors (m) of ``seed``'s networks with the tables' pseudo std beside the validation std.

    The left side is ``seed``'s own runs in ``result`` (not the seed aggregate of the tables), so that both
    sides come from the same networks; INS and GPS (no seed) are on both sides.

    Returns
    -------
    DataFrame
        :data:`SENSITIVITY_COLUMNS`, one row per outage and method present on both sides.
    """
    per_seed = result.per_seed
    base = aggregate_seeds(per_seed[per_seed["seed"].isna() | (per_seed["seed"] == seed)], "first")
    both = base.merge(alternative.table, on=["outage", "method"], suffixes=("", " (validation std)"))
    return both[list(SENSITIVITY_COLUMNS)]


def pseudo_std_sensitivity(cfg: dict, profile: str, result: TableResult, ecfg: dict) -> Sensitivity:
    """Run ``result``'s dataset again with ``pseudo_gps.std_m: validation``, with the networks of the first
    seed of ``ecfg['seeds']`` (those of ``result.models``; none is trained or loaded again).

    Parameters
    ----------
    cfg : dict
        The profile.
    profile : str
    result : TableResult
        The tables' run (:func:`bgfn.evaluate.tables.evaluate_dataset`); its drive is reused when it has one.
    ecfg : dict
        The evaluation configuration of the tables (:func:`bgfn.evaluate.setup.evaluate_config`).
    """
    seed = ecfg["seeds"][0]
    alt_cfg = {**ecfg, "pseudo_gps": {**ecfg["pseudo_gps"], "std_m": "validation"}}
    alternative = evaluate_dataset(cfg, profile, result.dataset, drive=result.drive, ecfg=alt_cfg,
                                   models={k: m for k, m in result.models.items() if k[1] == seed}, nhc_rows=False)
    return Sensitivity(seed, alternative, sensitivity_table(result, alternative, seed))


def save_sensitivity(out, sensitivity: Sensitivity) -> Path:
    """Write the sensitivity run's seed aggregate (``TABLE_COLUMNS``) to
    ``<out>/tables/outage_<test>_std_validation.csv``, atomically; returns the path."""
    stem = table_file(sensitivity.alternative.test)[: -len(".csv")]
    path = Path(out) / "tables" / f"{stem}_std_validation.csv"
    atomic_write_csv(path, sensitivity.alternative.table, float_format="%.4f")
    return path

"""The energy of the learned odometers (beyond the paper): ``BGFN-ODO`` against its ANN twin
``Transformer-ODO``, counted by the same rules as the paper's model (:mod:`bgfn.energy.rules`).

Which networks: the odometers that notebook 07 trained (:mod:`bgfn.studies.odometer.bars`) on the first dataset of
``evaluate.odometer.datasets`` (null: the sweep's), recorded drives first, in sweep fold 0, with the first of
``evaluate.odometer.network_seeds``. Which windows: ``energy.max_windows`` IMU windows of the odometer's length
(``evaluate.odometer.window_s``) evenly spaced over that drive: an odometer reads the raw body-frame IMU only, so
every stretch of the drive is an input it meets in an outage. Each network reads them through the odometers'
front end (``evaluate.odometer.inputs``, :func:`bgfn.learning.odometry.network_inputs`) with its own training
normalization. The front end (band powers of short frames, the same for both networks and for ``RIDGE-ODO``)
is preprocessing, not counted.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from bgfn.config import odometer_datasets, odometer_inputs, odometer_network_seeds
from bgfn.data import load_drive
from bgfn.data.registry import recorded_first
from bgfn.energy.checkpoint import MEASURED, SPIKING, check_trained, improved
from bgfn.energy.counts import layer_counts, mean_rate
from bgfn.energy.tables import reduction_pct, stack_tables, table_from_counts, total_energy_uj
from bgfn.learning import odometry as lo
from bgfn.nav.constraints import DEFAULT_PLATFORM
from bgfn.paper import odometer_label
from bgfn.train import load_trained
from bgfn.train.checkpoints import card_path, checkpoint_name, odometer_models_dir

#: The sweep fold whose odometers are measured (every fold trains the same networks on other windows).
FOLD = 0


def odometer_dataset(cfg: dict, profile: str | None = None) -> str | None:
    """The dataset whose odometers are measured: the first of the odometer bars' drives
    (:func:`bgfn.config.odometer_datasets`), recorded drives first, that is a car (notebook 07 trains no odometer
    for another platform; checked on the drive when ``profile`` is given); None when the profile trains no
    odometer network."""
    ecfg = cfg.get("evaluate") or {}
    oc = ecfg.get("odometer") or {}
    if not oc.get("methods"):
        return None
    names = recorded_first(odometer_datasets(oc, (ecfg.get("sweep") or {}).get("datasets")))
    if profile is not None:
        names = [n for n in names if load_drive(n, profile=profile).meta.get("platform", DEFAULT_PLATFORM) == "car"]
    return names[0] if names else None


@dataclass
class OdometerEnergy:
    """Energy per prediction of the measured odometers.

    Attributes
    ----------
    dataset : str
    seed : int
    paths : dict
        Method -> checkpoint (the methods of :data:`bgfn.energy.checkpoint.MEASURED` that were trained).
    tables : dict
        Method -> per-layer energy table (:func:`bgfn.energy.tables.table_from_counts`).
    mean_rate : float
        BGFN-ODO's mean input firing rate.
    n_windows : int
    improved : dict
        Method -> whether training improved on its initial network (:func:`bgfn.energy.checkpoint.improved`); a
        BGFN-ODO that did not gives an untrained network's energy, and no saving is claimed from it.
    """

    dataset: str
    seed: int
    paths: dict[str, Path]
    tables: dict[str, pd.DataFrame]
    mean_rate: float
    n_windows: int
    improved: dict[str, bool] = field(default_factory=dict)

    @property
    def table(self) -> pd.DataFrame:
        """Every measured network's layers (:func:`bgfn.energy.tables.stack_tables`; ``model``: ``BGFN-ODO`` ...),
        the dataset in the first column; with :attr:`improved`, whether each network trained (``improved``, last)."""
        table = stack_tables(self.tables)
        table.insert(0, "dataset", self.dataset)
        if self.improved:
            table["improved"] = [self.improved.get(m, True) for m, t in self.tables.items() for _ in range(len(t))]
        return table

    @property
    def reduction_pct(self) -> float:
        """BGFN-ODO's energy saved against its twin, % (NaN without the twin, or when BGFN-ODO did not train)."""
        if not set(MEASURED) <= set(self.tables) or not self.improved.get("bgfn", True):
            return float("nan")
        return reduction_pct(self.tables["bgfn"], self.tables["transformer"])

    def totals(self) -> pd.DataFrame:
        """One row per network: label, energy per prediction (µJ), MACs, SOPs."""
        rows = []
        for m, t in self.tables.items():
            tot = t[t["layer"] == "total"].iloc[0]
            rows.append({"model": tot["model"], "energy_uj": total_energy_uj(t), "macs": float(tot["macs"]),
                         "sops": float(tot["sops"])})
        return pd.DataFrame(rows)


def odometer_energy(profile: str, cfg: dict, e_mac: float, e_ac: float, batch_size: int = 32) -> OdometerEnergy | None:
    """Count the measured odometers (module docstring); None when the profile trains no odometer network.

    Raises
    ------
    FileNotFoundError
        BGFN-ODO's checkpoint is missing (notebook 07 writes it); the message names the file.
    bgfn.errors.DataError
        BGFN-ODO never improved on its initial weights (unless ``energy.allow_untrained``).
    """
    dataset = odometer_dataset(cfg, profile)
    if dataset is None:
        return None
    oc = cfg["evaluate"]["odometer"]
    seed = odometer_network_seeds(oc, dataset)[0]
    folder = odometer_models_dir(profile, dataset, FOLD, create=False)
    paths = {m: folder / checkpoint_name(m, seed) for m in MEASURED if m in oc["methods"]}
    if "bgfn" not in paths or not paths["bgfn"].is_file():
        raise FileNotFoundError(f"BGFN-ODO's checkpoint not found: {folder / checkpoint_name('bgfn', seed)} -- "
                                f"notebook 07_learned_odometer.ipynb trains it (evaluate.odometer.methods)")
    paths = {m: p for m, p in paths.items() if p.is_file()}
    allow = bool(cfg["energy"]["allow_untrained"])
    # BGFN-ODO's card must be there (its firing rates decide its energy); the twin's says only whether it trained
    cards = {m: json.loads(card_path(p).read_text()) if m in SPIKING or card_path(p).is_file() else {}
             for m, p in paths.items()}
    for m in SPIKING:
        check_trained(cards[m], card_path(paths[m]), allow)
    trained = {m: load_trained(p, device="cpu") for m, p in paths.items()}
    drive = load_drive(dataset, profile=profile)
    window, rate = lo.window_samples(drive.imu, oc["window_s"])
    t = drive.imu["time"].to_numpy(float)
    n = int((cfg.get("energy") or {}).get("max_windows") or 128)
    ws = lo.speed_windows(drive.imu, np.linspace(t[window], t[-1], n), window)
    fed = {m: lo.network_inputs(ws, odometer_inputs(oc, m), rate) for m in trained}     # each network's front end
    counts = {m: layer_counts(tm.model.eval(), tm.norm.x(fed[m].x).astype(np.float32), batch_size)
              for m, tm in trained.items()}
    tables = {m: table_from_counts(c, odometer_label(m), e_mac, e_ac) for m, c in counts.items()}
    return OdometerEnergy(dataset, seed, paths, tables, mean_rate(counts["bgfn"]), len(ws),
                          {m: improved(c) for m, c in cards.items()})

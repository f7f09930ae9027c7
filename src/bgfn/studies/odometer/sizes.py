"""The learned odometers at another model size, run on another machine and kept in ``data/measured/``.

quick trains its odometer networks at the smoke size; whether their failure against INS+NHC is a matter of size is
a question for the paper's size (the profile ``paper-odometer``), minutes on a GPU and hours here. Such a run is
made once, elsewhere: ``python -m bgfn odometers --profile paper-odometer`` runs the odometer bars alone and writes
the run's facts (:func:`write_run_facts`); ``--record`` keeps the summary and the networks' facts, with the date,
the commit and the device, in :data:`MEASURED_FILE` and :data:`MEASURED_NETWORKS` (:func:`record`). The results page
reads them (:func:`read_measured`) beside quick's own rows.
"""

from __future__ import annotations

import datetime
import json
import os
import time
from pathlib import Path

import numpy as np
import pandas as pd
import torch

from bgfn.config import PROJECT_ROOT, SHARED_TABLES, git_commit, results_dir
from bgfn.errors import DataError
from bgfn.studies.odometer.bars import NETWORK_COLUMNS, ORACLE, ORACLE_WALK, SUMMARY_COLUMNS
from bgfn.io import atomic_write_csv, atomic_write_text

#: Summary rows of runs made elsewhere (:func:`record`).
MEASURED_FILE = PROJECT_ROOT / "data" / "measured" / "odometer_sizes.csv"
#: Their networks' facts (:data:`bgfn.studies.odometer.bars.NETWORK_COLUMNS`).
MEASURED_NETWORKS = PROJECT_ROOT / "data" / "measured" / "odometer_sizes_networks.csv"
#: What describes a run, before the table's own columns.
RUN_COLUMNS: tuple[str, ...] = ("profile", "size", "inputs", "epochs_max", "batch_size", "device", "wall_s", "date",
                                "commit", "correlation")
#: The run's facts beside its tables.
RUN_FACTS = "odometer_run.json"


def device_name() -> str:
    """The GPU torch trains on, else ``CPU (<n> cores)``."""
    if torch.cuda.is_available():
        return torch.cuda.get_device_name(0)
    return f"CPU ({os.cpu_count()} cores)"


def write_run_facts(profile: str, cfg: dict, t0: float, jobs: str) -> Path:
    """``results/<profile>/odometer_run.json``: the device, the wall time since ``t0`` (``time.perf_counter``), the
    runner (``jobs``), the networks' inputs, torch's version, the odometers' model size and budget, whether the filter
    fused them with their error correlation (``evaluate.odometer.correlation``), and the commit (``$BGFN_COMMIT``
    where set: a copy of the tree on another machine may carry no git, or another one's)."""
    tc = (cfg["evaluate"]["odometer"].get("train") or {}).get("optimizer") or {}
    facts = {"profile": profile, "size": (cfg["evaluate"]["sweep"].get("train") or {}).get("size"),
             "inputs": inputs if isinstance(inputs := cfg["evaluate"]["odometer"].get("inputs"), str | None)
             else ", ".join(f"{m}: {i}" for m, i in inputs.items()),          # per network: one cell of the table
             "correlation": bool(cfg["evaluate"]["odometer"]["correlation"]),
             "epochs_max": tc.get("epochs"), "batch_size": tc.get("batch_size"), "device": device_name(),
             "wall_s": round(time.perf_counter() - t0, 1), "jobs": jobs, "torch": torch.__version__,
             "date": datetime.date.today().isoformat(), "commit": os.environ.get("BGFN_COMMIT") or git_commit()}
    path = results_dir(profile) / RUN_FACTS
    atomic_write_text(path, json.dumps(facts, indent=1))
    return path


def record(profile: str, note: str = "", measured: Path = MEASURED_FILE,
           measured_networks: Path = MEASURED_NETWORKS) -> list[Path]:
    """Keep ``profile``'s last odometer run (its tables and :data:`RUN_FACTS`) in the measured files: the summary
    without the oracle's grid, and the networks' facts, each row led by :data:`RUN_COLUMNS` and ended by ``note``;
    the profile's earlier rows are replaced, other profiles' kept. Every input is checked before either file is
    written."""
    res = results_dir(profile, create=False)
    paths = {"facts": res / RUN_FACTS, "summary": res / "tables" / SHARED_TABLES["odometer_summary"],
             "networks": res / "tables" / SHARED_TABLES["odometer_networks"]}
    for what, path in paths.items():
        if not path.is_file():
            raise DataError(str(path), what, f"a finished `python -m bgfn odometers --profile {profile}`", "absent")
    facts = json.loads(paths["facts"].read_text())
    run = {c: facts.get(c) for c in RUN_COLUMNS}
    run["commit"] = run["commit"] or "unknown"
    summary = pd.read_csv(paths["summary"])
    summary = summary[~summary["method"].isin([ORACLE, ORACLE_WALK])]
    networks = pd.read_csv(paths["networks"])
    written = []
    for table, cols, path in ((summary, SUMMARY_COLUMNS, measured), (networks, NETWORK_COLUMNS, measured_networks)):
        new = pd.DataFrame({**run, **{c: table[c] if c in table else np.nan for c in cols}, "note": note},
                           index=table.index)     # a summary written before a column existed leaves it empty
        old = read_measured(path)
        keep = [old[old["profile"] != profile]] if len(old) else []
        table = pd.concat([*keep, new], ignore_index=True)
        atomic_write_csv(path, table[[*new.columns, *(c for c in table.columns if c not in new.columns)]],
                         float_format="%.4f")
        written.append(path)
    return written


def read_measured(path: Path = MEASURED_FILE) -> pd.DataFrame:
    """The recorded rows of :data:`MEASURED_FILE` (or :data:`MEASURED_NETWORKS`); empty when none."""
    return pd.read_csv(path) if Path(path).is_file() else pd.DataFrame()

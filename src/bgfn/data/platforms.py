"""What moved each drive, as the run recorded it, and the tables written with the aids that ran on it.

Notebook 02 records each drive's platform with its constraints (``kf_baseline.json``); a table of the ``+NHC``
rows is written with the label of the aids that ran there (:func:`bgfn.row_labels.ran_labels`: ``INS+ZUPT`` for a
walker), while the code keys the rows ``+NHC`` throughout and reads the tables back so
(:func:`bgfn.row_labels.key_labels`).
"""

from __future__ import annotations

import json
from pathlib import Path

import pandas as pd

from bgfn.config import RUN_RECORDS
from bgfn.data.csv_meta import META_FILE, read_meta
from bgfn.data.names import dataset_folder, dataset_id
from bgfn.errors import DataError
from bgfn.io import atomic_write_csv
from bgfn.nav.constraints import DEFAULT_PLATFORM, PLATFORM_AIDS, platform_aids
from bgfn.row_labels import ran_labels


def recorded_platforms(out: str | Path) -> dict[str, str]:
    """``{dataset id: platform}`` of the drives notebook 02 ran (``kf_baseline.json`` under ``out``, ``results/<p>``);
    empty before it ran."""
    path = Path(out) / RUN_RECORDS["kf_baseline"]
    record = json.loads(path.read_text(encoding="utf-8")) if path.is_file() else {}
    return {dataset_id(name): str(((facts or {}).get("constraints") or {}).get("platform", DEFAULT_PLATFORM))
            for name, facts in (record.get("datasets") or {}).items()}


def recorded_platform(out: str | Path, dataset: str) -> str:
    """The platform of ``dataset`` as notebook 02 recorded it; ``car`` when it says nothing."""
    return recorded_platforms(out).get(dataset_id(dataset), DEFAULT_PLATFORM)


def _own_platform(dataset: str, out: str | Path) -> str:
    """The platform a CSV folder's ``meta.yaml`` names (``car`` for a registered dataset or none said); ``dataset``
    a folder, or its id in the profile whose results ``out`` holds (``results/<profile>``)."""
    try:
        folder = dataset_folder(dataset, Path(out).name)
    except DataError:                               # ``out`` is no profile's results: the name as it is
        folder = dataset_folder(dataset)
    if folder is None or not (folder / META_FILE).is_file():
        return DEFAULT_PLATFORM
    return str(read_meta(folder / META_FILE).get("platform", DEFAULT_PLATFORM))


def drive_platform(out: str | Path, dataset: str) -> str:
    """The platform of ``dataset``: as notebook 02 recorded it under ``out`` (``results/<profile>``), else as its
    folder's ``meta.yaml`` names it; ``car`` when neither says."""
    return recorded_platforms(out).get(dataset_id(dataset)) or _own_platform(dataset, out)


def platform_aid_names(platform: str) -> tuple[str, ...]:
    """The aids ``platform`` takes (a platform not known reads as the default's)."""
    return platform_aids(platform if platform in PLATFORM_AIDS else DEFAULT_PLATFORM)


def write_ran_table(path: str | Path, frame: pd.DataFrame, out: str | Path, **kwargs) -> Path:
    """Write ``frame`` (rows of several drives, a ``dataset`` column) to ``path`` with each row's ``+NHC`` label
    named by the aids that ran on its drive (:func:`recorded_platforms` of ``out``; a drive notebook 02 did not run:
    its folder's ``meta.yaml``); a car's table byte for byte as before."""
    platforms = recorded_platforms(out)
    aids = {d: platform_aid_names(platforms.get(dataset_id(d)) or _own_platform(d, out))
            for d in (frame["dataset"].unique() if "dataset" in frame.columns else ()) if isinstance(d, str)}
    default = platform_aid_names(DEFAULT_PLATFORM)          # a row of no drive (none so far) as a car's
    table = ran_labels(frame, lambda d: aids.get(d, default)) if aids else frame
    return atomic_write_csv(path, table, **kwargs)


__all__ = ["drive_platform", "platform_aid_names", "recorded_platform", "recorded_platforms", "write_ran_table"]

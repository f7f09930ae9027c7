"""The drives: the NaveGo Turin drive (acquisition, truth, simulated IMUs and GNSS), a recorded car drive and a
user's CSV folders, as datasets (``load_drive``).

:func:`load_drive` ``(name, **overrides) -> Drive`` over the registry :data:`DATASETS` (a CSV folder path loads a
user's drive); :func:`dataset_id` names a dataset's result files; :class:`Drive` holds the ``reference``, ``imu``
and ``gnss`` tables, ``meta`` and ``imu_bias``; :func:`fetch_all` / :func:`resolve` get the raw files
(``python -m bgfn.data fetch``). The building blocks (truth, IMU errors, fixes, the CSV schema, RTKLIB's files,
regridding, IMU levels) are modules of their own; :mod:`bgfn.data.summary` and :mod:`bgfn.data.plots` make
notebook 01's tables and figures.
"""

from bgfn.data.acquire import NAVEGO_FILES, MissingFileError, fetch_all, resolve
from bgfn.data.csv_drive import load_csv_drive, write_csv_drive
from bgfn.data.drive import Drive
from bgfn.data.drives import DATASETS, DEFAULT_DATASET, dataset_params, load_drive
from bgfn.data.gnss import simulate_fixes
from bgfn.data.imu_errors import EKINOX_D, MPU6000, apply_imu_errors, error_params
from bgfn.data.names import dataset_id
from bgfn.data.trajectory import smooth_reference

__all__ = [
    "DATASETS", "DEFAULT_DATASET", "Drive", "EKINOX_D", "MPU6000", "MissingFileError", "NAVEGO_FILES",
    "apply_imu_errors", "dataset_id", "dataset_params", "error_params", "fetch_all", "load_csv_drive", "load_drive",
    "resolve", "simulate_fixes", "smooth_reference", "write_csv_drive",
]

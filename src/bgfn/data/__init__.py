"""The NaveGo Turin drive: acquisition, truth, simulated IMUs/GNSS, datasets (``load_drive``).

Public API:

- :func:`load_drive` ``(name="turin-sim-ekinox", **overrides) -> Drive`` and the registry
  :data:`DATASETS` (name -> default parameters); a CSV folder path loads a user's drive.
- :func:`dataset_id`: the safe id that names a dataset's result files (a folder path never becomes a file name).
- :class:`Drive`: ``name``, ``reference``, ``imu``, ``gnss`` tables, ``meta``, ``imu_bias``.
- :func:`fetch_all` / :func:`resolve`: the NaveGo files, ``data/raw`` -> mirror -> pinned URL
  (``python -m bgfn.data fetch``).
- :func:`smooth_reference`, :func:`apply_imu_errors`, :func:`error_params`, :func:`simulate_fixes`,
  :func:`load_csv_drive`, :func:`write_csv_drive`: the building blocks.
- :mod:`bgfn.data.rtklib`: readers of RTKLIB-logged files, behind the dataset ``rtklib-drive0708`` (a real car
  drive: recorded MEMS IMU, RTK reference without attitude); :mod:`bgfn.data.imu_levels`: a drive's IMU
  noise levels at rest and while driving; :mod:`bgfn.studies.ins_fidelity.imu_roughness` (on :mod:`bgfn.data.allan`): its Allan
  deviation, the bias between stops, and the trajectory twin (the same road with a simulated IMU).
- :mod:`bgfn.data.summary` (``summary_table``) and :mod:`bgfn.data.plots` (matplotlib; not imported here):
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

"""Beyond the paper: is our INS as good, and as honest, as it should be?

The standalone INS over many starts (:mod:`~bgfn.studies.ins_fidelity.ins_drift`), the filter's covariance
against its errors (:mod:`~bgfn.studies.ins_fidelity.nees`), the filter set up as NaveGo's
(:mod:`~bgfn.studies.ins_fidelity.ins_setups`), and how rough the simulated stand-in IMU is against a recorded one
(:mod:`~bgfn.studies.ins_fidelity.imu_roughness`, :mod:`~bgfn.studies.ins_fidelity.imu_twin`).
"""

from bgfn.studies.ins_fidelity.imu_twin import (TWIN_COLUMNS, effective_instability, implied_setting, settle_setting,
                                                twin_check, twin_section)
from bgfn.studies.ins_fidelity.ins_drift import (DRIFT_COLUMNS, DRIFT_RUN_COLUMNS, drift_starts,
                                                 drift_summary, ins_drift_runs, plot_ins_drift)
from bgfn.studies.ins_fidelity.nees import (NEES_COLUMNS, consistency_scan, nees_section, nees_summary)

__all__ = [
    "TWIN_COLUMNS", "effective_instability", "implied_setting", "settle_setting", "twin_check",
    "twin_section", "DRIFT_COLUMNS", "DRIFT_RUN_COLUMNS", "drift_starts", "drift_summary",
    "ins_drift_runs", "plot_ins_drift", "NEES_COLUMNS", "consistency_scan", "nees_section",
    "nees_summary",
]

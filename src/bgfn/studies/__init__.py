"""The studies beyond the paper, each a package above the paper's pipeline; the paper's layers never import one.

- :mod:`~bgfn.studies.outage_sweep` -- many outage starts and durations, the oracle increments, the variants;
- :mod:`~bgfn.studies.odometer` -- a learned odometer: forward speed and its uncertainty as a filter aid;
- :mod:`~bgfn.studies.ins_fidelity` -- the INS against NaveGo, its covariance's honesty, the IMU's roughness;
- :mod:`~bgfn.studies.gallery` -- own logs of other vehicles, mountings and rates, run as a user would.
"""

from bgfn.studies import gallery, ins_fidelity, odometer, outage_sweep

__all__ = ["gallery", "ins_fidelity", "odometer", "outage_sweep"]

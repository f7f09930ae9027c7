"""Beyond the paper: a learned odometer (forward speed and its uncertainty, fused with the NHC rows).

The bars it must clear and its rows in the sweep's outages (:mod:`~bgfn.studies.odometer.bars`), the parts of
its speed error (:mod:`~bgfn.studies.odometer.errors`), its uncertainty's calibration
(:mod:`~bgfn.studies.odometer.uncertainty`), the ridge's learning curve (:mod:`~bgfn.studies.odometer.ridge_curve`),
the networks at other sizes (:mod:`~bgfn.studies.odometer.sizes`) and their energy
(:mod:`~bgfn.studies.odometer.energy`). The filter aid itself is :mod:`bgfn.nav.odometer`.
"""

from bgfn.studies.odometer.bars import (ODOMETER_COLUMNS, ODOMETER_METHODS, odometer_rows, odometer_summary,
                                        run_odometer_bars)
from bgfn.studies.odometer.section import OdometerSection, odometer_table, run_odometer_section
from bgfn.studies.odometer.energy import OdometerEnergy, odometer_energy

__all__ = [
    "ODOMETER_COLUMNS", "ODOMETER_METHODS", "OdometerSection", "odometer_rows",
    "odometer_summary", "odometer_table", "run_odometer_bars", "run_odometer_section", "OdometerEnergy",
    "odometer_energy",
]

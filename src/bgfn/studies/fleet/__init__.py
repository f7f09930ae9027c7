"""Beyond the paper: a fleet of drives of one vehicle, the learned odometer trained on some and tested on drives it
never saw (notebook 11).

The drives made comparable (:mod:`~bgfn.studies.fleet.drives`), the protocol and the odometer table's rows per test
drive (:mod:`~bgfn.studies.fleet.protocol`), what the training drives covered (:mod:`~bgfn.studies.fleet.coverage`),
the tables per drive and pooled (:mod:`~bgfn.studies.fleet.summary`), all together (:mod:`~bgfn.studies.fleet.study`).
A profile's ``fleet:`` section (:class:`bgfn.settings.Fleet`) names the drives; off while it names none.
"""

from bgfn.studies.fleet.drives import PREPARATION_COLUMNS, PreparedDrive, fleet_drives, prepare_fleet
from bgfn.studies.fleet.study import FLEET_TABLES, FleetResult, check_fleet, fleet_enabled, run_fleet, write_fleet_tables

__all__ = ["PREPARATION_COLUMNS", "PreparedDrive", "fleet_drives", "prepare_fleet", "FleetResult", "check_fleet",
           "fleet_enabled", "run_fleet", "FLEET_TABLES", "write_fleet_tables"]

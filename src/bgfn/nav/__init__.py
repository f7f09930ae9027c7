"""Navigation core (paper Sec. 2): WGS84 Earth, NED strapdown INS, 15-state loosely coupled KF with aids.

One concept per module (SI units, radians, NED, tables as in CONTRIBUTING.md): the Earth and frames
(:mod:`~bgfn.nav.earth`, :mod:`~bgfn.nav.transform`); the INS (:mod:`~bgfn.nav.strapdown`, its exact inverse
:mod:`~bgfn.nav.sim`); the filter (:mod:`~bgfn.nav.error_model`, Eqs. eq9/eq13; :mod:`~bgfn.nav.state`; the engine
:mod:`~bgfn.nav.engine`, Eqs. eq3/eq4, with its ``Aid`` interface; :mod:`~bgfn.nav.filter`); the aids (GNSS and
pseudo-GPS fixes :mod:`~bgfn.nav.gnss_aid`, NHC and ZUPT :mod:`~bgfn.nav.constraints`, a forward speed
:mod:`~bgfn.nav.odometer`); the outages (:mod:`~bgfn.nav.outage_window`, on the IMU epochs;
:mod:`~bgfn.nav.outages`, :mod:`~bgfn.nav.outage_rules`); the start and
its checks (:mod:`~bgfn.nav.alignment`, :mod:`~bgfn.nav.tuning`, :mod:`~bgfn.nav.consistency`,
:mod:`~bgfn.nav.metrics`); notebook 02's KF baseline (:mod:`~bgfn.nav.baseline`, :mod:`~bgfn.nav.plots`); NaveGo's
setup of the filter (:mod:`~bgfn.nav.navego_setup`) and pyins beside ours (:mod:`~bgfn.nav.pyins_bridge`).
"""

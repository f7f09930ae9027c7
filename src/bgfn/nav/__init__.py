"""Navigation core (paper Sec. 2): WGS84 Earth, NED strapdown INS, 15-state loosely coupled KF.

Modules (pyins style, one concept each; SI units, radians, NED, tables as in CONTRIBUTING.md):

- :mod:`~bgfn.nav.earth` -- WGS84 constants ``A, E2, OMEGA_IE``; ``curvature_radii(lat) -> (r_m, r_n)``,
  ``normal_gravity(lat, h)``, ``earth_rate_n(lat)``, ``transport_rate_n(lat, h, v_n)``,
  ``lla_to_ecef``, ``ecef_to_lla``, ``lla_to_ned(lat, lon, h, lat0, lon0, h0) -> [..., 3]``,
  ``ned_to_lla(ned, lat0, lon0, h0) -> (lat, lon, h)`` (exact via ECEF; all vectorized).
- :mod:`~bgfn.nav.transform` -- ``skew``, ``dcm_from_euler(roll, pitch, yaw)`` (C_b^n, Eq. cnb,
  shape ``(..., 3, 3)``), ``euler_from_dcm``, ``dcm_from_rotvec``, ``rotvec_from_dcm``, ``wrap_angle``.
- :mod:`~bgfn.nav.strapdown` -- ``propagate(lat, lon, h, v_n, c_bn, gyro, accel, dt)`` one step from the
  mean rates over the step; ``integrate(initial_row, imu) -> DataFrame`` (reference schema, row 0 = the
  initial epoch, then one row per IMU row with ``time > t0``); numba kernel ``step_inplace``.
  Earth rate, transport rate and gravity are taken at the start of each step.
- :mod:`~bgfn.nav.sim` -- ``imu_from_trajectory(reference) -> imu DataFrame`` (rows for
  ``reference.time[1:]``), the exact inverse of ``propagate``; ``positions_from_velocity(time, v_ned,
  lat0, lon0, h0)`` makes a trajectory's positions consistent with the strapdown's trapezoid rule;
  ``demo_trajectory(duration_s, rate_hz)`` a smooth curvy 3D test drive; ``gnss_from_trajectory``.
- :mod:`~bgfn.nav.error_model` -- state indices of Eq. (eq13) (``PHI_E ... BG_Z``, ``N_STATES = 15``),
  the system matrix F of Eqs. (eq9, IVE, IPE) and the discrete process noise.
- :mod:`~bgfn.nav.state` -- ``FilterState`` (time, pos, v, c_bn, accel_bias, gyro_bias, P),
  ``FilterNoise`` and ``noise_from_imu_errors(meta['imu_errors'])``, ``initial_covariance``,
  ``initial_state``, ``save_states`` / ``load_states`` (.npz format in the module docstring).
- :mod:`~bgfn.nav.engine` -- the filter engine: ``Stepper(times, dt, gyro, accel, initial, noise, aids)`` with
  ``propagate_to(t)`` (Eq. eq3) and ``update(Measurement)`` (Eq. eq4 and feedback); the ``Aid`` interface (an
  aid names its epochs and answers with a ``Measurement(dz, H, std)``); the numba kernels.
- :mod:`~bgfn.nav.gnss_aid` -- position fixes as aids: ``GnssFixes`` (with the innovation gate,
  ``gate_thresholds``) and ``PseudoGps`` (Eq. pred-gps inside the outage windows); ``position_fix``.
- :mod:`~bgfn.nav.filter` -- ``run_filter(imu, initial, noise, gnss, lever_arm, outage_windows,
  pseudo_gps, t_end, snapshots, aids=[...]) -> FilterResult`` and ``run_outage(imu, start_state, window, noise,
  lever_arm, pseudo_gps, aids=[...])`` (one outage from a saved state): the engine with these aids.
- :mod:`~bgfn.nav.outage_window` -- ``OutageWindow``, ``check_windows``, ``snap_windows`` (edges onto the IMU
  epochs), the pseudo-GPS hook (``PseudoFix``, ``PseudoGpsContext``, ``IncrementPseudoGps`` = Eq. pred-gps,
  ``TablePseudoGps``); :mod:`~bgfn.nav.outages` re-exports them above the filter and reads
  ``outage_windows(profile, drive, dataset)`` (the profile's one key: one list, or per dataset a list or a rule).
- :mod:`~bgfn.nav.outage_rules` -- ``pick_windows(rule, reference, margin_s)``: a drive's outages picked by a
  rule (``cruise_and_manoeuvre``: one cruising, one manoeuvring, as the paper's field test).
- :mod:`~bgfn.nav.constraints` -- the vehicle constraints of the ``+NHC`` rows, an aid of the filter engine:
  NHC and ZUPT velocity updates (``nhc_measurement``, ``zupt_measurement``), the stillness detector
  ``stillness``, the vehicle frame ``mounting_track``; ``build_constraints(imu, imu_errors, config, trajectory)
  -> Constraints``, which ``run_filter`` / ``run_outage`` take in ``aids``.
- :mod:`~bgfn.nav.odometer` -- ``Odometer(vehicle, SpeedTrack)``: a forward speed as an aid, joint with the
  vehicle constraints' NHC rows (``aids=[constraints, odometer]``, ``aid_list``).
- :mod:`~bgfn.nav.outages` -- ``outage_windows(profile, drive)`` (the profile's one key, on the IMU epochs; a
  rule's warm-up from the filter's start), and :mod:`~bgfn.nav.outage_window`'s windows and pseudo-GPS hook.
- :mod:`~bgfn.nav.metrics` -- ``navigation_errors``, ``outage_metrics`` (max |east|, max |north|,
  horizontal RMSE, end error), ``rms_table``; ``reference_rows`` (a drive's spans where the reference is not
  trusted, ``meta["reference_excluded_s"]``, left out of every comparison).
- :mod:`~bgfn.nav.alignment` -- ``align(imu, gnss, lever_arm, noise, options) -> Alignment`` (its ``state``: the
  filter's start without a reference attitude), ``rest_end``, ``level_from_specific_force``,
  ``level_by_velocity_matching``.
- :mod:`~bgfn.nav.tuning` -- ``search_noise_scale(mean_nis, options) -> NoiseTuning`` (``nav.noise_scale: auto``).
- :mod:`~bgfn.nav.consistency` -- ``nis_summary(updates)``, ``verdict``, ``nis_line``, ``nis_table``.
- :mod:`~bgfn.nav.baseline` -- notebook 02: ``nav_config``, ``run_drive(drive, nav_section)``,
  ``prepare_filter(drive, cfg) -> FilterSetup`` (start and noise; ``initial_and_noise`` without the record), ``filter_start``,
  ``run_baseline(drive, cfg, windows)``, ``ins_layout``, ``save_baseline``; :mod:`~bgfn.nav.plots` -- its figures.
- :mod:`~bgfn.nav.navego_setup` -- the filter set up as NaveGo v1.4's ``ins_gnss.m`` (``nav.ins_tuning: navego``):
  ``navego_noise``, ``static_biases``, ``initial_bias_estimates``, ``remove_static_biases``.
- :mod:`~bgfn.studies.ins_fidelity.ins_setups` -- the standalone-INS row under each setup beside the paper's:
  ``ins_tuning_table(drive, cfg, windows)``, ``layout``, ``gap_explained``, ``sentences``, ``save_table``.
"""

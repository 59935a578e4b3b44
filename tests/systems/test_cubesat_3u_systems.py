"""The 3U's shipped detumble and day systems (issue 57), the FMUs through the master with their
parameter files from the mission definition (components.mission.cubesat_3u):
- cubesat_3u_detumble: the magnetometer-only three-axis B-dot takes the 10 deg/s tumble down
  within three orbits, the rods within their 0.2 A.m2;
- cubesat_3u_nadir_day, its first orbit (the whole day is the docs' run, docs/models/cubesat_3u.md):
  nadir pointing under the disturbance torques with the wheels and the dumping, the battery
  through an eclipse;
- cubesat_3u_mission, its first 4500 s (the whole day is the docs' run): detumble, Sun-safe and
  nadir in that order, each entered as its condition says, and the true nadir error on the
  estimator within the stated 1 deg."""
import numpy as np

from components.acs import mode_sequence
from components.attitude.pointing import nadir_axis_error
from components.mission import cubesat_3u


def _columns(data, name, n):
    return np.column_stack([np.asarray(data[f"{name}[{i}]"], float) for i in range(1, n + 1)])


def test_detumble_system_takes_10_deg_per_s_down_with_the_magnetometer_alone(ssp_paths):
    import system_ssp
    outputs = [f"dynamics.omega_BN_B[{i}]" for i in (1, 2, 3)] + [f"coils.dipole_B[{i}]" for i in (1, 2, 3)]
    d = system_ssp.simulate(ssp_paths["cubesat_3u_detumble"], outputs=outputs).data
    rate = np.degrees(np.linalg.norm(_columns(d, "dynamics.omega_BN_B", 3), axis=1))
    dipole = _columns(d, "coils.dipole_B", 3)
    t = np.asarray(d["time"], float)
    assert abs(rate[0] - 10.0) < 1e-9, rate[0]
    assert t[-1] == 17100.0 and rate[t >= 15000.0].max() < 0.5, rate[t >= 15000.0].max()
    assert np.abs(dipole).max() <= cubesat_3u.COILS.max_dipole


def test_nadir_day_system_first_orbit_points_dumps_and_charges_through_an_eclipse(ssp_paths):
    import system_ssp
    outputs = (["guidance.pointing_error", "power.state_of_charge", "solar_arrays.solar_power",
                "shadow.sunlit_fraction", "power.load_power"]
               + [f"wheels.wheel_speed[{i}]" for i in (1, 2, 3, 4)]
               + [f"dumping.wheel_momentum_B[{i}]" for i in (1, 2, 3)]
               + [f"coils.dipole_B[{i}]" for i in (1, 2, 3)])
    d = system_ssp.simulate(ssp_paths["cubesat_3u_nadir_day"], stop_time=5700.0, outputs=outputs).data
    t = np.asarray(d["time"], float)
    error = np.degrees(np.asarray(d["guidance.pointing_error"], float))
    assert error[0] > 30.0 and error[t >= 600.0].max() < 0.1, error[t >= 600.0].max()
    speeds = _columns(d, "wheels.wheel_speed", 4)
    assert np.abs(speeds).max() < cubesat_3u.WHEELS.max_speed
    h_w = np.linalg.norm(_columns(d, "dumping.wheel_momentum_B", 3), axis=1)
    capacity = cubesat_3u.WHEELS.J_s * cubesat_3u.WHEELS.max_speed  # one wheel's
    assert h_w[t >= 600.0].max() < 0.5 * capacity, (h_w[t >= 600.0].max(), capacity)
    assert np.abs(_columns(d, "coils.dipole_B", 3)).max() <= cubesat_3u.COILS.max_dipole
    soc, solar = np.asarray(d["power.state_of_charge"], float), np.asarray(d["solar_arrays.solar_power"], float)
    dark = np.asarray(d["shadow.sunlit_fraction"], float) == 0.0
    assert 1500.0 < dark.sum() < 2500.0, dark.sum()  # ~35 min of umbra an orbit
    assert np.all(solar[dark] == 0.0) and solar[~dark].max() > 10.0
    assert np.all(np.diff(soc)[dark[1:]] < 0.0) and 0.0 < soc.min() and soc.max() <= 1.0
    load = np.asarray(d["power.load_power"], float)
    always_on = cubesat_3u.POWER.base_load + cubesat_3u.WHEELS.count * cubesat_3u.POWER.wheel_base_power
    assert load.min() >= always_on - 1e-12


def test_mission_system_detumbles_goes_sun_safe_then_points_at_nadir_on_the_estimator(ssp_paths):
    import system_ssp
    outputs = (["modes.mode", "modes.transitions", "estimator.attitude_valid", "css.sun_valid"]
               + [f"gyro.omega_meas_B[{i}]" for i in (1, 2, 3)] + [f"dynamics.q_BN[{i}]" for i in (1, 2, 3, 4)]
               + [f"orbit.r_BN_N[{i}]" for i in (1, 2, 3)] + [f"wheels.wheel_speed[{i}]" for i in (1, 2, 3, 4)]
               + [f"coils.dipole_B[{i}]" for i in (1, 2, 3)] + [f"detumble.dipole_cmd_B[{i}]" for i in (1, 2, 3)])
    d = system_ssp.simulate(ssp_paths["cubesat_3u_mission"], stop_time=4500.0, outputs=outputs).data
    t, mode = np.asarray(d["time"], float), np.asarray(d["modes.mode"], int)
    changes = np.nonzero(np.diff(mode))[0] + 1
    assert [int(mode[0])] + mode[changes].tolist() == [mode_sequence.DETUMBLE, mode_sequence.SUN_SAFE,
                                                      mode_sequence.POINTING], mode[changes]
    sun_safe, nadir = t[changes]
    gyro = np.degrees(np.linalg.norm(_columns(d, "gyro.omega_meas_B", 3), axis=1))
    hold = cubesat_3u.MODES.hold_time
    # detumble ended after a minute below 1.5 deg/s on the gyro, which it had not had before
    before = (t >= sun_safe - hold) & (t < sun_safe)
    assert gyro[before].max() < np.degrees(cubesat_3u.MODES.detumble_exit_rate) and 1000.0 < sun_safe < 4000.0
    assert np.asarray(d["estimator.attitude_valid"], bool)[(t >= nadir - hold) & (t < nadir)].all()
    # the coils: B-dot's command while detumbling, off (dumping only, a few mA.m2) once the wheels fly
    dipole, bdot = _columns(d, "coils.dipole_B", 3), _columns(d, "detumble.dipole_cmd_B", 3)
    assert np.abs(dipole[t < sun_safe - 1]).max() > 0.1 and np.abs(bdot[t > sun_safe + 1]).max() == 0.0
    error = np.degrees(nadir_axis_error(_columns(d, "dynamics.q_BN", 4), _columns(d, "orbit.r_BN_N", 3)))
    settled = t >= nadir + 600.0
    assert settled.sum() > 300 and error[settled].max() < 1.0, error[settled].max()
    assert np.abs(_columns(d, "wheels.wheel_speed", 4)).max() < cubesat_3u.WHEELS.max_speed

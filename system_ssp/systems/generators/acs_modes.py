"""Write the acs_modes system (.ssd) and its parameter files (.ssv).

    python -c "import build_fmus, pathlib; [build_fmus.build_fmu(pathlib.Path(f'fmus/neighbor_{n}.py'), \
pathlib.Path('build/fmus')) for n in ('circular_orbit', 'sun_ephemeris', 'earth_shadow', 'sunline', \
'magnetic_field', 'acs_signals', 'acs_mode_manager', 'acs_control', 'torque_coils', 'momentum_wheel', \
'paddles', 'optical_tracker', 'rigid_body')]"
    python system_ssp/systems/generate_acs_modes.py

System (ACS mode specification): the ACS mode manager (`modes`) commanding the per-mode control laws
(`control`) of a spacecraft with three torque coils (`coils`), a Y momentum wheel (`wheel`),
deployable paddles (`paddles`) and a star-tracking optical system (`optical`); the truth:
circular orbit (`orbit`), Sun (`sun`), Earth shadow (`shadow`), Sun heading in B (`sunline`),
geomagnetic field (`field`), rigid body with the wheel (`dynamics`, rk4); `signals` computes the
mode manager's state values from the truth (stand-in for sensors and estimator).

Step 1 s: the fastest dynamics are the tumble (2 deg/s per axis: 3.5 deg per step), the wheel
transfer (10 s time constant) and the azimuth loop (0.05 rad/s natural frequency, omega_n h =
0.05); the specification's shortest delays are 10 s (WMD, AMD, ODMD, GCMD) and the optical loss time 5 s.

Gauss-Seidel order: field, sunline, shadow, signals, optical, modes, paddles, control, coils,
wheel, dynamics, orbit, sun. The state sources (dynamics, orbit, sun) come last, so everything
read in a macro step [t, t + h] is their state at t; the mode manager decides at t on signals
and the shadow at t, the optical flag after its step over [t, t + h] with orbit_day(t) (tracking
is then true at the very point night falls, and at dawn for loss_time > h), and the paddle
state at t (paddles step after the decision that commands them); control, coils, wheel act on
the decision at t and the plant integrates them over the step.

Parameter files:
- acs_modes_spacecraft.ssv  host box (12 kg, 0.1 x 0.2 x 0.3 m: J = diag(0.05, 0.13, 0.10)), rk4;
- acs_modes_control.ssv, acs_modes_signals.ssv  the matching inertias; acs_modes_sunline.ssv
  the quaternion attitude input;
- acs_modes_orbit.ssv       420 km, 51.6 deg orbit, epoch 2023-01-01: eclipses each orbit;
- acs_modes_initial_state.ssv  tumbling start: 2 deg/s about each body axis, identity attitude;
- acs_modes_shortened.ssv   scenario for tests: mode delays scaled down (RMD 300 s etc.),
  5 s step-compatible, coils 1 A.m2, small paddle/tracker times: the whole nominal sequence and
  two day/night alternations (stop time 18000 s, step 5 s): Detumble/Spinup by 2620 s (dawn),
  Reorient falls back to Spinup at the first dusk (6125 s, Spinup col 5, tables), completes in
  the second daylight, Orbit Day at 9430 s, then Orbit Night/Day at 11705/13780/17280 s;
- acs_modes_sun_facing.ssv  scenario for the long run with the specification's delays: RMD = 6000 s
  exceeds the 5577 s period and Reorient falls back to Spinup at every night (Spinup col 5),
  so the deployment needs an eclipse-free orbit: see examples/acs_modes_long_run.py.
- acs_modes_ground_command.ssv  scenario: the shortened one with a ground-command window.
Default stop time: 6 orbits of the default orbit (33460 s), step 1 s.
"""
import math


from components.orbit import circular
from components.attitude import rigid_body
from components.environment import sun
from components.mission.neighbor import SPACECRAFT as BASELINE

from ...ssp.writer import vec
from .from_spec import write_system

MASS, EDGES = BASELINE.mass, {"edge_a": BASELINE.edge_a, "edge_b": BASELINE.edge_b, "edge_c": BASELINE.edge_c}
J = rigid_body.box_inertia(MASS, EDGES["edge_a"], EDGES["edge_b"], EDGES["edge_c"])
IX, IY, IZ = float(J[0][0]), float(J[1][1]), float(J[2][2])
ORBIT = {"altitude": 420e3, "inclination": math.radians(51.6), "raan": 0.0, "arg_latitude0": 0.0}
PERIOD = circular.CircularOrbit(ORBIT["altitude"]).period
STEP = 1.0
W0 = [math.radians(2.0)] * 3

SPACECRAFT = {"mass": MASS, **EDGES, "inertia_from_box": True, "integrator": "rk4", "max_substep": 0.05}
CONTROL_INERTIA = {"Ix": IX, "Iy": IY, "Iz": IZ}
SIGNALS = {"Iy": IY}
SUNLINE = {"attitude_input": "quaternion"}
INITIAL = {**vec("q0", [0.0, 0.0, 0.0, 1.0]), **vec("omega0", W0)}

SHORT_DELAYS = {"WMD": 10.0, "DMD": 60.0, "SMD": 60.0, "RMD": 300.0, "DWMD": 60.0, "AMD": 10.0, "DPMD": 60.0,
                "ODMD": 10.0, "GCMD": 20.0}
SHORTENED = {**{f"modes.{k}": v for k, v in SHORT_DELAYS.items()},
             "control.reorient_duration": SHORT_DELAYS["RMD"],
             **{f"coils.max_dipole[{i}]": 1.0 for i in (1, 2, 3)},
             "paddles.deployment_time": 20.0, "optical.acquisition_time": 10.0, "optical.loss_time": 7.0}
SHORT_STEP, SHORT_STOP = 5.0, 18000.0
GROUND = {**SHORTENED, "signals.command_start": 12000.0, "signals.command_end": 12030.0}


def sun_facing():
    """Long-run scenario with the specification's delays: an orbit whose plane faces the Sun at the epoch
    (node 90 deg east of the Sun, inclination chosen so the Sun is 75 deg from the plane at
    the epoch: no eclipse). The eclipse-free deployment is what RMD = 6000 s > period needs."""
    ra, dec = sun.right_ascension_declination(sun.SunEphemeris().position())
    return {"orbit.raan": (ra + math.pi / 2) % (2 * math.pi), "orbit.inclination": math.radians(98.0)}


def generate(writer):
    writer.ssv("acs_modes_spacecraft",
               "12 kg host box (0.1 x 0.2 x 0.3 m) and rk4 integrator for dynamics", SPACECRAFT)
    writer.ssv("acs_modes_control",
               "Inertias of the 12 kg host box for control: J = diag(0.05, 0.13, 0.10) kg.m2", CONTROL_INERTIA)
    writer.ssv("acs_modes_signals", "Iy of the host box for H_d", SIGNALS)
    writer.ssv("acs_modes_sunline", "Sunline takes the attitude as q_BN", SUNLINE)
    writer.ssv("acs_modes_orbit", "Circular orbit 420 km, 51.6 deg (SI units)", ORBIT)
    writer.ssv("acs_modes_initial_state",
               "Tumbling start: 2 deg/s about each body axis, identity attitude", INITIAL)
    writer.ssv("acs_modes_shortened",
               "Scenario: mode delays scaled down, 1 A.m2 coils, short paddle and tracker times (run with 5 s steps)",
               SHORTENED)
    writer.ssv("acs_modes_ground_command",
               "Scenario: the shortened one with a ground command over [12000, 12030) s", GROUND)
    writer.ssv("acs_modes_sun_facing",
               "Scenario: orbit plane facing the Sun at the epoch (no eclipse) for the specification's 6000 s RMD",
               sun_facing())
    write_system(writer, "acs_modes")

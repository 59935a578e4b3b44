"""Write the sunline system (the sunline module description): a spinning rigid body feeding its attitude quaternion to
the sunline-ephemeris FMU, with fixed Sun and spacecraft positions.

    python -c "import build_fmus; from pathlib import Path; [build_fmus.build_fmu(Path(s), Path('build/fmus'))
               for s in ('fmus/neighbor_rigid_body.py', 'fmus/neighbor_sunline_ephemeris.py')]"
    python system_ssp/systems/generate_sunline.py

Parameter files (system_ssp/systems/parameters/):
- sunline_ephemeris.ssv       for `sunline`: attitude_input = "quaternion" and the fixed Sun and
  spacecraft positions, given as start values of the unconnected position inputs;
- sunline_initial_state.ssv   for `dynamics`: rk4, initial attitude (1-2-3 Euler angles
  0.3, -0.2, 0.5 rad) and a spin of 0.1 rad/s about the body z axis (a principal axis, so the
  torque-free rate stays constant and the heading in B turns at -0.1 rad/s about z);
- sunline_spin_x.ssv          scenario (names `component.variable`): spin of 0.05 rad/s about
  the body x axis instead.
`dynamics` also binds the shared spacecraft.ssv (host mass and box edges).
"""


from components.core import rotations
from components.core.constants import ASTRONOMICAL_UNIT as AU

from ...ssp.writer import vec
from .from_spec import write_system

# Sun about 1 au away, off every axis; spacecraft in a low Earth orbit position.
R_SUN_N = [0.8 * AU, -0.55 * AU, 0.24 * AU]
R_SC_N = [4.2e6, 5.1e6, 1.9e6]
Q0 = list(rotations.from_euler123(0.3, -0.2, 0.5))
SPIN_Z = 0.1  # rad/s
SPIN_X = 0.05  # rad/s

EPHEMERIS = {"attitude_input": "quaternion", **vec("r_SN_N", R_SUN_N), **vec("r_BN_N", R_SC_N)}
INITIAL_STATE = {"integrator": "rk4", **vec("q0", Q0), **vec("omega0", [0.0, 0.0, SPIN_Z])}
SCENARIOS = {
    "sunline_spin_x": ("Spin of 0.05 rad/s about the body x axis (principal) from the same attitude",
                       {**vec("dynamics.omega0", [SPIN_X, 0.0, 0.0])}),
}


def generate(writer):
    writer.ssv("sunline_ephemeris",
               "Sunline FMU: quaternion attitude input, fixed Sun and spacecraft positions in N (m)", EPHEMERIS)
    writer.ssv("sunline_initial_state",
               "Rigid body of the sunline system: rk4, initial attitude (1-2-3 Euler 0.3, -0.2, 0.5 rad), "
               "spin 0.1 rad/s about body z", INITIAL_STATE)
    for name, (description, values) in SCENARIOS.items():
        writer.ssv(name, description, values)
    write_system(writer, "sunline")

"""FMU `RigidBody` (instance `dynamics` in the systems): rigid-body attitude dynamics.

Wraps components.attitude.rigid_body.RigidBody: Euler's equation and quaternion kinematics (thesis
Eq. 4-5, 17-31). Outputs are states, so none depends directly on the torque input.
euler_integrated is the thesis' Eq. 31 (rates integrated into "Euler angles"), for comparing
with its printed triples; euler123 is the attitude's true 1-2-3 angles.

Momentum wheels: the inputs wheel_torque_B (the wheel motors' torque on the wheels; the body
feels -wheel_torque_B) and wheel_momentum_B (the wheels' momentum relative to the body) turn
Euler's equation into the gyrostat equation J omega_dot = L - wheel_torque_B - omega x
(J omega + h_w). They are declared after every other variable so that the value references of
the original variables are unchanged; left at zero the model is bit-identical to the wheel-less
one. H_B stays the body's own J omega (the total is H_B + wheel_momentum_B).

Disturbances (appended last): the input disturbance_torque_B (DisturbanceTorques' torque_B) is
added to torque_B; left at zero the model is the undisturbed one bit for bit.

Mass properties that follow the tank (appended last, off by default): with
`propellant_mass_properties` the inertia is the one about the centre of mass once
propellant_used + rcs_propellant kg left the tank at the NEIGHBOR module's centre
(components.attitude.mass_properties), recomputed before a step once 0.1 g more has been drawn;
`center_of_mass_B` says where it moved. Off, or with less than 0.1 g drawn, the model is the
fixed-inertia one bit for bit.

The body's own inertia (appended last): `inertia_error` scales its second moments of mass along
x, y and z against the nominal inertia (box or inertia_B), which the flight software keeps
(components.attitude.mass_properties.with_moment_errors: a real mass distribution for any error
in range); the dispersion campaigns draw it. Zero, the model is the nominal one bit for bit.
"""

import numpy as np

from neighbor_fmu_support import NeighborSlave

from components.attitude import mass_properties, rigid_body


class RigidBody(NeighborSlave):
    description = ("Rigid-body attitude dynamics: Euler's equation and quaternion kinematics (NEIGHBOR thesis "
                   "Eq. 4-29); body torque in, attitude quaternion, rates and 1-2-3 Euler angles out")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.inertia_parameters("Spacecraft mass at takeover: the box inertia's (Eq. 4) and the one the propellant "
                                "is drawn from")
        self.parameter_array("q0", [0.0, 0.0, 0.0, 1.0], "1",
                             "Initial attitude quaternion q_BN, scalar last (rk4 normalizes it, euler keeps it "
                             "as given like the thesis scripts; zero norm is an error)")
        self.parameter_array("omega0", [0.0, 0.0, 0.0], "rad/s", "Initial angular velocity omega_BN_B")
        self.parameter("integrator", "rk4", None,
                       "'euler': one explicit Euler step per communication step, no normalization (thesis "
                       "scripts); 'rk4': Runge-Kutta 4 sub-stepped, quaternion normalized", str)
        self.parameter("max_substep", 0.005, "s", "Largest RK4 sub-step (rk4 only), > 0")

        self.input_array("torque_B", [0.0, 0.0, 0.0], "N.m", "External torque on the body in B, held over a step")

        m = lambda: self.model  # noqa: E731
        self.output_array("q_BN", 4, lambda: m().q, "1", "Attitude quaternion of B relative to N, scalar last")
        self.output_array("omega_BN_B", 3, lambda: m().omega, "rad/s", "Angular velocity of B relative to N, in B")
        self.output_array("omega_dot_BN_B", 3, lambda: m().omega_dot, "rad/s2",
                          "Angular acceleration over the last step (euler: the derivative the step used; "
                          "rk4: mean over the step; zero before the first step)")
        self.output_array("euler123", 3, lambda: m().euler123(), "rad",
                          "1-2-3 Euler angles phi, theta, psi of q_BN (Eq. 25-29)")
        self.output_array("H_B", 3, lambda: m().angular_momentum(), "N.m.s",
                          "Angular momentum I omega of the body alone in B (without the wheels' relative momentum)")

        # Appended last: value references of the variables above stay as they were.
        self.input_array("wheel_torque_B", [0.0, 0.0, 0.0], "N.m",
                         "Torque the momentum-wheel motors apply to the wheels in B (the body feels the "
                         "opposite), held over a step; 0 without wheels")
        self.input_array("wheel_momentum_B", [0.0, 0.0, 0.0], "N.m.s",
                         "Angular momentum of the wheels relative to the body in B at the step start "
                         "(gyroscopic term omega x h_w); 0 without wheels")
        # Thesis Eq. 30-31 angles, appended after the wheel inputs for the same reason.
        self.output_array("euler_integrated", 3, lambda: m().euler_integrated, "rad",
                          "Body rates integrated from the start angles, angles += omega dt (thesis Eq. 31, the "
                          "'Euler angles' its scripts print), with the attitude's integrator; not an attitude")
        self.parameter("euler0_from_q0", True, None,
                       "Start euler_integrated at the 1-2-3 angles of q0 (Eq. 27-30, as the thesis scripts do); "
                       "false: at euler0", bool)
        self.parameter_array("euler0", [0.0, 0.0, 0.0], "rad",
                             "Start of euler_integrated when euler0_from_q0 is false (to continue a previous "
                             "maneuver's angles, as the thesis' slews continue its detumbles)")
        # Mass properties that follow the propellant drawn (appended last, issue 28)
        self.parameter("propellant_mass_properties", False, None,
                       "The inertia follows the propellant drawn from the tank at the module's centre (-c/2 + a/2, "
                       "0, 0), about the moving centre of mass; false: the fixed inertia (thesis)", bool)
        self.input("propellant_used", 0.0, "kg", "Propellant the de-orbit burn drew from the tank (>= 0), from "
                   "the propulsion; with propellant_mass_properties")
        self.input("rcs_propellant", 0.0, "kg", "Propellant the RCS thrusters drew from the same tank (>= 0); "
                   "with propellant_mass_properties")
        self.output_array("center_of_mass_B", 3, lambda: m().center_of_mass, "m",
                          "Centre of mass in B relative to the one at takeover (moves to +x as the tank empties)")
        # The body's own inertia off the nominal one (appended last, issue 28's dispersions)
        self.parameter_array("inertia_error", [0.0, 0.0, 0.0], "1",
                             "Fractional error of the body's second moment of mass along body x, y, z (the integral "
                             "of x_i^2 dm) against the nominal inertia (the box, or inertia_B) the flight software "
                             "assumes, in [-0.5, 0.5]; 0: the nominal inertia")
        # The environment's torque (appended last, issue 56): summed with torque_B; 0 is the model bit for bit
        self.input_array("disturbance_torque_B", [0.0, 0.0, 0.0], "N.m",
                         "Disturbance torque on the body in B (DisturbanceTorques.torque_B: gravity gradient, drag, "
                         "solar pressure, residual dipole), added to torque_B, held over a step; 0 without")
        self.share_values()
        self._inputs_at = self.shared_indices((("torque_B", 3), ("wheel_torque_B", 3), ("wheel_momentum_B", 3),
                                               ("disturbance_torque_B", 3)))
        self._outputs_at = self.shared_indices(rigid_body.PUBLISHED)

    def build_model(self):
        J = mass_properties.with_moment_errors(self.inertia(rigid_body.box_inertia), self.vector("inertia_error", 3))
        euler0 = None if self.values["euler0_from_q0"] else self.vector("euler0", 3)
        self._tank = mass_properties.tank_position(self.values["edge_a"], self.values["edge_c"])
        return rigid_body.RigidBody(J, self.vector("q0", 4), self.vector("omega0", 3),
                                    self.values["integrator"], self.values["max_substep"], euler0)

    def do_step(self, current_time, step_size):
        v = self.values
        if v["propellant_mass_properties"]:
            self.model.follow_propellant(self.input_value("propellant_used") + self.input_value("rcs_propellant"),
                                         v["mass"], self._tank)
        # the step and the publish (NeighborSlave.publish_after_step) in one compiled call
        if self.model.step_and_publish(self.shared, self._inputs_at, self._outputs_at, step_size):
            self.mark_published()
        else:  # the get that reads them raises publish's error
            self._outputs_stale()
        if not self.share_native[0] and self.native_ready():
            from components.attitude import native_steps  # numba is loaded: the same step, no Python
            model = self.model
            arrays = (model.x, self.shared, self._inputs_at, self._outputs_at, self.share_flags,
                      np.array([model.max_substep, model.integrator == "euler"], float))
            if v["propellant_mass_properties"]:  # native while the inertia need not follow the tank
                used = self.shared_indices((("propellant_used", 1), ("rcs_propellant", 1)))
                self.arm_native(native_steps.step("rigid_body_following"), *arrays, model.drawn_cell, used)
            else:
                self.arm_native(native_steps.step("rigid_body"), *arrays)
        return True

    def publish(self):
        # the outputs the getters define (NeighborSlave.publish), written by one compiled call
        self.model.publish_into(self.shared, self._outputs_at)
        self.mark_published()

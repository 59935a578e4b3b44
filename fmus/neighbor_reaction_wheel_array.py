"""FMU `ReactionWheelArray` (instance `wheels`): up to six reaction wheels on arbitrary spin axes.

Wraps components.acs.reaction_wheel_array.ReactionWheelArray (Basilisk's balanced-wheel
dynamics): motor torque commands in, limited in Basilisk's order (torque, minimum torque, power,
speed), friction added; wheel speeds, the wheels' reaction torque and absolute spin momentum in B,
and the electrical power out. Connect wheel_torque_B and wheel_momentum_B to the RigidBody inputs
of the same names and omega_BN_B from it; the rigid body's inertia is then the spacecraft's
without the wheels' spin-axis inertia (components.acs.reaction_wheel_array.body_inertia).
The state is the spin momenta and the body rate at the last step's end: initialization fixes
them from Omega0 and the body rate then, and a step reads omega_BN_B when it ends, so the wheel
speeds and momentum have no direct dependency, and the torque outputs depend on the commands only.

In a Gauss-Seidel order put the array after the rigid body: the body then flies the wheels'
torque and momentum at the step start, as it holds them; before it, the body would read the
momentum of the step's end.

Slots above wheel_count are unused (their outputs are zero). The default is four wheels in a
pyramid about +z (each spin axis 35.26 deg above the xy plane, at azimuths 45, 135, 225, 315 deg):
every body axis gets the same torque and momentum capability.
"""
import numpy as np

from neighbor_fmu_support import NeighborSlave
from neighbor_wheel_support import SLOTS as N, padded, wheel_axes, wheel_geometry_parameters

from components.acs import reaction_wheel_array as rwa
from components.core.names import element_names


class ReactionWheelArray(NeighborSlave):
    description = ("Reaction-wheel array (up to 6 wheels on any spin axes): motor torque commands in (torque, "
                   "power and speed limits, Coulomb and viscous friction); wheel speeds, reaction torque and "
                   "spin momentum in B for the rigid body, electrical power out")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        wheel_geometry_parameters(self, "Number of wheels used")
        self.parameter_array("J_s", [rwa.DEFAULT_INERTIA] * N, "kg.m2", "Wheel spin-axis inertia, > 0")
        self.parameter_array("max_torque", [rwa.DEFAULT_MAX_TORQUE] * N, "N.m", "Largest motor torque, > 0")
        self.parameter_array("max_speed", [rwa.DEFAULT_MAX_SPEED] * N, "rad/s",
                             "Largest wheel speed relative to the body, > 0 (no torque beyond it that speeds the "
                             "wheel up; default 6000 rpm)")
        self.parameter_array("max_power", [rwa.DEFAULT_MAX_POWER] * N, "W",
                             "Largest mechanical motor power |u Omega|, >= 0 (0: no power limit)")
        self.parameter_array("min_torque", [0.0] * N, "N.m", "Commands below this magnitude give no torque, >= 0")
        self.parameter_array("coulomb_friction", [0.0] * N, "N.m", "Coulomb friction torque, >= 0")
        self.parameter_array("viscous_friction", [0.0] * N, "N.m.s", "Viscous friction coefficient, >= 0")
        self.parameter("omega_limit_cycle", rwa.DEFAULT_OMEGA_LIMIT_CYCLE, "rad/s",
                       "Below this speed the friction is linear through zero (Basilisk's limit-cycle guard), > 0")
        self.parameter_array("base_power", [0.0] * N, "W", "Electrical power of a wheel's electronics, >= 0")
        self.parameter("motor_efficiency", 1.0, "1", "Mechanical over electrical power when driving, in (0, 1]")
        self.parameter("regen_efficiency", 0.0, "1",
                       "Electrical power recovered per mechanical power when braking, in [0, 1] (0: dumped)")
        self.parameter_array("Omega0", [0.0] * N, "rad/s",
                             "Initial wheel speed relative to the body, |Omega0| <= max_speed")
        commands = self.input_array("torque_cmd", [0.0] * N, "N.m", "Commanded motor torque on the wheel about "
                                    "its spin axis (the body feels the opposite)")
        enabled = self.input("enabled", True, None, "Wheel motors enabled; when false every motor torque is zero",
                             bool)
        available = self.input_array("wheel_available", [True] * N, None,
                                     "Wheel available; when false its motor torque is zero (a failed wheel)", bool)
        self.input_array("omega_BN_B", [0.0, 0.0, 0.0], "rad/s",
                         "Body angular velocity relative to N in B (the rigid body's), read when initialization "
                         "ends and when a step ends")
        out = lambda: self.feedthrough(self._evaluate)  # noqa: E731
        # states: the spin momenta and the body rate at the last step's end (omega_BN_B is read
        # then, and when initialization ends)
        self.output_array("wheel_speed", N, lambda: padded(out()[0]), "rad/s",
                          "Wheel speed Omega relative to the body (at the body rate of the last step's end)")
        torque_inputs = commands + (enabled,) + available
        self.output_array("motor_torque", N, lambda: padded(out()[1]), "N.m",
                          "Motor torque applied to the wheel (the command after the limits)", depends_on=torque_inputs)
        self.output_array("wheel_torque_B", 3, lambda: out()[3], "N.m",
                          "Motor plus friction torque on the wheels in B, sum g_i (u_i + f_i); the body feels the "
                          "opposite (the rigid body's wheel_torque_B)", depends_on=torque_inputs)
        # a state: the spin momenta are fixed from Omega0 and the body rate when initialization ends
        self.output_array("wheel_momentum_B", 3, lambda: out()[4], "N.m.s",
                          "Absolute spin angular momentum of the wheels in B, sum g_i J_i (g_i . omega + Omega_i) "
                          "(the rigid body's wheel_momentum_B)")
        self.output("electrical_power", lambda: float(np.sum(out()[5])), "W",
                    "Electrical power drawn by the wheels (base plus motor power; braking recovers "
                    "regen_efficiency of it)", depends_on=torque_inputs)

    _provisional = False  # the spin momenta were fixed in initialization, before its end

    def build_model(self):
        v = self.values
        count, axes = wheel_axes(v)
        used = lambda name: [v[e] for e in element_names(name, N)][:count]  # noqa: E731
        return rwa.ReactionWheelArray(axes, used("J_s"), used("max_torque"), used("max_speed"), used("max_power"),
                                      used("min_torque"), used("coulomb_friction"), used("viscous_friction"),
                                      v["omega_limit_cycle"], used("Omega0"), used("base_power"),
                                      v["motor_efficiency"], v["regen_efficiency"])

    def _inputs(self):
        count = self.model.count
        return (self.vector("torque_cmd", N)[:count], self.input_value("enabled"),
                self.vector("wheel_available", N)[:count])

    def _evaluate(self):
        model = self.model
        if model.H is None or self._provisional:  # in initialization: Omega0 at the body rate as it is now
            model.start(self.vector("omega_BN_B", 3))
            self._provisional = True
        commands, enabled, available = self._inputs()
        return model.evaluate(commands, enabled, available)

    def exit_initialization_mode(self):
        super().exit_initialization_mode()
        self.model.start(self.vector("omega_BN_B", 3))  # Omega0 relative to the body's start rate
        self._provisional = False
        self._input_version += 1

    def do_step(self, current_time, step_size):
        commands, enabled, available = self._inputs()
        self.model.step(commands, step_size, self.vector("omega_BN_B", 3), enabled, available)
        self._input_version += 1  # the spin momenta changed: recompute the outputs
        return True

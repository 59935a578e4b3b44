"""FMU `RcsThrusterSet` (instance `thrusters`): the NEIGHBOR thrusters one by one.

Wraps components.attitude.thruster_set.ThrusterSet: the thesis' 12 RCS thrusters on the module's
edge centres and 4 axial thrusters on its -x face corners (Figures 16-19), each with its own
position, direction, optional force error and misalignment; torque per Eq. 13 (l x F) summed over
the firing thrusters, the minimum on-time, the propellant thruster by thruster (Eq. 74). Same
connectors as the pair model `RcsThrusters` (torque_cmd_B in; torque_B, thrust_flag,
torque_level, fire_time, fire_time_total, propellant_mass out), so a system swaps one for the
other by replacing the component; in addition the net RCS force, and `axial_firing` (the burn)
adds the axial thrusters' torque, a disturbance when they are misaligned. With `off_pulsing` (appended
last) the y and z torques in the burn come from switching axial thrusters off (the RCS y and z pairs
stay off); `axial_off_time`, the thruster-seconds switched off, goes to the propulsion, which takes
that thrust out of the burn.
"""
from neighbor_fmu_support import NeighborSlave

from components.attitude import thruster_set
from components.mission.neighbor import SPACECRAFT

# declared after the outputs that depend on it (appended in a later release)
AXIAL_FIRING = "axial_firing"
N = 16


class RcsThrusterSet(NeighborSlave):
    description = ("NEIGHBOR thrusters one by one (thesis Figures 16-19, Eq. 13, 74): 12 RCS thrusters on the "
                   "module's edge centres and 4 axial thrusters, per-thruster force error and misalignment, "
                   "minimum on-time; applied torque, net force, firing time and propellant")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter("thrust", SPACECRAFT.rcs_thrust, "N", "Nominal force of one RCS thruster (25 mN)")
        self.parameter("edge_a", SPACECRAFT.edge_a, "m",
                       "Edge a of the host: the module's side, x-pair spacing (Eq. 16)")
        self.parameter("edge_c", SPACECRAFT.edge_c, "m",
                       "Edge c of the host along x: the y/z pairs' arms c/2, c/2 - c/3 (Eq. 16)")
        self.parameter("Isp", SPACECRAFT.isp, "s", "Specific impulse of the thrusters")
        self.parameter("g0", SPACECRAFT.g0, "m/s2", "Standard gravity used with Isp (thesis value 9.81)")
        command = self.input_array("torque_cmd_B", [0.0] * 3, "N.m", "Commanded body torque from the active controller")
        self.output_array("torque_B", 3, lambda: self.feedthrough(self._force_torque)[1], "N.m",
                          "Torque of the firing thrusters, sum of l x F (Eq. 13)",
                          depends_on=command + (AXIAL_FIRING,))
        self.output_array("thrust_flag", 3, lambda: self.feedthrough(self._flags), None,
                          "Firing pair per axis: 1 positive torque, -1 negative, 0 off", int, depends_on=command)
        self.output_array("torque_level", 3, lambda: self.model.levels, "N.m",
                          "Nominal torque of one thruster pair per axis (Eq. 16)")
        self.output_array("fire_time", 3, lambda: self.model.axis_fire_time(), "s",
                          "Accumulated firing time of the x, y, z thruster pairs")
        self.output("fire_time_total", lambda: sum(self.model.axis_fire_time()), "s",
                    "Firing time summed over the axes (the thesis' ThrustTime)")
        self.output("propellant_mass", lambda: self.model.propellant_mass(), "kg",
                    "RCS propellant used, sum of |F_i| t_i / (Isp g0) over the thrusters (Eq. 74)")
        self.parameter("min_on_time", 0.0, "s",
                       "Minimum on-time of a firing (>= 0): a thruster fired stays on at least this long")
        self.parameter_array("force_error", [0.0] * N, "1",
                             "Force error of each thruster as a fraction of thrust, in (-1, 1] (12 RCS, then 4 axial)")
        self.parameter_array("misalignment_1", [0.0] * N, "rad",
                             "Misalignment of each thruster's direction: rotation about its first perpendicular axis "
                             "(|angle| <= 0.2)")
        self.parameter_array("misalignment_2", [0.0] * N, "rad",
                             "Misalignment of each thruster's direction: rotation about its second perpendicular axis "
                             "(|angle| <= 0.2)")
        self.input(AXIAL_FIRING, False, None, "The axial de-orbit thrusters are firing (the burn): their torque "
                   "is added (their force is the propulsion's)", bool)
        self.output_array("force_B", 3, lambda: self.feedthrough(self._force_torque)[0], "N",
                          "Net force of the firing RCS thrusters in B (zero for aligned pairs; the axial thrusters' "
                          "force is the propulsion's)",
                          depends_on=command + (AXIAL_FIRING,))
        self.parameter("off_pulsing", False, None,
                       "In the burn, y and z torques by switching axial thrusters off instead of firing RCS pairs",
                       bool)
        self.output("axial_off_time", lambda: self.model.axial_off_time, "s",
                    "Time the axial thrusters were switched off in the burn (off-pulsing), summed over the thrusters")

    def build_model(self):
        v = self.values
        return thruster_set.ThrusterSet(
            v["thrust"], v["edge_a"], v["edge_c"], v["Isp"], v["g0"], v["min_on_time"], self.vector("force_error", N),
            list(zip(self.vector("misalignment_1", N), self.vector("misalignment_2", N))), v["off_pulsing"])

    def _flags(self):
        return self.model.flags(self.vector("torque_cmd_B", 3))

    def _force_torque(self):
        return self.model.force_and_torque(self.feedthrough(self._flags), self.values["axial_firing"])

    def do_step(self, current_time, step_size):
        self.model.step(self.feedthrough(self._flags), step_size, self.values["axial_firing"])
        self._input_version += 1  # the minimum on-time changed: outputs computed before the step are stale
        return True

"""FMU `RcsThrusters` (instance `thrusters`): RCS thruster pairs of NEIGHBOR.

Wraps components.attitude.thrusters.ThrusterPairs (thesis Eq. 13-16 and 74): commanded torque in,
applied torque and thrust flags out (direct feedthrough), firing time and propellant mass
accumulated over the steps (states).
"""
from neighbor_fmu_support import NeighborSlave

from components.attitude import thrusters
from components.mission.neighbor import SPACECRAFT


class RcsThrusters(NeighborSlave):
    description = ("RCS thruster pairs (NEIGHBOR thesis Eq. 13-16, 74): commanded torque rounded to the pair "
                   "torque levels, applied torque, firing time and propellant used")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter("thrust", thrusters.tc.F_THRUSTER, "N", "Force of one RCS thruster (25 mN)")
        self.parameter("edge_a", SPACECRAFT.edge_a, "m", "Edge a of the host (x-axis pair lever arm a/2, Eq. 16)")
        self.parameter("edge_c", SPACECRAFT.edge_c, "m", "Edge c of the host (y/z-axis pair lever arms, Eq. 16)")
        self.parameter("Isp", SPACECRAFT.isp, "s", "Specific impulse of the thrusters")
        self.parameter("g0", SPACECRAFT.g0, "m/s2", "Standard gravity used with Isp (thesis value 9.81)")
        command = self.input_array("torque_cmd_B", [0.0] * 3, "N.m", "Commanded body torque from the active controller")

        self.output_array("torque_B", 3, lambda: self.feedthrough(self._applied), "N.m",
                          "Torque applied by the firing pairs (nearest level in {-L, 0, +L})",
                          depends_on=command)
        self.output_array("thrust_flag", 3, lambda: self.feedthrough(self._flags), None,
                          "Firing pair per axis: 1 positive torque, -1 negative, 0 off", int, depends_on=command)
        self.output_array("torque_level", 3, lambda: self.model.levels, "N.m",
                          "Torque of one thruster pair per axis from the geometry (Eq. 16)")
        self.output_array("fire_time", 3, lambda: self.model.fire_time, "s",
                          "Accumulated firing time of the x, y, z thruster pairs")
        self.output("fire_time_total", lambda: self.model.total_fire_time(), "s",
                    "Firing time summed over the axes (the thesis' ThrustTime)")
        self.output("propellant_mass", lambda: self.model.propellant_mass(), "kg",
                    "Propellant used, 2 F t_fire / (Isp g0) (Eq. 74)")
        self.share_values()
        self._inputs_at = self.shared_indices((("torque_cmd_B", 3),))
        self._outputs_at = self.shared_indices(thrusters.PUBLISHED)

    def build_model(self):
        return thrusters.ThrusterPairs(self.values["thrust"], self.values["edge_a"], self.values["edge_c"],
                                       self.values["Isp"], self.values["g0"])

    def _applied(self):
        return self.model.applied_torque(self.vector("torque_cmd_B", 3))

    def _flags(self):
        return self.model.flags(self.vector("torque_cmd_B", 3))

    def do_step(self, current_time, step_size):
        self.model.step_into(self.shared, self._inputs_at, self._outputs_at, step_size)
        self.mark_published()
        if not self.share_native[0] and self.native_ready():
            from components.attitude import native_steps  # numba is loaded: the same step, no Python
            self.arm_native(native_steps.step("thruster_pairs"), self.model.state, self.shared, self._inputs_at,
                            self._outputs_at, self.share_flags,
                            publish=native_steps.step("thruster_pairs_publish"))
        return True

    def publish(self):
        # the getters' values (NeighborSlave.publish) in one compiled call
        self.model.step_into(self.shared, self._inputs_at, self._outputs_at, 0.0, stepping=False)
        self.mark_published()

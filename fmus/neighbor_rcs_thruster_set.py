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

The stuck-thruster fault and its management (appended after off-pulsing): `stuck_thruster`
(1-12, 0 none) never fires, or with `stuck_on` fires at every step, once the set has operated
`stuck_time`; with `fault_detection` the flight software's monitor
(components.attitude.thruster_monitor) compares the gyro's rates (`omega_meas_B`) with the
response the thrusters it opened should give (nominal layout, the inertia of a box of `mass` and
edges a, b, c), closes the declared thrusters' latch valves and allocates the flags over the
others (a pair declared together, one stuck off and one stuck on, is probed below 1 deg/s and the
healthy one reopened); `disabled_mask` (bit i-1 for RCS thruster i, the valves closed now) and
`fault_time` (the first declaration) say what and when.

Mass properties and the orbit (appended last): with `propellant_mass_properties` the torques are about
the centre of mass as propellant leaves the tank at the module's centre (the burn's
`propellant_used` from the propulsion and the set's own `propellant_mass`; `mass` the mass at
takeover). `impulse_B` is the running total of the force that the propulsion's nominal thrust does
not carry (the RCS net force, the axial thrusters' force error and misalignment in the burn): the
orbit takes its mean over each of its steps.
"""
import math

from neighbor_fmu_support import NeighborSlave

from components.attitude import mass_properties, rigid_body, thruster_monitor, thruster_set
from components.core import checks
from components.mission.neighbor import SPACECRAFT

# declared after the outputs that depend on them (appended in later releases)
AXIAL_FIRING = "axial_firing"
PROPELLANT_USED = "propellant_used"
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
                          "Torque of the firing thrusters, sum of l x F (Eq. 13), about the centre of mass",
                          depends_on=command + (AXIAL_FIRING, PROPELLANT_USED))
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
        # the stuck-thruster fault and its detection (appended in a later release)
        self.parameter("stuck_thruster", 0, None,
                       "Stuck-thruster fault: the RCS thruster that sticks, 0 for none (1-12 in layout order: x+1, "
                       "x+2, x-1, x-2, y+far, y+near, y-far, y-near, z+far, z+near, z-far, z-near)", int)
        self.parameter("stuck_on", False, None, "The stuck thruster fires at every step (a valve stuck open); false: "
                       "it never fires", bool)
        self.parameter("stuck_time", 0.0, "s", "Operating time (the sum of the set's steps) at which the thruster "
                       "sticks (>= 0)")
        self.parameter("fault_detection", False, None,
                       "Flight software detects a stuck thruster from the gyro's rates, closes its latch valve and "
                       "allocates the flags over the others", bool)
        self.parameter("mass", SPACECRAFT.mass, "kg", "Spacecraft mass the detection's inertia is computed from "
                       "(a uniform box of edges a, b, c, Eq. 4)")
        self.parameter("edge_b", SPACECRAFT.edge_b, "m", "Box edge b along body z, for the detection's inertia")
        self.parameter("gyro_sigma", 5.5e-4, "rad/s", "The gyro's noise of one sample at gyro_sample_time (the "
                       "detection's noise model)")
        self.parameter("gyro_sample_time", 0.1, "s", "The sample time gyro_sigma is given at (white rate noise: "
                       "scaled by the square root of the ratio to the step)")
        self.parameter("detection_window", 1.0, "s", "Window of the rate response the detection tests (two in a "
                       "row name the fault)")
        self.input_array("omega_meas_B", [0.0] * 3, "rad/s", "The gyro's measured body rates (the "
                                 "detection's only view of the body)")
        self.output("disabled_mask", lambda: sum(1 << self.model.rcs.index(i) for i in self.model.disabled), None,
                    "RCS thrusters whose latch valve the fault detection closed: bit i-1 for thruster i (0: none)", int)
        self.output("fault_time", lambda: self.model.fault_time, "s",
                    "Time the fault detection declared a stuck thruster (-1: never)")
        # mass properties and the force on the orbit (appended in a later release)
        self.parameter("propellant_mass_properties", False, None,
                       "Torques about the centre of mass as the propellant leaves the tank at the module's centre "
                       "(-c/2 + a/2, 0, 0); false: about the host's centre (thesis)", bool)
        self.input(PROPELLANT_USED, 0.0, "kg", "Propellant the de-orbit burn drew from the tank (>= 0), from the "
                   "propulsion; moves the centre of mass with propellant_mass_properties")
        self.output_array("impulse_B", 3, lambda: self.model.impulse, "N.s",
                          "Running total of the force beyond the propulsion's nominal thrust, in B: the RCS net force "
                          "and the axial thrusters' force error and misalignment in the burn (for the orbit)")
        self.share_values(outputs=False)

    def build_model(self):
        v = self.values
        # the detection's and the mass properties' values, refused even while those options are off
        # (a negative mass was taken silently and failed only once the option was switched on)
        for name, unit in (("mass", "kg"), ("edge_b", "m"), ("gyro_sample_time", "s"), ("detection_window", "s")):
            checks.positive(name, v[name], unit)
        if not (math.isfinite(v["gyro_sigma"]) and v["gyro_sigma"] >= 0.0):
            raise ValueError(f"gyro_sigma = {v['gyro_sigma']!r} rad/s must be a finite number >= 0")
        model = thruster_set.ThrusterSet(
            v["thrust"], v["edge_a"], v["edge_c"], v["Isp"], v["g0"], v["min_on_time"], self.vector("force_error", N),
            list(zip(self.vector("misalignment_1", N), self.vector("misalignment_2", N))), v["off_pulsing"],
            v["stuck_thruster"], v["stuck_on"], v["stuck_time"])
        if v["fault_detection"]:
            inertia = rigid_body.box_inertia(v["mass"], v["edge_a"], v["edge_b"], v["edge_c"])
            model.monitor = thruster_monitor.ThrusterMonitor(
                dict(enumerate(model.nominal_torques)), model.rcs, inertia, v["gyro_sigma"], v["gyro_sample_time"],
                v["detection_window"])
        if v["propellant_mass_properties"]:
            model.follow_propellant(v["mass"], mass_properties.tank_position(v["edge_a"], v["edge_c"]))
        return model

    def _flags(self):
        return self.model.flags(self.vector("torque_cmd_B", 3))

    def _force_torque(self):
        self.model.set_main_propellant(self.input_value(PROPELLANT_USED))
        return self.model.force_and_torque(self.feedthrough(self._flags), self.input_value(AXIAL_FIRING))

    def do_step(self, current_time, step_size):
        self.count_shared_inputs()  # inputs the binary set since the last get: a new feedthrough version
        flags, burn = self.feedthrough(self._flags), self.input_value(AXIAL_FIRING)
        self.model.set_main_propellant(self.input_value(PROPELLANT_USED))
        if self.model.monitor is not None:
            self.model.watch(current_time, self.vector("omega_meas_B", 3), flags, step_size, burn)
        self.model.step(flags, step_size, burn)
        self._input_version += 1  # the minimum on-time changed: outputs computed before the step are stale
        return True

"""FMU `SunAvoidanceGuidance` (instance `guidance`): Sun-avoidance slew reference.

Wraps components.attitude.sun_avoidance.SunAvoidanceGuidance: plans (from parameters only) an
eigenaxis slew from q0 to q_f (from rest or the start rate phi_dot_0, to rest or the end rate
phi_dot_f), split into three eigenaxis segments around the Sun keep-out cone when the direct one
would sweep the boresight through it, each with a bang-coast-bang profile, and streams the
analytic reference at the communication point time. Its outputs depend on time only; its one
input, the spacecraft's attitude, is only checked against q0 when initialization ends (a
mismatch is an error, not a reference that jumps). The reference time is the FMU's only state.
"""
import math

from neighbor_fmu_support import NeighborSlave

from components.attitude import rigid_body, sun_avoidance
from components.mission.neighbor import SPACECRAFT

MAX_SEGMENTS = 3


class SunAvoidanceGuidance(NeighborSlave):
    description = ("Sun-avoidance slew guidance: eigenaxis slew (three segments around the Sun keep-out cone when "
                   "needed), bang-coast-bang profiles; reference quaternion, rates, accelerations, feed-forward torque")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter_array("boresight_B", [0.0, 0.0, 1.0], "1",
                             "Body-fixed boresight direction P in B (non-zero; normalized)")
        self.parameter_array("sun_N", [1.0, 0.0, 0.0], "1", "Sun direction S in N (non-zero; normalized)")
        self.parameter("epsilon", math.radians(30.0), "rad", "Sun keep-out cone half-angle, in (0, pi/2)")
        self.parameter("margin", math.radians(5.0), "rad",
                       "Extra angle the detour keeps from the cone (>= 0, epsilon + margin < pi/2)")
        self.parameter_array("q0", [0.0, 0.0, 0.0, 1.0], "1", "Initial attitude q_BN, scalar last (non-zero)")
        self.parameter_array("q_f", [0.0, 0.0, 0.0, 1.0], "1", "Final attitude q_BN, scalar last (non-zero)")
        self.parameter("w_max", 0.05, "rad/s", "Maximum slew rate of each segment (> 0)")
        self.parameter("a_max", 0.01, "rad/s2", "Maximum slew acceleration of each segment (> 0)")
        self.parameter("t_start", 0.0, "s", "Simulation time at which the slew starts (q0 held before)")
        self.parameter("phi_dot_0", 0.0, "rad/s",
                       "Rate along the first segment's axis at t_start, in [0, w_max] (0: from rest)")
        self.parameter("phi_dot_f", 0.0, "rad/s",
                       "Rate along the last segment's axis at the end, in [0, w_max] (0: to rest; after the end "
                       "the reference goes on turning at it)")
        self.parameter("q0_tolerance", 1e-6, "rad",
                       "Largest rotation between q0 and the attitude input q_BN when initialization ends (> 0)")
        self.input_array("q_BN", [0.0] * 4, "1",
                         "Spacecraft attitude q_BN, scalar last (connect to the dynamics): must equal q0 at the "
                         "start; all zeros (not connected) skips the check")
        self.parameter("mass", SPACECRAFT.mass, "kg",
                       "Spacecraft mass for the box inertia of the feed-forward torque (Eq. 4)")
        self.parameter("edge_a", SPACECRAFT.edge_a, "m", "Box edge a along body y (Ix uses a, b; Iz uses a, c)")
        self.parameter("edge_b", SPACECRAFT.edge_b, "m", "Box edge b along body z (Ix uses a, b; Iy uses b, c)")
        self.parameter("edge_c", SPACECRAFT.edge_c, "m", "Box edge c along body x (Iy uses b, c; Iz uses a, c)")

        ref = self._reference  # cached per (model, time); outputs depend on time only
        self.output_array("q_ref_BN", 4, lambda: ref()["q"], "1", "Reference attitude quaternion q_BN, scalar last")
        self.output_array("omega_ref_BN_B", 3, lambda: ref()["omega"], "rad/s", "Reference angular velocity, in B")
        self.output_array("omega_dot_ref_BN_B", 3, lambda: ref()["omega_dot"], "rad/s2",
                          "Reference angular acceleration, in B")
        self.output_array("torque_ff_B", 3, lambda: ref()["torque_ff"], "N.m",
                          "Feed-forward torque J omega_dot_ref + omega_ref x J omega_ref, in B")
        self.output("segment", lambda: ref()["segment"], None,
                    "Current segment 1..segment_count (0 before t_start or with no motion; last after the end)", int)
        self.output("segment_count", lambda: len(self.model.segments), None,
                    "Number of planned segments (1: direct eigenaxis, 3: around the keep-out cone)", int)
        self.output("sun_angle", lambda: ref()["sun_angle"], "rad", "Angle between the reference boresight and the Sun")
        self.output("min_sun_angle", lambda: self.model.min_angle, "rad",
                    "Smallest boresight-to-Sun angle of the whole planned path (exact swept-arc test)")
        self.output("done", lambda: ref()["done"], None,
                    "The reference profile has ended (final attitude, at the end rate phi_dot_f)", bool)
        self.output("duration", lambda: self.model.duration, "s", "Planned total duration (sum of segment durations)")
        self.output_array("segment_angle", MAX_SEGMENTS, lambda: self._per_segment(lambda s: s.angle), "rad",
                          "Eigenaxis rotation angle of each segment (0 for unused segments)")
        self.output_array("segment_duration", MAX_SEGMENTS, lambda: self._per_segment(lambda s: s.profile.tf), "s",
                          "Duration of each segment's bang-coast-bang profile (0 for unused segments)")

    def _per_segment(self, f):
        segs = self.model.segments
        return [f(segs[i]) if i < len(segs) else 0.0 for i in range(MAX_SEGMENTS)]

    def _reference(self):
        m = self.model
        key = (id(m), m.time)
        if getattr(self, "_ref_key", None) != key:
            self._ref_key, self._ref = key, m.reference()
        return self._ref

    def build_model(self):
        v = self.values
        J = rigid_body.box_inertia(v["mass"], v["edge_a"], v["edge_b"], v["edge_c"]).tolist()
        model = sun_avoidance.SunAvoidanceGuidance(
            self.vector("boresight_B", 3), self.vector("sun_N", 3), v["epsilon"], self.vector("q0", 4),
            self.vector("q_f", 4), v["w_max"], v["a_max"], J, v["margin"], v["t_start"], v["phi_dot_0"],
            v["phi_dot_f"])
        model.time = self.start_time
        return model

    def exit_initialization_mode(self):
        super().exit_initialization_mode()
        if not self.values["q0_tolerance"] > 0.0:
            raise ValueError(f"q0_tolerance {self.values['q0_tolerance']} must be > 0")
        sun_avoidance.check_start(self.vector("q0", 4), self.vector("q_BN", 4), self.values["q0_tolerance"])

    def do_step(self, current_time, step_size):
        self.model.step(current_time + step_size)
        return True

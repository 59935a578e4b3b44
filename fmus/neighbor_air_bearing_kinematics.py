"""FMU `AirBearingKinematics` (instance `kinematics`): attitude thresholding for a spherical
air-bearing testbed without an IMU (the air-bearing note).

Wraps components.sensing.air_bearing.AirBearingKinematics. Input: the DCM stream dcm_BN[i,j] ([BN],
N components to B components, like components.core.rotations.attitude_matrix; the description's R = R^N_B
(B to N) is its transpose). Outputs: the attitude rebuilt from 3-2-1 Euler angles with pitch
and roll limited to +-tau, the angular velocity estimated from consecutive DCMs, the limited
angles and a `limited` flag. All outputs depend directly on the DCM input (the rate through
the difference with the previous, stored DCM).

The DCM present at doStep(t, h) is committed as the sample at t. A new DCM set after the step
gives the rate over the step at once (air_bearing.ssd steps Gauss-Seidel in the order to_dcm,
kinematics, dynamics: no lag); if the input is still the committed DCM (Jacobi, libcosim, or the
DCM's source stepped first) omega holds the committed sample's estimate (one step of lag).
"""
import math

from neighbor_fmu_support import NeighborSlave

from components.core.names import matrix_names
from components.sensing import air_bearing


class AirBearingKinematics(NeighborSlave):
    description = ("Air-bearing testbed kinematics without an IMU (the air-bearing note): angular velocity from "
                   "the DCM "
                   "stream, 3-2-1 Euler angles, pitch and roll limited to +-tau, DCM and quaternion rebuilt "
                   "from the limited angles")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter("tau", math.radians(40.0), "rad",
                       "Pitch and roll limit tau, in (0, pi/2); default 40 deg")
        self.parameter("dcm_tol", 1e-6, "1",
                       "Largest accepted max|C C^T - I| of the input dcm_BN, in (0, 0.1]; beyond it is an error")
        self.parameter("rate_method", "log_map", None,
                       "'log_map': omega = log(C_k C_prev^T)/h, exact for a constant rate; 'finite_difference': "
                       "the description's [omega x] = -(C_k - C_prev)/h C_k^T (skew part)", str)
        self.parameter("rate_from_thresholded", True, None,
                       "True (seed): omega is the rate of the thresholded DCM stream (the thresholded DCM is "
                       "the previous DCM of the next estimate); false: rate of the raw input DCMs", bool)
        self._dcm_inputs = tuple(
            self.input(element, 1.0 if i == j else 0.0, "1",
                       f"Input DCM [BN] element ({i},{j}): maps N components to B components "
                       "(transpose of the description's R^N_B)")
            for i, row in enumerate(matrix_names("dcm_BN", 3, 3), 1) for j, element in enumerate(row, 1))
        dcm = self._dcm_inputs

        self.output_array("q_BN", 4, lambda: self._out()["q_BN"], "1",
                          "Thresholded attitude quaternion of B relative to N, scalar last (sign continuous)",
                          depends_on=dcm)
        self.output_array("omega_BN_B", 3, lambda: self._out()["omega_BN_B"], "rad/s",
                          "Angular velocity of B relative to N in B, estimated from consecutive DCMs "
                          "(zero before the first step)", depends_on=dcm)
        self.output_array("euler321", 3, lambda: self._out()["euler321"], "rad",
                          "3-2-1 Euler angles after limiting, in the order yaw psi, pitch theta, roll phi; "
                          "[BN] = R1(phi) R2(theta) R3(psi)", depends_on=dcm)
        for i, row in enumerate(matrix_names("dcm_out_BN", 3, 3), 1):
            for j, element in enumerate(row, 1):
                self.output(element, lambda i=i, j=j: self._out()["dcm_out_BN"][i - 1][j - 1], "1",
                            f"Thresholded DCM [BN] element ({i},{j}), rebuilt from the limited 3-2-1 angles",
                            depends_on=dcm)
        self.output("limited", lambda: self._out()["limited"], None,
                    "True when pitch or roll exceeded tau and was clamped", bool, depends_on=dcm)

    def build_model(self):
        return air_bearing.AirBearingKinematics(self.values["tau"], self.values["dcm_tol"],
                                                self.values["rate_method"], self.values["rate_from_thresholded"])

    def _dcm(self):
        values = self.values
        return [values[k] for k in self._dcm_inputs]

    def _evaluate(self):
        return self.model.evaluate(self._dcm())

    def _out(self):
        return self.feedthrough(self._evaluate)

    def do_step(self, current_time, step_size):
        self.model.step(self._dcm(), current_time, step_size)
        self._input_version += 1  # the stored previous DCM changed: outputs must be recomputed
        return True

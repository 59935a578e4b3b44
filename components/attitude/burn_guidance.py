"""De-orbit burn guidance: the burn attitude and its rate from the actual orbit.

Thesis Section 3.3.8: during the burn the axial thrusters' axis (+x_B, the force on the
spacecraft, components/orbit/propulsion.py) points against the direction of motion, so the
burn frame turns once per orbit about the orbit normal. From the orbit's position r and
velocity v (N frame):

    x_B = -v / |v|                     (anti-velocity: the thrust lowers the orbit)
    y_B = h / |h|,  h = r x v          (orbit normal)
    z_B = x_B x y_B                    (towards nadir on a circular orbit: z_B = -r/|r|)
    A_target = [x_B y_B z_B]^T          (rows: the body axes in N; maps N to B, Eq. 22)
    omega_target_B = [0, |h| / |r|^2, 0]

For a circular orbit |h| / |r|^2 is the mean motion, the thesis' Eq. 67-68 rate at the actual
radius instead of at Re + 400 km. On a slightly eccentric orbit v turns at a rate that differs
from |h|/|r|^2 by order e; the tracking controller corrects the difference, and the target is
recomputed from r and v at every step, so the error does not accumulate.
"""
import math

from ..core import checks, rotations


def burn_frame(r_N, v_N):
    """(q_BN, omega_BN_B) of the burn attitude for position r_N (m) and velocity v_N (m/s)."""
    r = checks.finite_vector(r_N, 3, "r_BN_N", "position in N (m)")
    v = checks.finite_vector(v_N, 3, "v_BN_N", "velocity in N (m/s)")
    h = rotations.cross(r, v)
    rn, vn, hn = rotations.norm(r), rotations.norm(v), rotations.norm(h)
    if rn == 0.0 or vn == 0.0 or hn <= 1e-9 * rn * vn:
        raise ValueError(f"r_BN_N {list(r)} and v_BN_N {list(v)} must be non-zero and not parallel "
                         "(the orbit plane is undefined)")
    x = tuple(-c / vn for c in v)
    y = tuple(c / hn for c in h)
    z = rotations.cross(x, y)
    return rotations.dcm_to_quaternion((x, y, z)), (0.0, hn / (rn * rn), 0.0)


def thrust_axis_error(q_BN, r_N, v_N, axis_B=(1.0, 0.0, 0.0)):
    """Angle (rad) between the thrust axis axis_B (in B, for attitude q_BN) and -v."""
    A = rotations.attitude_matrix(q_BN)
    axis_N = tuple(sum(A[i][j] * axis_B[i] for i in range(3)) for j in range(3))  # A^T axis_B
    vn = rotations.norm(v_N)
    c = -rotations.dot(axis_N, v_N) / (vn * rotations.norm(axis_N))
    return math.acos(max(-1.0, min(1.0, c)))


class BurnGuidance:
    """Stateless guidance law, as the FMU wrapper's model: frame(r, v) = burn_frame(r, v)."""

    def frame(self, r_N, v_N):
        return burn_frame(r_N, v_N)

    def get_state(self):
        return {}

    def set_state(self, state):
        pass

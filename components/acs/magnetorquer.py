"""Three orthogonal magnetic torque coils (magnetorquers) along the body axes.

The commanded magnetic dipole is saturated per axis to +-max_dipole[i] (A.m2), zero when the
coils are disabled, and the torque is the dipole crossed with the local field:

    tau_B = m_B x B_B      (N.m = A.m2 x T: the torque on a magnetic dipole in a field, e.g.
                            Markley and Crassidis, Fundamentals of Spacecraft Attitude
                            Determination and Control, 2014, ch. 3; the thesis/seed convention
                            "torque = dipole cross field")

Default max_dipole 0.2 A.m2 per axis: the class of CubeSat torque rods and embedded air-core
coils (typically 0.1-0.4 A.m2). The coils are ideal (no inductance or current dynamics, no
residual dipole): the dipole follows the command within the communication step.
"""
import math

from ..core import rotations


class TorqueCoils:
    def __init__(self, max_dipole=(0.2, 0.2, 0.2)):
        md = tuple(float(x) for x in max_dipole)
        if len(md) != 3:
            raise ValueError(f"max_dipole {list(md)} must have 3 components")
        for i, x in enumerate(md, 1):
            if not (math.isfinite(x) and x >= 0.0):
                raise ValueError(f"max_dipole[{i}] = {x!r} must be a finite number >= 0 A.m2")
        self.max_dipole = md

    def dipole(self, dipole_cmd, enabled=True):
        """Commanded dipole saturated per axis to [-max_dipole, max_dipole]; zero if disabled."""
        if not enabled:
            return (0.0, 0.0, 0.0)
        out = []
        for i in range(3):
            c = float(dipole_cmd[i])
            if math.isnan(c):
                raise ValueError(f"dipole_cmd_B[{i + 1}] = nan must be a number (A.m2)")
            m = self.max_dipole[i]
            out.append(m if c > m else (-m if c < -m else c))
        return tuple(out)

    def torque(self, dipole_cmd, field_B, enabled=True):
        """(dipole_B, torque_B = dipole_B x field_B)."""
        m = self.dipole(dipole_cmd, enabled)
        if not all(math.isfinite(float(x)) for x in field_B):
            raise ValueError(f"B_B {list(field_B)} must be finite (T)")
        return m, rotations.cross(m, tuple(float(x) for x in field_B))

    def get_state(self):
        return {}

    def set_state(self, state):
        pass

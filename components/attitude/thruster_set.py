"""The NEIGHBOR thrusters one by one: positions, directions, force per thruster, Eq. 13 torques.

Thesis Section 3.3.2 (Figures 16-19, Eq. 13-16): twelve RCS thrusters sit on the centre points of
the edges of the NEIGHBOR module, and four axial de-orbit thrusters on the corners of its face
that the x axis crosses. With the host's edges a (along y), b (along z), c (along x) and the
module a cube of side a = c/3 at the -x end of the host (its far face at x = -c/2, its near face
at x = -c/2 + c/3, the "50 mm gap" to the y axis of Figure 18), every thruster's exhaust leaves
outward from the module, so its force points inward:

    x pairs  edges along x at x = -c/2 + a/2, (y, z) = (+-a/2, +-a/2), force -+z (z = +-a/2)
    y pairs  edges along y at x = -c/2 and -c/2 + a, z = +-a/2, force -+z
    z pairs  edges along z at x = -c/2 and -c/2 + a, y = +-a/2, force -+y
    axial    corners of the x = -c/2 face, (y, z) = (+-a/2, +-a/2), force +x (the burn)

A pair fires two thrusters with opposite forces (no net force) whose torques add:

    L = sum_i l_i x F_i                                                   (Eq. 13)
    L_x = (a/2) 2F,   L_y = L_z = F c/2 - F (c/2 - c/3) = F c/3           (Eq. 16)

which this geometry gives exactly, with the centre of mass at the host's centre. Each
thruster can carry its own force error (a fraction of F) and a misalignment (a small rotation
of its direction, two angles about the axes perpendicular to it), so the torques and the net
force of a pair are those of real hardware. A thruster, once fired, stays on for at least
`min_on_time` (the minimum impulse bit); the propellant is m = sum_i F_i t_i / (Isp g0) (Eq. 74
per thruster; with nominal forces, 2 F t per pair as the thesis counts it).

Off-pulsing (`off_pulsing`, off by default: the thesis fires RCS pairs for every axis). In the
burn a y or z torque can come from switching axial thrusters off instead of firing an RCS pair:
an axial thruster at (x, y, z) pushing +x adds (0, z F, -y F) to the torque, so switching it off
adds (0, -z F, y F). A y command of sign s switches off the two on the z = -s a/2 side, a z
command the two on the y = s a/2 side (2 (a/2) F = a F about the axis, the y/z pair's F c/3 for
the thesis' module a = c/3), both together the one thruster on the diagonal (half of that on each
axis). The RCS y and z pairs then stay off in the burn; x always comes from its pairs. The torque
is that of the real (misaligned, force-error) thrusters left on. The thrust lost is counted in
thruster-seconds (`axial_off_time`): the propulsion takes it out of the burn's thrust and flow, so
the burn lasts a little longer on the same propellant and the RCS spends none on y and z. This is
how a spacecraft trims a thrust-axis misalignment during a burn at no propellant cost.
"""
import math

from ..core import checks, rotations
from ..mission.neighbor import SPACECRAFT
from . import thruster_control as tc

AXES = ("x", "y", "z")


def thesis_layout(a=0.1, c=0.3):
    """[(name, position (m), unit force direction, role)] of the 12 RCS and 4 axial thrusters;
    role is (axis index, sign) of the pair torque it belongs to, or "axial"."""
    for name, value in (("edge a", a), ("edge c", c)):
        checks.positive(name, value, "m")
    h = a / 2.0
    far, near = -c / 2.0, -c / 2.0 + c / 3.0
    mid = far + h
    out = []
    # x pairs (edges along x): L_x = y F_z - z F_y
    for sign, pair in ((1, [((mid, h, -h), (0.0, 0.0, 1.0)), ((mid, -h, h), (0.0, 0.0, -1.0))]),
                       (-1, [((mid, h, h), (0.0, 0.0, -1.0)), ((mid, -h, -h), (0.0, 0.0, 1.0))])):
        out += [(f"x{'+-'[sign < 0]}{k + 1}", p, d, (0, sign)) for k, (p, d) in enumerate(pair)]
    # y pairs (edges along y): L_y = -x F_z; the far thruster's torque outweighs the near one's
    for sign, pair in ((1, [((far, 0.0, -h), (0.0, 0.0, 1.0)), ((near, 0.0, h), (0.0, 0.0, -1.0))]),
                       (-1, [((far, 0.0, h), (0.0, 0.0, -1.0)), ((near, 0.0, -h), (0.0, 0.0, 1.0))])):
        out += [(f"y{'+-'[sign < 0]}{('far', 'near')[k]}", p, d, (1, sign)) for k, (p, d) in enumerate(pair)]
    # z pairs (edges along z): L_z = x F_y
    for sign, pair in ((1, [((far, h, 0.0), (0.0, -1.0, 0.0)), ((near, -h, 0.0), (0.0, 1.0, 0.0))]),
                       (-1, [((far, -h, 0.0), (0.0, 1.0, 0.0)), ((near, h, 0.0), (0.0, -1.0, 0.0))])):
        out += [(f"z{'+-'[sign < 0]}{('far', 'near')[k]}", p, d, (2, sign)) for k, (p, d) in enumerate(pair)]
    for y, z in ((h, h), (-h, h), (-h, -h), (h, -h)):
        out.append((f"axial{len(out) - 11}", (far, y, z), (1.0, 0.0, 0.0), "axial"))
    return out


def _sign(x):
    return (x > 0) - (x < 0)


def _misaligned(direction, angles):
    """`direction` turned by the small angles (rad) about the two axes perpendicular to it."""
    d = tuple(direction)
    k = max(range(3), key=lambda i: abs(d[i]))
    u = [0.0, 0.0, 0.0]
    u[(k + 1) % 3] = 1.0
    v = rotations.cross(d, u)
    q = rotations.circle_cross(rotations.from_axis_angle(u, angles[0]), rotations.from_axis_angle(v, angles[1]))
    A = rotations.attitude_matrix(q)
    out = tuple(sum(A[j][i] * d[j] for j in range(3)) for i in range(3))  # A^T d: turned by q
    n = rotations.norm(out)
    return tuple(x / n for x in out)


class ThrusterSet:
    """RCS and axial thrusters one by one (thesis geometry by default).

    force: nominal force of one thruster (N); force_error: per-thruster fraction (16 values, e.g.
    0.02 = 2 % strong); misalignment: per-thruster pair of small angles (rad); min_on_time (s);
    isp, g0 for the propellant; off_pulsing: y and z torques in the burn from the axial thrusters
    (module docstring). Commands are -1/0/+1 per axis (the controllers' thrust flags)."""

    def __init__(self, force=SPACECRAFT.rcs_thrust, a=SPACECRAFT.edge_a, c=SPACECRAFT.edge_c, isp=SPACECRAFT.isp,
                 g0=SPACECRAFT.g0, min_on_time=0.0, force_error=None,
                 misalignment=None, off_pulsing=False):
        self.layout = thesis_layout(a, c)
        n = len(self.layout)
        self.force = checks.positive("thrust", force, "N")
        self.isp = checks.positive("Isp", isp, "s")
        self.g0 = checks.positive("g0", g0, "m/s2")
        self.min_on_time = float(min_on_time)
        if not (math.isfinite(self.min_on_time) and self.min_on_time >= 0):
            raise ValueError(f"min_on_time = {min_on_time!r} s must be a finite number >= 0")
        errors = [0.0] * n if force_error is None else [float(x) for x in force_error]
        if len(errors) != n or not all(math.isfinite(x) and -1.0 < x <= 1.0 for x in errors):
            raise ValueError(f"force_error must be {n} fractions in (-1, 1], got {errors!r}")
        angles = [(0.0, 0.0)] * n if misalignment is None else [tuple(map(float, m)) for m in misalignment]
        if len(angles) != n or not all(len(m) == 2 and all(math.isfinite(x) and abs(x) <= 0.2 for x in m)
                                       for m in angles):
            raise ValueError(f"misalignment must be {n} pairs of angles within 0.2 rad, got {angles!r}")
        self.forces = []  # force vector of each thruster while it fires (N, B)
        self.torques = []  # its torque l x F (N.m, B), Eq. 13
        for (_, position, direction, _), err, ang in zip(self.layout, errors, angles):
            d = _misaligned(direction, ang) if ang != (0.0, 0.0) else direction
            f = tuple(self.force * (1.0 + err) * x for x in d)
            self.forces.append(f)
            self.torques.append(rotations.cross(position, f))
        self.force_norms = [rotations.norm(f) for f in self.forces]  # read at every step's propellant output
        self.pairs = {}  # (axis, sign) -> thruster indices
        for i, (_, _, _, role) in enumerate(self.layout):
            if role != "axial":
                self.pairs.setdefault(role, []).append(i)
        self.axial = [i for i, (_, _, _, role) in enumerate(self.layout) if role == "axial"]
        self.levels = tc.pair_torques(self.force, a, c)  # the nominal pair torques (Eq. 16)
        self.off_pulsing = bool(off_pulsing)
        # (y sign, z sign) of the torque each axial thruster adds when switched off: (-z, y)
        self._off_signs = {i: (-_sign(self.layout[i][1][2]), _sign(self.layout[i][1][1])) for i in self.axial}
        self.fire_time = [0.0] * n
        self.on_left = [0.0] * n  # minimum on-time still owed after a firing started
        self.axial_off_time = 0.0  # thruster-seconds the axial thrusters were switched off in the burn

    def flags(self, command):
        """-1/0/+1 per axis: nearest available level to the commanded torque."""
        return tc.nearest_pair_flags(command, self.levels)

    def axis_fire_time(self):
        """Firing time of the x, y and z pairs (s): each pair's two thrusters' time, halved."""
        return [0.5 * sum(self.fire_time[i] for key, idx in self.pairs.items() if key[0] == axis for i in idx)
                for axis in range(3)]

    def firing(self, flags, axial=False):
        """Indices of the RCS thrusters the pair flags (-1/0/1 per axis) fire, with the ones still
        inside their minimum on-time; in the burn with off-pulsing, the x pairs only."""
        on = {i for i in range(len(self.layout)) if self.on_left[i] > 0.0}
        pulsing = axial and self.off_pulsing
        for axis, f in enumerate(flags):
            if f not in (-1, 0, 1):
                raise ValueError(f"thrust flag {axis + 1} = {f!r} must be -1, 0 or 1")
            if f and not (pulsing and axis > 0):
                on.update(self.pairs[(axis, int(f))])
        return sorted(on)

    def axial_off(self, flags, axial=False):
        """Indices of the axial thrusters switched off for the y and z flags (none unless
        off-pulsing in the burn): the side pair for one axis, the diagonal one for both."""
        if not (axial and self.off_pulsing):
            return ()
        fy, fz = int(flags[1]), int(flags[2])
        if not (fy or fz):
            return ()
        return tuple(i for i in self.axial
                     if (not fy or self._off_signs[i][0] == fy) and (not fz or self._off_signs[i][1] == fz))

    def force_and_torque(self, flags, axial=False):
        """(net force of the RCS thrusters firing for `flags` (N, B), torque (N.m, B)), the torque
        with the axial thrusters' left on when `axial` (the burn: their force is the propulsion's;
        their torque, zero when aligned and all on, is a disturbance here)."""
        fx = fy = fz = tx = ty = tz = 0.0
        for i in self.firing(flags, axial):
            f, t = self.forces[i], self.torques[i]
            fx, fy, fz = fx + f[0], fy + f[1], fz + f[2]
            tx, ty, tz = tx + t[0], ty + t[1], tz + t[2]
        if axial:
            off = self.axial_off(flags, axial)
            for i in self.axial:
                if i not in off:
                    t = self.torques[i]
                    tx, ty, tz = tx + t[0], ty + t[1], tz + t[2]
        return (fx, fy, fz), (tx, ty, tz)

    def step(self, flags, h, axial=False):
        """Advance h seconds with `flags` (and `axial`, the burn) held: firing times, the minimum
        on-time and the axial thrusters' off time."""
        for i in self.firing(flags, axial):
            started = self.on_left[i] <= 0.0
            self.fire_time[i] += h
            left = (self.min_on_time if started else self.on_left[i]) - h
            self.on_left[i] = max(0.0, left)
        self.axial_off_time += h * len(self.axial_off(flags, axial))

    def propellant_mass(self):
        """Propellant spent by the RCS so far (kg), Eq. 74 thruster by thruster."""
        impulse = sum(n * t for n, t in zip(self.force_norms, self.fire_time))
        return impulse / (self.isp * self.g0)

    def get_state(self):
        return {"fire_time": list(self.fire_time), "on_left": list(self.on_left), "axial_off_time": self.axial_off_time}

    def set_state(self, state):
        self.fire_time = list(state["fire_time"])
        self.on_left = list(state["on_left"])
        self.axial_off_time = float(state["axial_off_time"])

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

A stuck thruster (`stuck_thruster`, one of the 12 RCS thrusters, 1-based in layout order; off by
default): once the set has operated `stuck_time` seconds (the sum of its steps) that thruster
never fires (stuck off) or fires at every step (`stuck_on`, a valve stuck open). Each thruster's
feed has a latch valve (an assumption: the thesis sizes no valves): the fault management
(components.attitude.thruster_monitor) closes the faulty thruster's with `disable`, which stops
a stuck-on one (and reopens one it closed in doubt with `enable`), and from then on the flags are
allocated over the thrusters left (`allocation_table`): the torque nearest the pair torques the
flags ask for, then the smallest net force, then the fewest thrusters. No other thruster makes an
x torque of the same sign as a dead x thruster's partner, so that partner fires alone (half the
torque) and a y or z pair cancels its side torque. In the burn with off-pulsing, where the axial
thrusters take y and z, an x flag opens the x torque alone: the partner without the y pair.
With every thruster enabled the pairs fire exactly as before.

Mass properties (`follow_propellant`, off by default): the torques are about the centre of mass,
which moves to +x as propellant leaves the tank at the module's centre
(components.attitude.mass_properties): L = sum_i (l_i - r_cm) x F_i = sum_i l_i x F_i - r_cm x
sum_i F_i, so a pair (a couple) gives the same torque and only the net force of the thrusters firing,
the axial ones' in the burn included, adds r_cm x F. What reaches the orbit besides the
propulsion's nominal thrust n F x is kept as a running total, `impulse` (N.s, B): the net force of
the RCS thrusters firing and, in the burn, the axial thrusters' deviation from their nominal force
(force error and misalignment); the orbit applies its mean over each of its steps.
"""
import itertools
import math
import operator

import numpy as np

from ..core import checks, rotations
from ..mission.neighbor import SPACECRAFT
from . import mass_properties
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


def allocation_table(torques, forces, levels, force, candidates, max_thrusters=6, axes=(1.0, 1.0, 1.0),
                     force_weight=0.05):
    """{(fx, fy, fz): thruster indices} over the 27 flag triples, from the thrusters `candidates`
    (indices into `torques`/`forces`, the nominal N.m and N of each): per triple the subset of at
    most `max_thrusters` whose torque is nearest the pair torques (fx Lx, fy Ly, fz Lz) relative to
    each axis' level, then with the smallest net force, then the fewest thrusters. `axes` weighs
    each axis' miss, `force_weight` the net force (relative to one thruster's)."""
    candidates = sorted(candidates)
    subsets = [()] + [c for k in range(1, min(max_thrusters, len(candidates)) + 1)
                      for c in itertools.combinations(candidates, k)]
    member = np.zeros((len(subsets), len(torques)))
    for row, subset in enumerate(subsets):
        member[row, list(subset)] = 1.0
    torque = member @ np.asarray(torques, dtype=float)
    net_force = member @ np.asarray(forces, dtype=float)
    levels = np.asarray(levels, dtype=float)
    # a missed torque costs most, a net force (pushing the orbit) next, a thruster opened least
    base = force_weight * np.sum((net_force / force) ** 2, axis=1) + 0.01 * member.sum(axis=1)
    weights = np.asarray(axes, dtype=float)
    table = {}
    for flags in itertools.product((-1, 0, 1), repeat=3):
        cost = np.sum(weights * ((torque - np.asarray(flags) * levels) / levels) ** 2, axis=1) + base
        table[flags] = subsets[int(np.argmin(cost))]
    return table


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
    isp, g0 for the propellant; off_pulsing: y and z torques in the burn from the axial thrusters;
    stuck_thruster (1-12, 0: none), stuck_on, stuck_time (s of operation): the stuck-thruster fault
    (module docstring). Commands are -1/0/+1 per axis (the controllers' thrust flags)."""

    def __init__(self, force=SPACECRAFT.rcs_thrust, a=SPACECRAFT.edge_a, c=SPACECRAFT.edge_c, isp=SPACECRAFT.isp,
                 g0=SPACECRAFT.g0, min_on_time=0.0, force_error=None,
                 misalignment=None, off_pulsing=False, stuck_thruster=0, stuck_on=False, stuck_time=0.0):
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
        self.nominal_forces, self.nominal_torques = [], []  # the same without errors: what flight software knows
        for (_, position, direction, _), err, ang in zip(self.layout, errors, angles):
            d = _misaligned(direction, ang) if ang != (0.0, 0.0) else direction
            f = tuple(self.force * (1.0 + err) * x for x in d)
            self.forces.append(f)
            self.torques.append(rotations.cross(position, f))
            nominal = tuple(self.force * x for x in direction)
            self.nominal_forces.append(nominal)
            self.nominal_torques.append(rotations.cross(position, nominal))
        self.force_norms = [rotations.norm(f) for f in self.forces]  # read at every step's propellant output
        # what an axial thruster's real force adds to the propulsion's nominal one (zero when ideal)
        self.deviations = [tuple(f - g for f, g in zip(fr, nom)) for fr, nom in zip(self.forces, self.nominal_forces)]
        self.impulse = (0.0, 0.0, 0.0)  # N.s in B: running total of the force beyond the propulsion's thrust
        self.tank = None  # the tank's centre (m, B) when the centre of mass follows the propellant
        self.mass0 = 0.0
        self.main_drawn = 0.0  # kg the de-orbit burn drew from the tank
        self.center_of_mass = (0.0, 0.0, 0.0)
        self._com_drawn = 0.0  # the propellant drawn at the centre of mass' last move
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
        self._firings = 0  # counts the changes of fire_time: the key of the propellant's last sum
        self._propellant_at = (-1, 0.0)
        self.on_left = [0.0] * n  # minimum on-time still owed after a firing started
        self.axial_off_time = 0.0  # thruster-seconds the axial thrusters were switched off in the burn
        self.rcs = [i for i in range(n) if i not in self.axial]
        stuck = int(stuck_thruster)
        if stuck != stuck_thruster or not 0 <= stuck <= len(self.rcs):
            raise ValueError(f"stuck_thruster = {stuck_thruster!r} must be 0 (none) or an RCS thruster "
                             f"1-{len(self.rcs)}")
        self.stuck_thruster = self.rcs[stuck - 1] if stuck else None
        self.stuck_on = bool(stuck_on)
        self.stuck_time = float(stuck_time)
        if not (math.isfinite(self.stuck_time) and self.stuck_time >= 0):
            raise ValueError(f"stuck_time = {stuck_time!r} s must be a finite number >= 0")
        self.operating_time = 0.0  # s, the sum of the steps: the stuck fault's clock
        self.disabled = set()  # thrusters whose latch valve the fault management closed
        self._allocation = None  # flags -> thrusters, once a thruster is disabled
        self._burn_allocation = None  # the same for the x flags in the burn with off-pulsing
        self.monitor = None  # the fault detection (components.attitude.thruster_monitor), if flown
        self.fault_time = -1.0  # when it declared a stuck thruster (-1: never)
        # the thrusters one set of flags opens (_plan), kept until the flags or the state that
        # decides them (minimum on-times owed, valves, the stuck fault's clock) change
        self._plan_version = 0
        self._plan_key, self._plan_value = None, None

    def follow_propellant(self, mass0, tank):
        """From now on the torques are about the centre of mass of a body of `mass0` kg from whose
        tank (m, B) the propellant is drawn (module docstring)."""
        self.mass0 = checks.positive("mass", mass0, "kg")
        self.tank = tuple(float(x) for x in tank)
        self._move_center_of_mass()

    def set_main_propellant(self, used):
        """The propellant the de-orbit burn has drawn from the same tank (kg)."""
        if used != self.main_drawn:
            self.main_drawn = float(used)
            self._move_center_of_mass()

    def _move_center_of_mass(self):
        if self.tank is None:
            return
        drawn = self.main_drawn + self.propellant_mass()
        if not (math.isfinite(drawn) and 0.0 <= drawn < self.mass0):
            raise ValueError(f"propellant drawn = {drawn!r} kg must be in [0, {self.mass0!r}) (the mass at takeover)")
        if abs(drawn - self._com_drawn) < mass_properties.RESOLUTION:
            return
        m = self.mass0 - drawn
        self.center_of_mass = tuple(-drawn * x / m for x in self.tank)
        self._com_drawn = drawn

    @property
    def stuck(self):
        """The stuck-thruster fault has happened (its thruster index), or None."""
        if self.stuck_thruster is not None and self.operating_time >= self.stuck_time - 1e-9:
            return self.stuck_thruster
        return None

    def disable(self, index):
        """Close thruster `index`'s latch valve (it never fires again, stuck open or not) and
        allocate the flags over the thrusters left."""
        if index not in self.rcs:
            raise ValueError(f"thruster {index!r} is not one of the RCS thrusters {self.rcs}")
        self.disabled.add(index)
        self._allocate()

    def enable(self, index):
        """Reopen thruster `index`'s latch valve and allocate the flags over the thrusters open."""
        self.disabled.discard(index)
        self._allocate()

    def _allocate(self):
        self._plan_version += 1
        open_ = [i for i in self.rcs if i not in self.disabled]
        if len(open_) == len(self.rcs):
            self._allocation = self._burn_allocation = None
            return
        self._allocation = allocation_table(self.nominal_torques, self.nominal_forces, self.levels, self.force, open_)
        # In the burn with off-pulsing the axial thrusters take y and z at no RCS propellant, so an x
        # flag opens the x torque alone and leaves them its side torque and net force: a dead x+1's
        # partner x+2 fires alone rather than with a y pair (three thrusters for half the torque;
        # 525 km run 82 spent 37 g of RCS that way, 16.5 g with x+2 alone)
        self._burn_allocation = allocation_table(self.nominal_torques, self.nominal_forces, self.levels, self.force,
                                                 open_, axes=(1.0, 0.0, 0.0), force_weight=0.001)

    def watch(self, t, omega_meas, flags, h, axial=False):
        """The fault detection's step [t, t + h) before the set's: the gyro's rates at t and the
        thrusters flight software opens for `flags` (with the axial ones left on in the burn);
        a declared fault closes its thrusters' valves before they fire in this step."""
        # the axial thrusters' nominal torques cancel only when all four fire
        commanded, _, axial_on, _ = self._plan(flags, axial)
        opened = commanded + axial_on
        action = self.monitor.step(t, omega_meas, opened, h, self.disabled)
        if action is not None:
            close, reopen, when = action
            for index in close:
                self.disable(index)
            for index in reopen:
                self.enable(index)
            if self.fault_time < 0.0:
                self.fault_time = when

    def flags(self, command):
        """-1/0/+1 per axis: nearest available level to the commanded torque."""
        return tc.nearest_pair_flags(command, self.levels)

    def axis_fire_time(self):
        """Firing time of the x, y and z pairs (s): each pair's two thrusters' time, halved."""
        return [0.5 * sum(self.fire_time[i] for key, idx in self.pairs.items() if key[0] == axis for i in idx)
                for axis in range(3)]

    def commanded(self, flags, axial=False):
        """Indices of the RCS thrusters the pair flags (-1/0/1 per axis) open, with the ones still
        inside their minimum on-time; in the burn with off-pulsing, the x pairs only. With a
        thruster disabled, the allocation over the others (never a disabled one)."""
        on = {i for i, left in enumerate(self.on_left) if left > 0.0}
        pulsing = axial and self.off_pulsing
        for axis, f in enumerate(flags):
            if f not in (-1, 0, 1):
                raise ValueError(f"thrust flag {axis + 1} = {f!r} must be -1, 0 or 1")
        if self._allocation is not None:
            if pulsing:
                return sorted(on.union(self._burn_allocation[(int(flags[0]), 0, 0)]) - self.disabled)
            return sorted(on.union(self._allocation[tuple(int(f) for f in flags)]) - self.disabled)
        for axis, f in enumerate(flags):
            if f and not (pulsing and axis > 0):
                on.update(self.pairs[(axis, int(f))])
        return sorted(on)

    def _plan(self, flags, axial):
        """(commanded, firing, axial_on, axial_off) for `flags` and `axial` in the set's state:
        the outputs, the fault detection and the step of one mission step ask for the same, so the
        last answer is kept while neither the flags nor that state changes (callers do not change
        the lists)."""
        key = (flags[0], flags[1], flags[2], bool(axial), self._plan_version)
        if key != self._plan_key:
            commanded = self.commanded(flags, axial)
            self._plan_value = (commanded, self.firing(flags, axial, commanded), self.axial_on(flags, axial),
                                self.axial_off(flags, axial))
            self._plan_key = key
        return self._plan_value

    def firing(self, flags, axial=False, commanded=None):
        """Indices of the RCS thrusters that fire: the commanded ones (`commanded`, if already
        known), less a stuck-off thruster, with a stuck-on one whose valve is still open once the
        set operates (a valve stuck open vents from the set's first step on: before it, in the
        mission's attitude determination, the set does not step, and its torque would spin up a body
        whose thrusters nothing watches or draws propellant for)."""
        on = self.commanded(flags, axial) if commanded is None else commanded
        stuck = self.stuck
        if stuck is None:
            return on
        if self.stuck_on:
            if stuck in on or stuck in self.disabled or self.operating_time <= 0.0:
                return on
            return sorted(on + [stuck])
        return [i for i in on if i != stuck]

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

    def axial_on(self, flags, axial=False):
        """Indices of the axial thrusters firing: in the burn (`axial`) those not switched off for
        the flags, else none."""
        if not axial:
            return []
        off = self.axial_off(flags, axial)
        return [i for i in self.axial if i not in off]

    def force_and_torque(self, flags, axial=False):
        """(net force of the RCS thrusters firing for `flags` (N, B), torque (N.m, B)), the torque
        with the axial thrusters' left on when `axial` (the burn: their force is the propulsion's;
        their torque, zero when aligned and all on, is a disturbance here)."""
        _, firing, axial_on, _ = self._plan(flags, axial)
        fx = fy = fz = tx = ty = tz = 0.0
        for i in firing:
            f, t = self.forces[i], self.torques[i]
            fx, fy, fz = fx + f[0], fy + f[1], fz + f[2]
            tx, ty, tz = tx + t[0], ty + t[1], tz + t[2]
        ax = ay = az = 0.0
        for i in axial_on:
            t, f = self.torques[i], self.forces[i]
            tx, ty, tz = tx + t[0], ty + t[1], tz + t[2]
            ax, ay, az = ax + f[0], ay + f[1], az + f[2]
        if self.tank is not None:  # about the centre of mass: less r_cm x (the net force of all firing)
            c = self.center_of_mass
            nx, ny, nz = fx + ax, fy + ay, fz + az
            tx, ty, tz = tx - (c[1] * nz - c[2] * ny), ty - (c[2] * nx - c[0] * nz), tz - (c[0] * ny - c[1] * nx)
        return (fx, fy, fz), (tx, ty, tz)

    def step(self, flags, h, axial=False):
        """Advance h seconds with `flags` (and `axial`, the burn) held: firing times, the minimum
        on-time, the axial thrusters' off time and the operating time."""
        commanded, firing, axial_on, axial_off = self._plan(flags, axial)
        for i in commanded:
            started = self.on_left[i] <= 0.0
            left = max(0.0, (self.min_on_time if started else self.on_left[i]) - h)
            if left != self.on_left[i]:
                self.on_left[i] = left
                self._plan_version += 1  # a minimum on-time owed, or paid
        fx = fy = fz = 0.0
        if firing:
            self._firings += 1
        for i in firing:
            self.fire_time[i] += h
            f = self.forces[i]
            fx, fy, fz = fx + f[0], fy + f[1], fz + f[2]
        for i in axial_on:
            f = self.deviations[i]
            fx, fy, fz = fx + f[0], fy + f[1], fz + f[2]
        p = self.impulse
        self.impulse = (p[0] + fx * h, p[1] + fy * h, p[2] + fz * h)
        self.axial_off_time += h * len(axial_off)
        self.operating_time += h
        if self.stuck_thruster is not None:
            self._plan_version += 1  # the fault's clock decides what fires
        if firing:
            self._move_center_of_mass()

    def propellant_mass(self):
        """Propellant spent by the RCS so far (kg), Eq. 74 thruster by thruster."""
        # read at every step (the propulsion's and the body's mass): summed again only after a firing
        if self._propellant_at[0] != self._firings:
            impulse = sum(map(operator.mul, self.force_norms, self.fire_time))  # in order, as a generator would
            self._propellant_at = (self._firings, impulse / (self.isp * self.g0))
        return self._propellant_at[1]

    def get_state(self):
        return {"fire_time": list(self.fire_time), "on_left": list(self.on_left), "axial_off_time": self.axial_off_time,
                "operating_time": self.operating_time, "disabled": sorted(self.disabled), "fault_time": self.fault_time,
                "monitor": None if self.monitor is None else self.monitor.get_state(), "impulse": list(self.impulse),
                "main_drawn": self.main_drawn, "com_drawn": self._com_drawn,
                "center_of_mass": list(self.center_of_mass)}

    def set_state(self, state):
        self.fire_time = list(state["fire_time"])
        self._firings += 1
        self.on_left = list(state["on_left"])
        self._plan_version += 1
        self.axial_off_time = float(state["axial_off_time"])
        self.operating_time = float(state["operating_time"])
        self.disabled, self._allocation, self._burn_allocation = set(), None, None
        for i in state["disabled"]:
            self.disable(int(i))
        self.fault_time = float(state["fault_time"])
        if self.monitor is not None and state["monitor"] is not None:
            self.monitor.set_state(state["monitor"])
        self.impulse = tuple(state.get("impulse", (0.0, 0.0, 0.0)))  # states saved before it carry none
        self.main_drawn = float(state.get("main_drawn", 0.0))
        self._com_drawn = float(state.get("com_drawn", 0.0))
        self.center_of_mass = tuple(state.get("center_of_mass", (0.0, 0.0, 0.0)))

"""Sun-avoidance slew (SAS) guidance: a rest-to-rest eigenaxis slew, split into three eigenaxis
segments when the direct one would sweep a body-fixed boresight through the Sun keep-out cone.

Conventions (docs/conventions.md, components/core/rotations.py): q = q_BN scalar last, A(q) maps N to B,
q_total = q_second (x) q_first, so A(q_second (x) q_first) = A(q_second) A(q_first).

Inputs of the plan
------------------
P (boresight, unit, in B), S (Sun direction, unit, in N), keep-out half-angle epsilon in
(0, pi/2), margin m >= 0 (epsilon + m < pi/2), initial and final attitudes q0, q_f, rate and
acceleration limits w_max, a_max > 0. Boresight in N: P_N(q) = A(q)^T P, so
P_i = A(q0)^T P and P_f = A(q_f)^T P. Both must lie outside the keep-out cone
(angle(P_i, S) > epsilon, angle(P_f, S) > epsilon), else no path exists (ValueError).

1. Eigenaxis rotation and what the boresight sweeps
---------------------------------------------------
q_err = q_f (x) q0^-1 (sign chosen with q4 >= 0, the short way) = [e_B sin(phi/2), cos(phi/2)]:
A(q_f) = A(q_err) A(q0). The axis e_B has the same components in every body frame along the
rotation, and the rotation is a physical rotation of the body by phi about the inertial axis
e_N = A(q0)^T e_B. Along the slew, q(theta) = q(e_B, theta) (x) q0, and

    omega_BN_B = theta_dot e_B,    omega_dot_BN_B = theta_ddot e_B        (eigenaxis: e fixed)

so the boresight in N is P_i rotated about e_N by theta (Rodrigues):

    P_N(theta) = (P_i.e) e + cos(theta) P_perp + sin(theta) (e x P_perp),  P_perp = P_i - (P_i.e) e

i.e. it sweeps an arc of the circle (cone) of half-angle acos(P_i.e) about e_N, not a great
circle in general (only when e is perpendicular to P, e.g. the SAS pseudocode's e = P_i x P_f / |..|).
The cosine of the boresight-to-Sun angle gamma along the arc is

    cos gamma(theta) = c0 + a cos(theta) + b sin(theta) = c0 + r cos(theta - theta*)
    c0 = (P_i.e)(S.e),  a = P_perp.S,  b = (e x P_perp).S,  r = sqrt(a^2 + b^2),  theta* = atan2(b, a)

so the smallest angle over theta in [0, phi] is acos(c0 + r) if theta* (taken in [0, 2 pi))
lies in the swept arc, else the smaller of the two end angles (function `min_sun_angle`). The
path intrudes when that minimum is below epsilon. For a great-circle rotation (e.P = 0, c0 = 0)
the interior minimum is pi/2 - acos|S.e| = |alpha|: the SAS pseudocode's test |alpha| < epsilon with
alpha = pi/2 - acos(S.e), valid when the Sun's projection S_par lies on the swept arc.

2. Three-segment path when the direct slew intrudes
---------------------------------------------------
Let eps_D = epsilon + m (waypoint cone, on which the path rides), theta_i = angle(P_i, S),
theta_f = angle(P_f, S).

* Segment 1: rotate the boresight in the plane of P_i and S, toward S, onto the eps_D cone:
  axis e1_N = (P_i x S)/|P_i x S|, angle phi1 = theta_i - eps_D (pseudocode step 1(b): acos(P_i.S_par) -
  eps_D with the plane through S itself). A rotation about e1_N by +phi1 moves P_i toward S
  along the great circle, so the Sun angle falls monotonically from theta_i to eps_D and never
  below. q1 = q(A(q0) e1_N, phi1) (x) q0. (If P_i is inside the margin, phi1 < 0: the boresight
  is moved out onto the eps_D cone, the angle rises from theta_i > epsilon to eps_D.)
* Segment 3 is built backwards from the full final attitude: the last segment moves the
  boresight from P_2, the point of the eps_D cone nearest P_f (in the plane of S and P_f), away
  from S to P_f: axis e3_N = (S x P_f)/|S x P_f|, angle phi3 = theta_f - eps_D; the Sun angle
  rises monotonically from eps_D to theta_f. Its start attitude carries the final attitude's
  roll back along that rotation: q2 = q(A(q_f) e3_N, -phi3) (x) q_f, so segment 3 ends exactly
  at q_f (full attitude, roll about the boresight included).
* Segment 2 is the eigenaxis rotation q1 -> q2 (q_err2 = q2 (x) q1^-1). It carries the
  boresight from P_1 to P_2 (both on the eps_D cone) and does whatever roll about the boresight
  is left. Its boresight arc lies on a circle through P_1 and P_2 (about the axis e2_N, which
  lies in the plane bisecting P_1 and P_2, as S does). Two distinct circles on the sphere meet in
  at most two points, so this circle crosses the eps_D cone boundary only at P_1 and P_2, and
  of its two arcs from P_1 to P_2 one lies entirely outside the cone and the other entirely
  inside (crossings at two distinct points are transversal). The short rotation (q_err2, angle
  phi2 <= pi) and the long one (-q_err2: axis -e2, angle 2 pi - phi2) reach the same attitude
  along the two arcs; the plan takes the short one if its minimum Sun angle (section 1) is at
  least eps_D, else the long one. When no roll is left the axis is +-S and the boresight rides
  exactly along the cone (pseudocode step 1(c): rotation about the Sun axis). So every point of every
  segment stays at or outside eps_D or between the segment's end angles, all > epsilon.

Segments of zero angle (e.g. P_i already on the eps_D cone) are dropped. If P_i or P_f lies
between epsilon and eps_D, that segment moves the boresight out to (or in from) the eps_D cone,
and its angle stays between the two.

Candidates. Plan (A) above ("cone-eigenaxis") is always safe but its segment 2 can be long
(when the circle through P_1 and P_2 is the direct path's great circle, the safe arc goes the
other way round). Two more candidates follow the SAS pseudocode more literally: segment 2 a rotation about
the Sun axis along the eps_D cone from P_1 to P_2 (either way round; the boresight stays exactly
on the cone), segment 3 the eigenaxis rotation from there to q_f (boresight motion and the
remaining roll together; "sun-axis", "sun-axis-other-way"). Their segment 3 has no guarantee,
so every candidate is checked segment by segment with the exact swept-arc test, a candidate
counts only if its whole path stays at or outside min(eps_D, theta_i, theta_f), and the plan
takes the shortest-duration candidate that does. The SAS pseudocode's phi2 = 2 asin(sin eps / sin theta)
(the angle about the Sun axis) and phi3 = acos(P_f.P_2) are the boresight-only versions of
these segments; they alone do not reach the full final attitude.
If the direct slew does not intrude, the plan is the single eigenaxis rotation q_err.

3. Bang-coast-bang profile per segment (rest to rest, analytic)
---------------------------------------------------------------
phi_tt = w_max^2 / a_max. If phi > phi_tt: t1 = w_max / a_max, t2 = t1 + (phi - phi_tt) / w_max,
tf = t2 + t1; else (triangle) t1 = t2 = sqrt(phi / a_max), tf = 2 t1. With the peak rate
w_p = a_max t1:  theta = a t^2/2 (t < t1);  a t1^2/2 + w_p (t - t1) (t1 <= t < t2);
phi - a (tf - t)^2 / 2 (t2 <= t < tf); phi after tf. Segments follow one another (each from rest
to rest); the plan starts at t_start and lasts the sum of the segment durations.

4. From and to a moving state (seed step 2b)
--------------------------------------------
The slew may start while the detumble's residual rate remains and hand over to tracking at its
rate: the first segment starts at the rate phi_dot_0 and the last ends at phi_dot_f, both along
the segment's axis and in [0, w_max] (the segments between meet at rest: the axis changes there).
With the coast (phi at least the angles of speeding up from phi_dot_0 to w_max and slowing down
to phi_dot_f), the seed's times:
    t1 = (w_max - phi_dot_0) / a_max,
    t2 = t1 + [phi - phi_dot_0 t1 - a_max t1^2 / 2 - w_max (w_max - phi_dot_f) / a_max
               + (w_max - phi_dot_f)^2 / (2 a_max)] / w_max,
    tf = t1 + [phi - phi_dot_0 t1 - a_max t1^2 / 2 + (w_max - phi_dot_f)^2 / (2 a_max)] / w_max;
without it the peak rate is w_p = sqrt(a_max phi + (phi_dot_0^2 + phi_dot_f^2) / 2), t1 = t2 =
(w_p - phi_dot_0) / a_max, tf = t1 + (w_p - phi_dot_f) / a_max; a segment too short to change
from one rate to the other (|phi_dot_0^2 - phi_dot_f^2| / (2 a_max) > phi) is refused. The angle
stays monotone in [0, phi] within the segment, so the keep-out test of section 1 holds as
before; after the end the reference goes on turning at phi_dot_f about the last axis (the
follower's business). phi_dot_0 = phi_dot_f = 0 is the rest-to-rest profile of section 3.

Reference outputs at time t: q_ref = q(e_B,k, theta_k(t)) (x) q_start,k, omega_ref = theta_dot e_B,k,
omega_dot_ref = theta_ddot e_B,k, feed-forward torque (Euler's equation)
torque_ff = J omega_dot_ref + omega_ref x J omega_ref.
"""
import math

from ..core import rotations
from ..core.checks import positive

TWO_PI = 2.0 * math.pi


def _unit(v, what):
    v = tuple(float(x) for x in v)
    if len(v) != 3 or not all(math.isfinite(x) for x in v):
        raise ValueError(f"{what} {list(v)} must be three finite numbers")
    n = rotations.norm(v)
    if n < 1e-12:
        raise ValueError(f"{what} {list(v)} has zero length; give a non-zero direction")
    return tuple(x / n for x in v)


def _quat(q, what):
    q = tuple(float(x) for x in q)
    if len(q) != 4 or not all(math.isfinite(x) for x in q):
        raise ValueError(f"{what} {list(q)} must be four finite numbers")
    return rotations.normalized(q, what)


def check_start(q0, q_actual, tolerance):
    """Refuse a plan whose start attitude q0 is not the spacecraft's attitude q_actual at the
    start (both scalar last; within `tolerance` rad of rotation): the reference would jump.
    An all-zero q_actual means there is nothing to compare with (the input is not connected)."""
    if not all(math.isfinite(x) for x in q_actual):
        raise ValueError(f"the attitude at the start {list(q_actual)} must be finite")
    if all(x == 0.0 for x in q_actual):
        return
    _, angle = eigenaxis(_quat(q_actual, "attitude at the start"), _quat(q0, "q0"))
    if angle > tolerance:
        raise ValueError(f"q0 {list(q0)} is {math.degrees(angle):.4g} deg away from the attitude at the start "
                         f"q_BN {list(q_actual)} (tolerance {math.degrees(tolerance):.3g} deg): the guidance must "
                         "start from the dynamics' initial attitude (set both to the same q0)")


def angle_between(u, v):
    """Angle (rad) between unit vectors, accurate near 0 and pi (atan2 of |u x v| and u.v)."""
    return math.atan2(rotations.norm(rotations.cross(u, v)), rotations.dot(u, v))


def mat_vec(M, v):
    return tuple(M[i][0] * v[0] + M[i][1] * v[1] + M[i][2] * v[2] for i in range(3))


def mat_t_vec(M, v):
    return tuple(M[0][i] * v[0] + M[1][i] * v[1] + M[2][i] * v[2] for i in range(3))


def rotate(v, e, theta):
    """Active rotation of v about unit axis e by theta (Rodrigues)."""
    c, s = math.cos(theta), math.sin(theta)
    ev = rotations.dot(e, v)
    exv = rotations.cross(e, v)
    return tuple(c * v[i] + s * exv[i] + (1 - c) * ev * e[i] for i in range(3))


def boresight_N(q, P):
    """Boresight direction in N for attitude q: A(q)^T P."""
    return mat_t_vec(rotations.attitude_matrix(q), P)


def perpendicular(v):
    """A unit vector perpendicular to unit v."""
    a = (1.0, 0.0, 0.0) if abs(v[0]) < 0.9 else (0.0, 1.0, 0.0)
    return _unit(rotations.cross(v, a), "perpendicular")


def min_sun_angle(P_start, e, phi, S):
    """Smallest angle between S and the boresight P_start (N) rotated about unit e (N) through
    theta in [0, phi], phi >= 0 (section 1 of the module docstring). Returns (angle, theta)."""
    pe = rotations.dot(P_start, e)
    perp = tuple(P_start[i] - pe * e[i] for i in range(3))
    a = rotations.dot(perp, S)
    b = rotations.dot(rotations.cross(e, perp), S)
    candidates = [0.0, phi]
    r = math.hypot(a, b)
    if r > 1e-15:
        t_star = math.atan2(b, a) % TWO_PI
        if t_star <= phi:
            candidates.append(t_star)
    best = None
    for th in candidates:
        ang = angle_between(rotate(P_start, e, th), S)
        if best is None or ang < best[0]:
            best = (ang, th)
    return best


def _cone_segment(q, a, b, boresight, phi):
    """Axis in B (at attitude q) and angle >= 0 of a rotation by phi about a x b (in N; about
    any axis perpendicular to the boresight when a and b are parallel), for the segments
    between a boresight direction and the keep-out cone."""
    c = rotations.cross(a, b)
    e_N = _unit(c, "axis") if rotations.norm(c) > 1e-9 else perpendicular(boresight)
    e_B = mat_vec(rotations.attitude_matrix(q), e_N)
    if phi < 0:
        e_B, phi = tuple(-x for x in e_B), -phi
    return e_B, phi


def eigenaxis(q_from, q_to):
    """Short-way eigenaxis rotation from q_from to q_to: (axis in B, angle in [0, pi]) with
    q_to = q(axis, angle) (x) q_from (up to sign). Axis (1, 0, 0) for a zero angle."""
    dq = rotations.circle_cross(q_to, rotations.conjugate(q_from))
    if dq[3] < 0:
        dq = tuple(-x for x in dq)
    v = dq[:3]
    s = rotations.norm(v)
    angle = 2.0 * math.atan2(s, dq[3])
    axis = tuple(x / s for x in v) if s > 1e-15 else (1.0, 0.0, 0.0)
    return axis, angle


class BangCoastBang:
    """Angle profile limited by w_max and a_max (section 3 of the docstring): rest to rest, or
    from the start rate w0 to the end rate wf (0 <= w0, wf <= w_max; section 4)."""

    def __init__(self, phi, w_max, a_max, w0=0.0, wf=0.0):
        if not (math.isfinite(phi) and phi >= 0):
            raise ValueError(f"segment angle {phi!r} must be finite and >= 0")
        self.phi, self.a = float(phi), float(a_max)
        self.w0, self.wf = float(w0), float(wf)
        for name, w in (("start rate phi_dot_0", self.w0), ("end rate phi_dot_f", self.wf)):
            if not (math.isfinite(w) and 0.0 <= w <= w_max):
                raise ValueError(f"{name} = {w!r} rad/s must lie in [0, w_max = {w_max!r}] (along the slew)")
        self.phi_tt = w_max * w_max / a_max
        self.rest_to_rest = self.w0 == 0.0 and self.wf == 0.0
        if self.rest_to_rest:
            if self.phi > self.phi_tt:
                self.triangle = False
                self.t1 = w_max / a_max
                self.t2 = self.t1 + (self.phi - self.phi_tt) / w_max
                self.tf = self.t2 + self.t1
            else:
                self.triangle = True
                self.t1 = self.t2 = math.sqrt(self.phi / a_max)
                self.tf = 2.0 * self.t1
            self.w_peak = a_max * self.t1
            return
        w0, wf, a = self.w0, self.wf, self.a
        # the angles of speeding up from w0 to w_max and slowing down from w_max to wf
        up, down = (w_max - w0) / a, (w_max - wf) / a
        ramps = w0 * up + 0.5 * a * up * up + w_max * down - 0.5 * a * down * down
        if self.phi >= ramps:
            self.triangle = False  # a coast at w_max (the seed's step 2b timing)
            self.t1 = up
            self.t2 = self.t1 + (self.phi - ramps) / w_max
            self.tf = self.t2 + down
            self.w_peak = w_max
        else:
            # no coast: the peak rate that covers phi, (w_p^2 - w0^2 + w_p^2 - wf^2) / (2 a) = phi
            self.triangle = True
            self.w_peak = math.sqrt(a * self.phi + 0.5 * (w0 * w0 + wf * wf))
            if self.w_peak < max(w0, wf) * (1.0 - 1e-12):
                raise ValueError(f"a {self.phi!r} rad segment is too short to go from {w0!r} to {wf!r} rad/s at "
                                 f"{a!r} rad/s2 (needs {abs(w0 * w0 - wf * wf) / (2.0 * a)!r} rad)")
            self.w_peak = max(self.w_peak, w0, wf)
            self.t1 = self.t2 = (self.w_peak - w0) / a
            self.tf = self.t1 + (self.w_peak - wf) / a
        self.angle_t1 = w0 * self.t1 + 0.5 * a * self.t1 * self.t1

    def evaluate(self, t):
        """(angle, rate, acceleration) at time t from the segment start; after the end the angle
        goes on at the end rate (rest to rest: stays at phi)."""
        a = self.a
        if not self.rest_to_rest:
            if t <= 0.0:
                return 0.0, self.w0, 0.0
            if t < self.t1:
                return self.w0 * t + 0.5 * a * t * t, self.w0 + a * t, a
            if t < self.t2:
                return self.angle_t1 + self.w_peak * (t - self.t1), self.w_peak, 0.0
            if t < self.tf:
                r = self.tf - t
                return self.phi - self.wf * r - 0.5 * a * r * r, self.wf + a * r, -a
            return self.phi + self.wf * (t - self.tf), self.wf, 0.0
        if t <= 0.0:
            return 0.0, 0.0, 0.0
        if t < self.t1:
            return 0.5 * a * t * t, a * t, a
        if t < self.t2:
            return 0.5 * a * self.t1 * self.t1 + self.w_peak * (t - self.t1), self.w_peak, 0.0
        if t < self.tf:
            r = self.tf - t
            return self.phi - 0.5 * a * r * r, a * r, -a
        return self.phi, 0.0, 0.0


class Segment:
    def __init__(self, q_start, axis_B, angle, w_max, a_max, t_begin, w0=0.0, wf=0.0):
        self.q_start = tuple(q_start)
        self.axis_B = tuple(axis_B)
        self.angle = float(angle)
        self.profile = BangCoastBang(angle, w_max, a_max, w0, wf)
        self.t_begin = float(t_begin)
        self.t_end = self.t_begin + self.profile.tf
        self.q_end = self.attitude(self.angle)

    def attitude(self, theta):
        return rotations.circle_cross(rotations.from_axis_angle(self.axis_B, theta), self.q_start)


class SunAvoidanceGuidance:
    """Plans the slew at construction; `reference(t)` evaluates it analytically at time t.

    `time` (the communication point the FMU reached) is the only state."""

    def __init__(self, boresight_B, sun_N, epsilon, q0, q_f, w_max, a_max,
                 inertia=((0.05, 0, 0), (0, 0.13, 0), (0, 0, 0.1)),
                 margin=math.radians(5.0), t_start=0.0, phi_dot_0=0.0, phi_dot_f=0.0):
        self.P = _unit(boresight_B, "boresight_B")
        self.S = _unit(sun_N, "sun_N")
        epsilon = float(epsilon)
        if not (math.isfinite(epsilon) and 0.0 < epsilon < math.pi / 2):
            raise ValueError(f"epsilon = {epsilon!r} rad must lie in (0, pi/2)")
        margin = float(margin)
        if not (math.isfinite(margin) and margin >= 0.0 and epsilon + margin < math.pi / 2):
            raise ValueError(f"margin = {margin!r} rad must be >= 0 with epsilon + margin < pi/2 "
                             f"(epsilon = {epsilon!r})")
        self.epsilon, self.margin = epsilon, margin
        self.q0 = _quat(q0, "q0")
        self.q_f = _quat(q_f, "q_f")
        self.w_max = positive("w_max", w_max, "rad/s")
        self.a_max = positive("a_max", a_max, "rad/s2")
        t_start = float(t_start)
        if not math.isfinite(t_start):
            raise ValueError(f"t_start = {t_start!r} s must be finite")
        self.t_start = t_start
        self.phi_dot_0, self.phi_dot_f = float(phi_dot_0), float(phi_dot_f)
        J = [[float(x) for x in row] for row in inertia]
        if len(J) != 3 or any(len(r) != 3 for r in J) or not all(math.isfinite(x) for r in J for x in r):
            raise ValueError(f"inertia {J} must be a finite 3x3 matrix (kg.m2)")
        self.J = tuple(tuple(r) for r in J)

        self.P_i = boresight_N(self.q0, self.P)
        self.P_f = boresight_N(self.q_f, self.P)
        self.theta_i = angle_between(self.P_i, self.S)
        self.theta_f = angle_between(self.P_f, self.S)
        for name, th in (("initial (q0)", self.theta_i), ("final (q_f)", self.theta_f)):
            if th <= epsilon:
                raise ValueError(f"the {name} boresight is {math.degrees(th):.4g} deg from the Sun, inside the "
                                 f"keep-out cone epsilon = {math.degrees(epsilon):.4g} deg: no Sun-avoiding slew "
                                 "exists")
        self._plan()
        self.time = float(t_start)

    # ---- planning ---------------------------------------------------------------------
    def _plan(self):
        axis_B, phi = eigenaxis(self.q0, self.q_f)
        e_N = mat_t_vec(rotations.attitude_matrix(self.q0), axis_B)
        self.direct_min_angle = min_sun_angle(self.P_i, e_N, phi, self.S)[0] if phi > 0 else self.theta_i
        self.intrudes = self.direct_min_angle < self.epsilon
        if not self.intrudes:
            plans = [("direct", self._build([(axis_B, phi)]))]
            floor = self.epsilon
        else:
            plans = [(name, self._build(turns)) for name, turns in self._three_segment_candidates()]
            # Segments 1 and 3 start/end at the boresight's own angle when that lies within the margin.
            floor = min(self.epsilon + self.margin, self.theta_i, self.theta_f)
        # Keep the candidates whose every segment stays outside the cone (exact swept-arc test),
        # then take the fastest. Candidate "cone-eigenaxis" always qualifies (docstring, section 2).
        safe = [(plan["duration"], name, plan) for name, plan in plans if plan["min_angle"] >= floor - 1e-9]
        if not safe:
            raise RuntimeError("no candidate path stays outside the keep-out cone: planner bug")
        _, self.path_kind, plan = min(safe, key=lambda x: x[0])
        self.candidates = {name: (plan_["duration"], plan_["min_angle"]) for name, plan_ in plans}
        self.segments = plan["segments"]
        self.min_angle = plan["min_angle"]
        self.t_end = self.segments[-1].t_end if self.segments else self.t_start
        self.duration = self.t_end - self.t_start
        self.q_end = self.segments[-1].q_end if self.segments else self.q0

    def _build(self, turns):
        segments, angles = [], []
        q, t = self.q0, self.t_start
        turns = [(axis, angle) for axis, angle in turns if angle > 1e-12]
        if not turns and (self.phi_dot_0 or self.phi_dot_f):
            raise ValueError("q0 and q_f are the same attitude: no slew to start at phi_dot_0 or end at phi_dot_f")
        for k, (axis, angle) in enumerate(turns):
            # the first segment starts at phi_dot_0, the last ends at phi_dot_f; the axis changes
            # between segments, so they meet at rest
            seg = Segment(q, axis, angle, self.w_max, self.a_max, t, self.phi_dot_0 if k == 0 else 0.0,
                          self.phi_dot_f if k == len(turns) - 1 else 0.0)
            segments.append(seg)
            q, t = seg.q_end, seg.t_end
            pN = boresight_N(seg.q_start, self.P)
            eN = mat_t_vec(rotations.attitude_matrix(seg.q_start), seg.axis_B)
            angles.append(min_sun_angle(pN, eN, seg.angle, self.S)[0])
        return {"segments": segments, "angles": angles, "duration": t - self.t_start,
                "min_angle": min(angles) if angles else self.theta_i}

    def _three_segment_candidates(self):
        S, P_i, P_f = self.S, self.P_i, self.P_f
        eps_d = self.epsilon + self.margin
        # Segment 1: in the plane of P_i and S, toward S, onto the eps_d cone.
        e1_B, phi1 = _cone_segment(self.q0, P_i, S, P_i, self.theta_i - eps_d)
        q1 = rotations.circle_cross(rotations.from_axis_angle(e1_B, phi1), self.q0)
        P1 = boresight_N(q1, self.P)
        # Segment 3 (built backwards from q_f): from the eps_d cone, away from S, to P_f.
        e3_B, phi3 = _cone_segment(self.q_f, S, P_f, P_f, self.theta_f - eps_d)
        q2 = rotations.circle_cross(rotations.from_axis_angle(e3_B, -phi3), self.q_f)
        P2 = boresight_N(q2, self.P)
        candidates = []
        # (A) Segment 2 = eigenaxis q1 -> q2, the way (short or long) whose arc stays outside eps_d.
        e2_B, phi2 = eigenaxis(q1, q2)
        e2_N = mat_t_vec(rotations.attitude_matrix(q1), e2_B)
        short = min_sun_angle(P1, e2_N, phi2, S)[0] if phi2 > 0 else eps_d
        if short < eps_d - 1e-9:
            long_ = min_sun_angle(P1, tuple(-x for x in e2_N), TWO_PI - phi2, S)[0]
            if long_ > short:
                e2_B, phi2 = tuple(-x for x in e2_B), TWO_PI - phi2
        candidates.append(("cone-eigenaxis", [(e1_B, phi1), (e2_B, phi2), (e3_B, phi3)]))
        # (B) Segment 2 = rotation about the Sun axis along the eps_d cone from P_1 to P_2 (either
        # way round); segment 3 = eigenaxis from there to q_f (boresight and roll together).
        # Accepted only if segment 3's arc also stays outside eps_d.
        a1 = tuple(P1[i] - rotations.dot(P1, S) * S[i] for i in range(3))
        a2 = tuple(P2[i] - rotations.dot(P2, S) * S[i] for i in range(3))
        psi = math.atan2(rotations.dot(rotations.cross(a1, a2), S), rotations.dot(a1, a2))
        S_B = mat_vec(rotations.attitude_matrix(q1), S)
        for name, ang in (("sun-axis", psi), ("sun-axis-other-way", psi - math.copysign(TWO_PI, psi))):
            axis = S_B if ang >= 0 else tuple(-x for x in S_B)
            q2b = rotations.circle_cross(rotations.from_axis_angle(axis, abs(ang)), q1)
            e3b, phi3b = eigenaxis(q2b, self.q_f)
            candidates.append((name, [(e1_B, phi1), (axis, abs(ang)), (e3b, phi3b)]))
        return candidates

    # ---- evaluation -------------------------------------------------------------------
    def reference(self, t=None):
        """Reference at time t (default: self.time): dict with q, omega, omega_dot (B), torque_ff,
        segment (1-based; 0 before t_start or with no motion), sun_angle, done."""
        if t is None:
            t = self.time
        segs = self.segments
        if not segs:
            q, theta_dot, theta_ddot, axis, k = self.q0, 0.0, 0.0, (0.0, 0.0, 0.0), 0
        elif t < self.t_start:
            q, theta_dot, theta_ddot, axis, k = self.q0, 0.0, 0.0, segs[0].axis_B, 0
        else:
            k = len(segs)
            for i, seg in enumerate(segs):
                if t < seg.t_end:
                    k = i + 1
                    break
            seg = segs[k - 1]
            theta, theta_dot, theta_ddot = seg.profile.evaluate(t - seg.t_begin)
            q, axis = seg.attitude(theta), seg.axis_B
        w = (theta_dot * axis[0], theta_dot * axis[1], theta_dot * axis[2])
        wd = (theta_ddot * axis[0], theta_ddot * axis[1], theta_ddot * axis[2])
        J = self.J
        Jw = mat_vec(J, w)
        Jwd = mat_vec(J, wd)
        g = rotations.cross(w, Jw)
        torque = (Jwd[0] + g[0], Jwd[1] + g[1], Jwd[2] + g[2])
        return {"q": q, "omega": w, "omega_dot": wd, "torque_ff": torque, "segment": k,
                "sun_angle": angle_between(boresight_N(q, self.P), self.S), "done": t >= self.t_end}

    def step(self, t_new):
        """Advance the reference time to the communication point t_new."""
        if not math.isfinite(t_new):
            raise ValueError(f"time {t_new!r} must be finite")
        self.time = float(t_new)

    def get_state(self):
        return {"time": self.time}

    def set_state(self, state):
        self.time = float(state["time"])

"""Mass properties that follow the propellant drawn from the tank (issue 28, item 4).

The thesis sizes the spacecraft as one uniform box of 12 kg (Eq. 4) and keeps it so through the
burn, while 0.56-1.7 kg of propellant (5-14 % of the mass) leaves the tank. Here the propellant
drawn is taken out as a point mass at the tank's centre: the NEIGHBOR module is the cube of side a
at the host's -x end (components.attitude.thruster_set: its far face at x = -c/2), and the
spherical tank (4.48 cm inner radius, Appendix H) sits at the module's centre,

    p_tank = (-c/2 + a/2, 0, 0)     (-0.1 m for the thesis' a = 0.1 m, c = 0.3 m)

in the host's body frame, whose origin is the host's geometric centre (the centre of mass at
takeover). With dm drawn from the body of mass m0 and inertia J0 about that origin:

    m = m0 - dm,   r_cm = -dm p_tank / m                          (the centre of mass moves to +x)
    J_o = J0 - dm (|p|^2 I - p p^T)                               (about the origin)
    J = J_o - m (|r_cm|^2 I - r_cm r_cm^T)                        (parallel axes, about r_cm)

For the 420 km burn (0.56 kg) the centre of mass moves 4.9 mm and the y and z moments fall by
about 5 %. Only mass leaving the body enters: the propellant's own motion in the tank (slosh) and
the jet damping of the exhaust are not modelled, and the inertia is held over a step (its rate,
about 2.4e-6 kg m2/s in the burn, makes J_dot omega about 1e-6 of one pair's torque).

The body's true inertia may also differ from the one the flight software assumes (a host whose
mass is not spread as a uniform box): `with_moment_errors` scales the body's second moments of
mass along its axes, M_i = integral of x_i^2 dm, by 1 + e_i. With M = tr(J)/2 I - J (the matrix
of second moments, positive semi-definite for any body) and D = diag(sqrt(1 + e_i)):

    M' = D M D,   J' = tr(M') I - M'

so J' is the inertia of a real mass distribution for any e_i > -1 (the principal moments keep the
triangle inequality, which independent errors of the moments themselves would break: the
thesis' box, 0.05, 0.13 and 0.10 kg m2, is 0.02 from its edge). For the box, e_i of 10 % move
each moment by up to 10 %.
"""
import math

from ..core import checks

# The mass properties are recomputed once this much more propellant has been drawn (kg): 0.1 g moves
# the inertia by 1e-5 of itself and the centre of mass by 1 um, and spares the attitude loop a
# recomputation at every 15 ms step that fires (a thruster's pulse draws 0.9 mg).
RESOLUTION = 1e-4


def tank_position(a, c):
    """The tank's centre in B (m): the centre of the NEIGHBOR module, the cube of side a at the -x end
    of a host of length c along x."""
    checks.positive("edge a", a, "m")
    checks.positive("edge c", c, "m")
    return (-c / 2.0 + a / 2.0, 0.0, 0.0)


def drawn(inertia0, mass0, propellant, tank):
    """(inertia about the centre of mass (3x3 tuples, kg m2), centre of mass in B (m)) after
    `propellant` kg left a body of `mass0` kg and `inertia0` about the B origin from the point `tank`."""
    dm = float(propellant)
    if not (math.isfinite(dm) and 0.0 <= dm < mass0):
        raise ValueError(f"propellant drawn = {propellant!r} kg must be in [0, {mass0!r}) (the mass at takeover)")
    m = mass0 - dm
    p = tank
    c = tuple(-dm * x / m for x in p)
    pp, cc = p[0] * p[0] + p[1] * p[1] + p[2] * p[2], c[0] * c[0] + c[1] * c[1] + c[2] * c[2]
    J = tuple(tuple(inertia0[i][j] - dm * ((pp if i == j else 0.0) - p[i] * p[j])
                    - m * ((cc if i == j else 0.0) - c[i] * c[j]) for j in range(3)) for i in range(3))
    return J, c


def with_moment_errors(inertia, errors):
    """The inertia (3x3 tuples, kg m2) of a body whose second moments of mass along its axes are
    (1 + errors[i]) times those of a body of inertia `inertia` (module docstring); `inertia`
    itself, unchanged, when every error is 0."""
    e = checks.finite_vector(errors, 3, "inertia errors", "fractions in [-0.5, 0.5]")
    if not all(-0.5 <= x <= 0.5 for x in e):
        raise ValueError(f"inertia errors {list(e)} must be 3 fractions in [-0.5, 0.5]")
    J = tuple(tuple(float(x) for x in row) for row in inertia)
    if not any(e):
        return J
    half_trace = 0.5 * (J[0][0] + J[1][1] + J[2][2])
    d = tuple(math.sqrt(1.0 + x) for x in e)
    M = [[d[i] * ((half_trace if i == j else 0.0) - J[i][j]) * d[j] for j in range(3)] for i in range(3)]
    trace = M[0][0] + M[1][1] + M[2][2]
    return tuple(tuple((trace if i == j else 0.0) - M[i][j] for j in range(3)) for i in range(3))


def inverse(J):
    """The inverse of a 3x3 matrix by its adjugate, in plain floats (the rigid body keeps its
    inertia as tuples of floats; numpy's inverse would cost more than the arithmetic)."""
    (a, b, c), (d, e, f), (g, h, i) = J
    A, B, C = e * i - f * h, f * g - d * i, d * h - e * g
    det = a * A + b * B + c * C
    if not (math.isfinite(det) and det > 0.0):
        raise ValueError(f"inertia {[list(r) for r in J]} is not positive definite (determinant {det!r})")
    return ((A / det, (c * h - b * i) / det, (b * f - c * e) / det),
            (B / det, (a * i - c * g) / det, (c * d - a * f) / det),
            (C / det, (b * g - a * h) / det, (a * e - b * d) / det))

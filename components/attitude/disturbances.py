"""Environmental disturbance torques on a rigid spacecraft: gravity gradient, aerodynamic drag and
solar radiation pressure of a faceted body, and a residual magnetic dipole (torques in B, N.m;
forces in N, newtons).

Gravity gradient (Wertz, Spacecraft Attitude Determination and Control, Eq. 17-46; Basilisk
GravityGradientEffector), with r_B = A(q_BN) r_BN_N:

    L_gg = 3 mu / |r|^5 (r_B x J r_B)

Aerodynamic drag of flat facets (Basilisk facetDragDynamicEffector's plate model; Vallado
Eq. 8-28 per facet). The atmosphere co-rotates with the Earth, so the flow is
v_rel = v_BN_N - omega_E x r_BN_N (omega_E = 7.292115e-5 rad/s about N's z, as the orbit
FMUs). A facet with unit outward normal n_B, area A, drag coefficient Cd and centre of pressure
c_B (relative to the centre of mass) faces the flow when n . v_hat > 0 and then feels

    F = -1/2 rho |v_rel|^2 Cd A (n . v_hat) v_hat,   L = c x F.

Facets do not shadow each other (a convex body such as a box is exact).

Solar radiation pressure of the same facets (Basilisk facetSRPDynamicEffector; Montenbruck and
Gill, Satellite Orbits, Eq. 3.75), with s_hat the unit vector from the spacecraft to the Sun,
cos(theta) = n . s_hat > 0, specular and diffuse reflection coefficients cs, cd (absorbed
1 - cs - cd), P = solar_flux / c (1 AU / |r_SB|)^2 and the sunlit fraction nu of the Earth's
shadow (EarthShadow):

    F = -nu P A cos(theta) [(1 - cs) s_hat + 2 (cs cos(theta) + cd / 3) n],   L = c x F.

Residual magnetic dipole m_B (A.m2): L = m_B x B_B, B_B = A(q_BN) B_N.

Centres of pressure are given relative to the centre of mass at takeover; `com_B` (the rigid
body's center_of_mass_B as the tank empties) moves the centre of mass, and the arms are c - com_B.

Everything is computed in one compiled call (`evaluate`) that writes the 18 numbers of
OUTPUTS into an array.
"""
import math

import numpy as np

from ..core.constants import ASTRONOMICAL_UNIT, MU_EARTH, OMEGA_EARTH_WGS84, SOLAR_FLUX_1AU
from ..core.jit import njit

SPEED_OF_LIGHT = 299792458.0  # m/s (exact)
MAX_FACETS = 16

# what `evaluate` writes, in order (3 each)
OUTPUTS = ("gravity_gradient_torque_B", "aerodynamic_torque_B", "aerodynamic_force_N", "srp_torque_B",
           "srp_force_N", "magnetic_torque_B")
SOURCES = ("gravity_gradient", "aerodynamic", "solar_radiation", "residual_dipole")


@njit(cache=True)
def _attitude(q, A):
    """A(q) (scalar last, normalized first) into the 3x3 array A; False for a zero quaternion."""
    n = math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    if not (n > 0.0) or not math.isfinite(n):
        return False
    q1, q2, q3, q4 = q[0] / n, q[1] / n, q[2] / n, q[3] / n
    A[0, 0] = q1 * q1 - q2 * q2 - q3 * q3 + q4 * q4
    A[0, 1] = 2 * (q1 * q2 + q3 * q4)
    A[0, 2] = 2 * (q1 * q3 - q2 * q4)
    A[1, 0] = 2 * (q1 * q2 - q3 * q4)
    A[1, 1] = -q1 * q1 + q2 * q2 - q3 * q3 + q4 * q4
    A[1, 2] = 2 * (q2 * q3 + q1 * q4)
    A[2, 0] = 2 * (q1 * q3 + q2 * q4)
    A[2, 1] = 2 * (q2 * q3 - q1 * q4)
    A[2, 2] = -q1 * q1 - q2 * q2 + q3 * q3 + q4 * q4
    return True


# 3x3 products by hand: numba's `@` calls BLAS through scipy, which a user's machine (numpy only,
# the FMUs' one requirement) does not have, and then aborts the host process.
@njit(cache=True)
def _times(M, x):
    """M x for a 3x3 M."""
    return np.array([M[0, 0] * x[0] + M[0, 1] * x[1] + M[0, 2] * x[2],
                     M[1, 0] * x[0] + M[1, 1] * x[1] + M[1, 2] * x[2],
                     M[2, 0] * x[0] + M[2, 1] * x[1] + M[2, 2] * x[2]])


@njit(cache=True)
def _times_transposed(M, x):
    """M^T x for a 3x3 M."""
    return np.array([M[0, 0] * x[0] + M[1, 0] * x[1] + M[2, 0] * x[2],
                     M[0, 1] * x[0] + M[1, 1] * x[1] + M[2, 1] * x[2],
                     M[0, 2] * x[0] + M[1, 2] * x[1] + M[2, 2] * x[2]])


@njit(cache=True)
def _add_facet(out, at, force, centre, com, fi):
    """A facet's force fi into the sum `force` and its torque (centre - com) x fi into out[at:at+3]."""
    ax, ay, az = centre[0] - com[0], centre[1] - com[1], centre[2] - com[2]
    out[at] += ay * fi[2] - az * fi[1]
    out[at + 1] += az * fi[0] - ax * fi[2]
    out[at + 2] += ax * fi[1] - ay * fi[0]
    force += fi


@njit(cache=True)
def evaluate(r, v, q, density, r_sun, sunlit, b_N, com, J, mu, omega_earth, normals, areas, centres, cd,
             specular, diffuse, dipole, solar_flux, switches, out):
    """The disturbances (module docstring) into out[0:18] in the order of OUTPUTS. `switches`:
    four flags (SOURCES order); a source switched off writes zeros. Returns False (out unchanged)
    when q is zero or the position is zero."""
    A = np.empty((3, 3))
    rr = math.sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2])
    if not _attitude(q, A) or not (rr > 0.0):
        return False
    for k in range(18):
        out[k] = 0.0
    r_B = _times(A, r)
    if switches[0]:
        Jr = _times(J, r_B)
        k3 = 3.0 * mu / rr ** 5
        out[0] = k3 * (r_B[1] * Jr[2] - r_B[2] * Jr[1])
        out[1] = k3 * (r_B[2] * Jr[0] - r_B[0] * Jr[2])
        out[2] = k3 * (r_B[0] * Jr[1] - r_B[1] * Jr[0])
    n_facets = areas.shape[0]
    if switches[1] and density > 0.0:
        w = np.array([v[0] + omega_earth * r[1], v[1] - omega_earth * r[0], v[2]])  # v - omega_E x r
        vm = math.sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2])
        if vm > 0.0:
            vh = _times(A, w) / vm
            f = np.zeros(3)
            for i in range(n_facets):
                proj = normals[i, 0] * vh[0] + normals[i, 1] * vh[1] + normals[i, 2] * vh[2]
                if areas[i] * proj > 0.0:
                    fi = -0.5 * density * vm * vm * cd[i] * areas[i] * proj * vh
                    _add_facet(out, 3, f, centres[i], com, fi)
            f_N = _times_transposed(A, f)
            out[6], out[7], out[8] = f_N[0], f_N[1], f_N[2]
    if switches[2] and sunlit > 0.0:
        s_N = np.array([r_sun[0] - r[0], r_sun[1] - r[1], r_sun[2] - r[2]])
        d = math.sqrt(s_N[0] * s_N[0] + s_N[1] * s_N[1] + s_N[2] * s_N[2])
        if d > 0.0:
            sh = _times(A, s_N) / d
            au = ASTRONOMICAL_UNIT / d
            pressure = sunlit * solar_flux / SPEED_OF_LIGHT * au * au
            f = np.zeros(3)
            for i in range(n_facets):
                c = normals[i, 0] * sh[0] + normals[i, 1] * sh[1] + normals[i, 2] * sh[2]
                if areas[i] * c > 0.0:
                    fi = -pressure * areas[i] * c * ((1.0 - specular[i]) * sh
                                                     + 2.0 * (diffuse[i] / 3.0 + specular[i] * c) * normals[i])
                    _add_facet(out, 9, f, centres[i], com, fi)
            f_N = _times_transposed(A, f)
            out[12], out[13], out[14] = f_N[0], f_N[1], f_N[2]
    if switches[3]:
        b = _times(A, b_N)
        out[15] = dipole[1] * b[2] - dipole[2] * b[1]
        out[16] = dipole[2] * b[0] - dipole[0] * b[2]
        out[17] = dipole[0] * b[1] - dipole[1] * b[0]
    return True


@njit(cache=True)
def publish_into(values, inputs, outputs, J, mu, omega_earth, normals, areas, centres, cd, specular, diffuse, dipole,
                 solar_flux, switches):
    """`evaluate` on the inputs at values[inputs] (r 3, v 3, q 4, density, r_SN 3, sunlit fraction,
    B_N 3, centre of mass 3: the FMU's shared array), its outputs written to values[outputs]
    (torque sum 3, force sum 3, then the 18 numbers of OUTPUTS in the FMU's order: the four
    torques, the two forces). Returns 0, or 1 when an input is out of range (nothing written:
    the caller raises the error by name)."""
    x = np.empty(inputs.shape[0])
    for k in range(inputs.shape[0]):
        x[k] = values[inputs[k]]
        if not math.isfinite(x[k]):
            return 1
    if x[10] < 0.0 or not 0.0 <= x[14] <= 1.0:
        return 1
    out = np.empty(18)
    if not evaluate(x[0:3], x[3:6], x[6:10], x[10], x[11:14], x[14], x[15:18], x[18:21], J, mu, omega_earth, normals,
                    areas, centres, cd, specular, diffuse, dipole, solar_flux, switches, out):
        return 1
    for i in range(3):
        values[outputs[i]] = out[i] + out[3 + i] + out[9 + i] + out[15 + i]
        values[outputs[3 + i]] = out[6 + i] + out[12 + i]
        values[outputs[6 + i]] = out[i]  # gravity gradient
        values[outputs[9 + i]] = out[3 + i]  # aerodynamic torque
        values[outputs[12 + i]] = out[9 + i]  # SRP torque
        values[outputs[15 + i]] = out[15 + i]  # dipole torque
        values[outputs[18 + i]] = out[6 + i]  # aerodynamic force
        values[outputs[21 + i]] = out[12 + i]  # SRP force
    return 0


class Facets:
    """A faceted body: unit outward normals (n x 3, B), areas (m2), centres of pressure (n x 3, m,
    relative to the centre of mass at takeover), drag coefficients and the specular and diffuse
    reflection coefficients. ValueError naming the facet for a bad value; facets of zero area are
    dropped (the FMU's unused slots)."""

    def __init__(self, normals, areas, centres, cd, specular, diffuse):
        normals = np.asarray(normals, dtype=float).reshape(-1, 3)
        n = normals.shape[0]
        columns = [np.asarray(x, dtype=float).reshape(-1) for x in (areas, cd, specular, diffuse)]
        centres = np.asarray(centres, dtype=float).reshape(-1, 3)
        if centres.shape[0] != n or any(c.shape[0] != n for c in columns):
            raise ValueError(f"facets: {n} normals need {n} areas, centres, Cd, specular and diffuse coefficients")
        areas, cd, specular, diffuse = (c.tolist() for c in columns)
        keep = []
        for i in range(n):
            name = f"facet {i + 1}"
            if not (np.all(np.isfinite(normals[i])) and np.all(np.isfinite(centres[i]))
                    and all(math.isfinite(c[i]) for c in (areas, cd, specular, diffuse))):
                raise ValueError(f"{name}: every value must be finite")
            if areas[i] < 0.0:
                raise ValueError(f"{name}: area {areas[i]!r} m2 must be >= 0 (0: no facet)")
            if areas[i] == 0.0:
                continue
            norm = float(np.linalg.norm(normals[i]))
            if abs(norm - 1.0) > 1e-6:
                raise ValueError(f"{name}: normal {normals[i].tolist()} must be a unit vector (|n| = {norm:.6g})")
            if not 0.0 <= cd[i] <= 10.0:
                raise ValueError(f"{name}: Cd {cd[i]!r} must be in [0, 10]")
            if not (0.0 <= specular[i] <= 1.0 and 0.0 <= diffuse[i] <= 1.0 and specular[i] + diffuse[i] <= 1.0):
                raise ValueError(f"{name}: specular {specular[i]!r} and diffuse {diffuse[i]!r} must be in [0, 1] "
                                 "with a sum <= 1 (the rest is absorbed)")
            keep.append(i)
        k = np.array(keep, dtype=np.int64)
        self.normals = np.ascontiguousarray(normals[k] / np.linalg.norm(normals[k], axis=1)[:, None]
                                            if len(k) else normals[k])
        self.areas, self.centres = np.array(areas)[k], np.ascontiguousarray(centres[k])
        self.cd, self.specular, self.diffuse = np.array(cd)[k], np.array(specular)[k], np.array(diffuse)[k]

    def __len__(self):
        return len(self.areas)


class DisturbanceTorques:
    """The four disturbances of a rigid body with inertia J (3x3, kg.m2, about the centre of
    mass) and `facets`. `compute(...)` returns the 18 numbers of OUTPUTS as an array (also kept
    as `.last`)."""

    def __init__(self, J, facets, residual_dipole_B=(0.0, 0.0, 0.0), sources=SOURCES, mu=MU_EARTH,
                 solar_flux=SOLAR_FLUX_1AU, omega_earth=OMEGA_EARTH_WGS84):
        self.J = np.asarray(J, dtype=float).reshape(3, 3)
        if not np.all(np.isfinite(self.J)):
            raise ValueError("inertia must be finite")
        self.facets = facets
        self.dipole = np.asarray(residual_dipole_B, dtype=float).reshape(3)
        if not np.all(np.isfinite(self.dipole)):
            raise ValueError(f"residual_dipole_B {self.dipole.tolist()} must be finite")
        unknown = set(sources) - set(SOURCES)
        if unknown:
            raise ValueError(f"unknown disturbance {sorted(unknown)}; choose from {', '.join(SOURCES)}")
        self.switches = np.array([s in sources for s in SOURCES], dtype=np.bool_)
        for name, value in (("mu", mu), ("solar_flux", solar_flux)):
            if not (math.isfinite(value) and value > 0.0):
                raise ValueError(f"{name} = {value!r} must be > 0")
        self.mu, self.solar_flux, self.omega_earth = float(mu), float(solar_flux), float(omega_earth)
        self.last = np.zeros(18)

    def publish_into(self, values, inputs, outputs):
        """The compiled evaluation from and into the FMU's shared array (module publish_into)."""
        f = self.facets
        return publish_into(values, inputs, outputs, self.J, self.mu, self.omega_earth, f.normals, f.areas, f.centres,
                            f.cd, f.specular, f.diffuse, self.dipole, self.solar_flux, self.switches)

    def compute(self, r_BN_N, v_BN_N, q_BN, density=0.0, r_SN_N=(ASTRONOMICAL_UNIT, 0.0, 0.0), sunlit_fraction=1.0,
                B_N=(0.0, 0.0, 0.0), com_B=(0.0, 0.0, 0.0)):
        vectors = {"r_BN_N": (r_BN_N, 3), "v_BN_N": (v_BN_N, 3), "q_BN": (q_BN, 4), "r_SN_N": (r_SN_N, 3),
                   "B_N": (B_N, 3), "center_of_mass_B": (com_B, 3)}
        arrays = {}
        for name, (value, n) in vectors.items():
            a = np.asarray(value, dtype=float).reshape(n)
            if not np.all(np.isfinite(a)):
                raise ValueError(f"{name} {a.tolist()} must be finite")
            arrays[name] = a
        for name, value in (("density", density), ("sunlit_fraction", sunlit_fraction)):
            if not math.isfinite(value):
                raise ValueError(f"{name} = {value!r} must be finite")
        if not 0.0 <= sunlit_fraction <= 1.0:
            raise ValueError(f"sunlit_fraction = {sunlit_fraction!r} must be in [0, 1]")
        if density < 0.0:
            raise ValueError(f"density = {density!r} kg/m3 must be >= 0")
        f = self.facets
        out = np.zeros(18)
        ok = evaluate(arrays["r_BN_N"], arrays["v_BN_N"], arrays["q_BN"], float(density), arrays["r_SN_N"],
                      float(sunlit_fraction), arrays["B_N"], arrays["center_of_mass_B"], self.J, self.mu,
                      self.omega_earth, f.normals, f.areas, f.centres, f.cd, f.specular, f.diffuse, self.dipole,
                      self.solar_flux, self.switches, out)
        if not ok:
            if not np.any(arrays["r_BN_N"]):
                raise ValueError("r_BN_N [0, 0, 0] must be a non-zero position")
            raise ValueError(f"q_BN {arrays['q_BN'].tolist()} must have a non-zero norm")
        self.last = out
        return out

    # ---- full state: none (the outputs are functions of the inputs) -------------------------
    def get_state(self):
        return {}

    def set_state(self, state):
        pass

    @staticmethod
    def total_torque(out):
        """The sum of the four torques of an `out` array (N.m, B)."""
        return out[0:3] + out[3:6] + out[9:12] + out[15:18]

    @staticmethod
    def total_force_N(out):
        """Aerodynamic plus SRP force (N, N frame)."""
        return out[6:9] + out[12:15]

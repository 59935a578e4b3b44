"""Cowell orbit propagation: r, v in N under gravity (point mass + EGM96 J2..J6), drag and thrust.

Equations of motion (N frame, m and s):

    r' = v
    v' = a_grav(r) + a_drag + a_thrust
    a_grav   : components.environment.gravity.accel_zonal (point mass + J2..J`zonal_degree`); with
               `gravity_degree` > 0 the point mass plus the GGM03S field to that degree and order
               (gravity.accel_harmonics) in the Earth-fixed frame (N rotated by the GMST of each
               stage's time), and optionally the Sun and the Moon as third bodies (gravity.third_body,
               the ephemerides of components.environment.sun and .moon)
    a_drag   = -1/2 rho(r, t) Cd A / m |v_rel| v_rel,  v_rel = v - omega_E x r       (thesis Eq. 1,
               with the velocity relative to the co-rotating atmosphere, omega_E = 7.292115e-5 rad/s
               about z)
    a_thrust = A(q_BN)^T F_B / m            (body-frame thrust rotated to N, components/core/rotations.py)
             = -|F_B| / m * v/|v|            when `retrograde` (along -v, v relative to N, taken at
                                             every stage, so the burn follows the velocity)

F_B, q_BN, `retrograde` and the mass are inputs held constant across a communication step
(zero-order hold). F_B is the propulsion's thrust plus, when given (`impulse_B`), the attitude
thrusters' mean force over the previous step (propulsion.ImpulseWindow: the RCS net force, the axial
thrusters' force error and misalignment); `retrograde` takes the propulsion's magnitude only.
The density rho comes from a model of components/environment/atmosphere/ (`make_density_model`)
and is evaluated at every integrator stage (no caching across stages).

Integrator: Dormand-Prince 8(5,3) (DOP853, Hairer's coefficients in components/orbit/dop853.py,
his error estimator and step control), written as one function that integrates a whole
communication step with adaptive internal steps and lands exactly on its end; the last internal
step size is carried to the next communication step. It is compiled by numba when numba is
installed (components/core/jit.py) and runs as plain Python otherwise, with the same results. The
density model's kernel is called at every stage (NRLMSIS's calls pymsis from compiled code).

Tolerances (defaults, from a convergence check, see bench/bench_orbit.py and the report):
rtol = 1e-11, atol = 1e-4 m on position and 1e-7 m/s on velocity.

Re-entry: the geodetic altitude above WGS-84 (components/environment/geodesy.py; it depends on z and
sqrt(x^2 + y^2) only, so it is evaluated in N) is checked after every accepted internal step;
once it is below `reentry_altitude`, `reentered` latches and the model keeps the state of that
step (its time is `reentry_time`), while its clock still advances to the requested times.

State (get_state/set_state): clock t, the state time, r, v, the carried step size, the re-entry
flag and time, and the held inputs: restoring it reproduces later steps bit for bit.
"""
import math

import numpy as np

from ..core.jit import function_of, loaded, njit
from ..core import rotations, time_utils
from ..environment import atmosphere, geodesy
from ..environment.atmosphere import base, exponential, harris_priester, jacchia_roberts
from ..core.checks import positive
from ..environment import magnetic_field, sun
from ..environment.gravity import (MU_MOON, MU_SUN, accel_harmonics, accel_zonal, spherical_harmonic_coefficients,
                                   third_body, zonal_coefficients)
from ..environment.moon import moon_position
from ..environment.sun import AU
from ..core.constants import DAY, DAYS_PER_CENTURY, MU_EARTH, OMEGA_EARTH_WGS84, R_EQ, WGS84_A, WGS84_F
from ..mission.neighbor import SPACECRAFT
from . import dop853
from .propulsion import ImpulseWindow
from .elements import kepler_to_cartesian, osculating_ecc, osculating_sma

RTOL = 1e-11
ATOL_POSITION = 1e-4  # m
ATOL_VELOCITY = 1e-7  # m/s
MAX_INTERNAL_STEPS = 1_000_000
INITIAL_STEP = 10.0  # s, first internal step (the controller adapts it at once)

_A, _B, _C, _E3, _E5 = (np.ascontiguousarray(x) for x in (dop853.A, dop853.B, dop853.C, dop853.E3, dop853.E5))

# indices into the force-parameter vector `fp`
_MU, _REQ, _DRAG, _BC, _JD0, _WE, _TX, _TY, _TZ, _TMAG, _RETRO = range(11)
# and into `grav`, the gravity beyond the zonal terms
_G_DEGREE, _G_SUN, _G_MOON, _G_S_J2000 = range(4)
gmst_nb = njit(cache=True)(magnetic_field.gmst)
sun_position_au_nb = njit(cache=True)(sun.sun_position_au)


@njit(cache=True)
def geodetic_altitude_nb(x, y, z):
    """Height above WGS-84 (m), Bowring's method as in components/environment/geodesy.py."""
    a = WGS84_A
    b = geodesy.WGS84_B
    e2 = geodesy.WGS84_E2
    f = WGS84_F
    p = math.sqrt(x * x + y * y)
    if p < 1e-9:
        return abs(z) - b
    ep2 = e2 / (1.0 - e2)
    beta = math.atan2(z * a, p * b)
    lat = 0.0
    for _ in range(3):
        sb = math.sin(beta)
        cb = math.cos(beta)
        lat = math.atan2(z + ep2 * b * sb ** 3, p - e2 * a * cb ** 3)
        beta = math.atan2((1.0 - f) * math.sin(lat), math.cos(lat))
    sl = math.sin(lat)
    n = a / math.sqrt(1.0 - e2 * sl * sl)
    if abs(lat) < math.radians(80.0):
        return p / math.cos(lat) - n
    return z / sl - n * (1.0 - e2)


@njit(cache=True)
def _extra_gravity(t, x, y, z, mu, r_eq, grav, Cnm, Snm):
    """The gravity beyond the zonal kernel's at time t (s since the epoch) and position (m, N):
    the spherical-harmonic terms of Cnm, Snm to degree grav[_G_DEGREE] in the Earth-fixed frame
    (N rotated by the GMST of the time), the Sun and the Moon as point masses (their flags)."""
    seconds = grav[_G_S_J2000] + t
    T = seconds / (DAY * DAYS_PER_CENTURY)
    ax = ay = az = 0.0
    degree = int(grav[_G_DEGREE])
    if degree > 0:
        th = gmst_nb(T)
        c, s = math.cos(th), math.sin(th)
        gx, gy, gz = accel_harmonics(c * x + s * y, -s * x + c * y, z, mu, r_eq, Cnm, Snm, degree)
        ax, ay, az = c * gx - s * gy, s * gx + c * gy, gz
    if grav[_G_SUN] != 0.0:
        sx, sy, sz = sun_position_au_nb(T)
        bx, by, bz = third_body(x, y, z, sx * AU, sy * AU, sz * AU, MU_SUN)
        ax, ay, az = ax + bx, ay + by, az + bz
    if grav[_G_MOON] != 0.0:
        mx, my, mz = moon_position(T)
        bx, by, bz = third_body(x, y, z, mx, my, mz, MU_MOON)
        ax, ay, az = ax + bx, ay + by, az + bz
    return ax, ay, az


# _deriv and _advance take the atmosphere's kernel as an argument, and numba types a function
# argument by the identity of its dispatcher object: the cache never matches one in another
# process, so cache=True only added a ~0.5 MB entry per run to the user's cache (for ever), and
# once an index held more entries than numba keeps their dispatchers alive, saving it raised
# ReferenceError inside fmi2DoStep. The product's kernels are bound in by the cached functions
# below (the kernel a module's global, their signatures without it); any other kernel is passed
# to _advance, compiled in each process (4-6 s).
@njit(cache=False)
def _deriv(t, y, fp, J, nmax, grav, Cnm, Snm, kernel, kdata, out):
    x = y[0]
    yy = y[1]
    z = y[2]
    vx = y[3]
    vy = y[4]
    vz = y[5]
    ax, ay, az = accel_zonal(x, yy, z, fp[_MU], fp[_REQ], J, nmax)
    if grav[_G_DEGREE] > 0.0 or grav[_G_SUN] != 0.0 or grav[_G_MOON] != 0.0:
        gx, gy, gz = _extra_gravity(t, x, yy, z, fp[_MU], fp[_REQ], grav, Cnm, Snm)
        ax += gx
        ay += gy
        az += gz
    if fp[_DRAG] != 0.0:
        rho = kernel(y[0:3], fp[_JD0] + t / DAY, kdata)
        w = fp[_WE]
        vrx = vx + w * yy
        vry = vy - w * x
        vrz = vz
        vr = math.sqrt(vrx * vrx + vry * vry + vrz * vrz)
        k = -fp[_BC] * rho * vr
        ax += k * vrx
        ay += k * vry
        az += k * vrz
    ax += fp[_TX]
    ay += fp[_TY]
    az += fp[_TZ]
    if fp[_RETRO] != 0.0:
        vm = math.sqrt(vx * vx + vy * vy + vz * vz)
        k = -fp[_TMAG] / vm
        ax += k * vx
        ay += k * vy
        az += k * vz
    out[0] = vx
    out[1] = vy
    out[2] = vz
    out[3] = ax
    out[4] = ay
    out[5] = az


@njit(cache=False)
def _advance(t, y0, t_end, h, rtol, atol, fp, J, nmax, grav, Cnm, Snm, kernel, kdata, A, B, C, E3, E5,
             reentry_altitude, max_steps):
    """DOP853 from t to t_end (lands exactly). Returns (t, y, h_next, reentered, steps, rejected).

    Step control as Hairer's DOP853 (safety 0.9, factor limits 0.2..10, error exponent -1/8)."""
    n = 6
    y = y0.copy()
    K = np.empty((13, n))
    ytmp = np.empty(n)
    ynew = np.empty(n)
    _deriv(t, y, fp, J, nmax, grav, Cnm, Snm, kernel, kdata, K[0])
    steps = 0
    rejected = 0
    reentered = False
    h_abs = h
    while t < t_end:
        if steps >= max_steps:
            raise RuntimeError("orbit integrator: too many internal steps in one communication step")
        step_rejected = False
        while True:
            remaining = t_end - t
            last = h_abs >= remaining
            hh = remaining if last else h_abs
            for s in range(1, 12):
                for k in range(n):
                    acc = 0.0
                    for j in range(s):
                        acc += A[s, j] * K[j, k]
                    ytmp[k] = y[k] + hh * acc
                _deriv(t + C[s] * hh, ytmp, fp, J, nmax, grav, Cnm, Snm, kernel, kdata, K[s])
            for k in range(n):
                acc = 0.0
                for j in range(12):
                    acc += B[j] * K[j, k]
                ynew[k] = y[k] + hh * acc
            t_new = t_end if last else t + hh
            _deriv(t_new, ynew, fp, J, nmax, grav, Cnm, Snm, kernel, kdata, K[12])
            e5 = 0.0
            e3 = 0.0
            for k in range(n):
                sc = atol[k] + max(abs(y[k]), abs(ynew[k])) * rtol
                a5 = 0.0
                a3 = 0.0
                for j in range(13):
                    a5 += E5[j] * K[j, k]
                    a3 += E3[j] * K[j, k]
                a5 /= sc
                a3 /= sc
                e5 += a5 * a5
                e3 += a3 * a3
            if e5 == 0.0 and e3 == 0.0:
                err = 0.0
            else:
                err = hh * e5 / math.sqrt((e5 + 0.01 * e3) * n)
            if err < 1.0:
                if err == 0.0:
                    factor = 10.0
                else:
                    factor = min(10.0, 0.9 * err ** (-1.0 / 8.0))
                if step_rejected:
                    factor = min(1.0, factor)
                new_h = hh * factor
                if last and hh < h_abs:  # a clipped final step says little about the step size
                    new_h = max(new_h, h_abs)
                h_abs = new_h
                break
            h_abs = hh * max(0.2, 0.9 * err ** (-1.0 / 8.0))
            step_rejected = True
            rejected += 1
            if h_abs < 1e-9:
                raise RuntimeError("orbit integrator: step size underflow")
        t = t_new
        for k in range(n):
            y[k] = ynew[k]
            K[0, k] = K[12, k]
        steps += 1
        if reentry_altitude == reentry_altitude:  # not NaN: check
            if geodetic_altitude_nb(y[0], y[1], y[2]) < reentry_altitude:
                reentered = True
                break
    return t, y, h_abs, reentered, steps, rejected


@njit(cache=True)
def _advance_jacchia_roberts(t, y0, t_end, h, rtol, atol, fp, J, nmax, grav, Cnm, Snm, kdata, A, B, C, E3, E5,
                             reentry_altitude, max_steps):
    return _advance(t, y0, t_end, h, rtol, atol, fp, J, nmax, grav, Cnm, Snm, jacchia_roberts.jacchia_roberts_kernel,
                    kdata, A, B, C, E3, E5, reentry_altitude, max_steps)


@njit(cache=True)
def _advance_harris_priester(t, y0, t_end, h, rtol, atol, fp, J, nmax, grav, Cnm, Snm, kdata, A, B, C, E3, E5,
                             reentry_altitude, max_steps):
    return _advance(t, y0, t_end, h, rtol, atol, fp, J, nmax, grav, Cnm, Snm, harris_priester.harris_priester_kernel,
                    kdata, A, B, C, E3, E5, reentry_altitude, max_steps)


@njit(cache=True)
def _advance_exponential(t, y0, t_end, h, rtol, atol, fp, J, nmax, grav, Cnm, Snm, kdata, A, B, C, E3, E5,
                         reentry_altitude, max_steps):
    return _advance(t, y0, t_end, h, rtol, atol, fp, J, nmax, grav, Cnm, Snm, exponential.exponential_kernel,
                    kdata, A, B, C, E3, E5, reentry_altitude, max_steps)


@njit(cache=True)
def _advance_without_drag(t, y0, t_end, h, rtol, atol, fp, J, nmax, grav, Cnm, Snm, kdata, A, B, C, E3, E5,
                          reentry_altitude, max_steps):
    return _advance(t, y0, t_end, h, rtol, atol, fp, J, nmax, grav, Cnm, Snm, base.vacuum_kernel,
                    kdata, A, B, C, E3, E5, reentry_altitude, max_steps)


_CACHED_ADVANCE = {function_of(k): f for k, f in ((jacchia_roberts.jacchia_roberts_kernel, _advance_jacchia_roberts),
                                                  (harris_priester.harris_priester_kernel, _advance_harris_priester),
                                                  (exponential.exponential_kernel, _advance_exponential),
                                                  (base.vacuum_kernel, _advance_without_drag))}


class CowellOrbit:
    """Cowell propagation of r, v in N; see the module docstring.

    density_model: a model from components.environment.atmosphere.make_density_model (or a name given to it,
    with `space_weather`); required when drag is True. zonal_degree: 0 (point mass) or 2..6.
    t0: simulation time (s since `epoch`) of the initial elements."""

    def __init__(self, epoch=time_utils.DEFAULT_EPOCH, sma0=R_EQ + 420e3, ecc0=0.0, inc0=math.radians(51.6),
                 raan0=0.0, argp0=0.0, ta0=0.0, Cd=SPACECRAFT.Cd, area=SPACECRAFT.drag_area,
                 mass=SPACECRAFT.mass, reentry_altitude=250e3,
                 density_model=None, drag=True, zonal_degree=6, mu=MU_EARTH, t0=0.0, space_weather=None,
                 rtol=RTOL, atol_position=ATOL_POSITION, atol_velocity=ATOL_VELOCITY, gravity_degree=0,
                 gravity_order=None, sun_gravity=False, moon_gravity=False):
        self.epoch = epoch
        self.jd0 = time_utils.julian_date(time_utils.parse_epoch(epoch, "epoch"))
        self.mu = positive("mu", mu, "m3/s2")
        self.Cd = positive("Cd", Cd, "(drag coefficient)")
        self.area = positive("area", area, "m2")
        self.reentry_altitude = float(reentry_altitude)
        if not math.isfinite(self.reentry_altitude):
            raise ValueError(f"reentry_altitude = {reentry_altitude!r} m must be finite")
        if isinstance(zonal_degree, bool) or int(zonal_degree) != zonal_degree or zonal_degree == 1:
            raise ValueError(f"zonal_degree = {zonal_degree!r} must be 0 (point mass) or an integer in [2, 6]")
        self.zonal_degree = int(zonal_degree)
        self.J = zonal_coefficients(self.zonal_degree)
        self._gravity_field(gravity_degree, gravity_order, sun_gravity, moon_gravity)
        self.rtol = positive("rtol", rtol, "")
        self.atol = np.array([positive("atol_position", atol_position, "m")] * 3
                             + [positive("atol_velocity", atol_velocity, "m/s")] * 3)
        sma0, ecc0, inc0 = float(sma0), float(ecc0), float(inc0)
        if not (math.isfinite(sma0) and sma0 > 0.0):
            raise ValueError(f"sma0 = {sma0!r} m must be a finite number > 0")
        if not (math.isfinite(ecc0) and 0.0 <= ecc0 < 1.0):
            raise ValueError(f"ecc0 = {ecc0!r} must be in [0, 1) (closed orbits only)")
        if not (math.isfinite(inc0) and 0.0 <= inc0 <= math.pi):
            raise ValueError(f"inc0 = {inc0!r} rad must be in [0, pi]")
        for name, value in (("raan0", raan0), ("argp0", argp0), ("ta0", ta0)):
            if not math.isfinite(float(value)):
                raise ValueError(f"{name} = {value!r} rad must be finite")
        r0, v0 = kepler_to_cartesian(sma0, ecc0, inc0, raan0, argp0, ta0, self.mu)
        perigee_alt = float(sma0) * (1.0 - float(ecc0)) - R_EQ
        if perigee_alt < self.reentry_altitude:
            raise ValueError(f"initial perigee altitude sma0 (1 - ecc0) - {R_EQ} m = {perigee_alt:.1f} m is below "
                             f"reentry_altitude = {self.reentry_altitude:.1f} m; raise sma0 or lower ecc0")
        self.drag = bool(drag)
        if isinstance(density_model, str):
            density_model = atmosphere.make_density_model(density_model, space_weather=space_weather,
                                                          inclination=float(inc0))
        if self.drag and density_model is None:
            raise ValueError("drag is on but no density_model was given; give a model from "
                             "components.environment.atmosphere.make_density_model or drag=False")
        self.density_model = density_model
        self._kernel = density_model.kernel if self.drag else base.vacuum_kernel  # not called: drag flag 0
        self._kdata = (density_model.kernel_data or ()) if self.drag else ()
        self.t = time_utils.check_time(t0, "t0")
        self.t_state = self.t
        self.y = np.concatenate([r0, v0])
        self.h = INITIAL_STEP
        self.reentered = False
        self.reentry_time = float("nan")
        self.steps = 0  # internal integrator steps so far (diagnostics)
        self.F_B = (0.0, 0.0, 0.0)
        self.F_extra_B = (0.0, 0.0, 0.0)  # the attitude thrusters' mean force over the previous step
        self.impulse = ImpulseWindow()
        self.q_BN = (0.0, 0.0, 0.0, 1.0)
        self.retrograde = False
        self.mass = positive("mass", mass, "kg")
        self._outputs = None

    def _gravity_field(self, degree, order, sun_gravity, moon_gravity):
        """gravity_degree > 0: the GGM03S field to that degree and order (default: the degree) in
        the Earth-fixed frame replaces the EGM96 zonal terms; the Sun and Moon point masses."""
        for name, value in (("sun_gravity", sun_gravity), ("moon_gravity", moon_gravity)):
            if not isinstance(value, (bool, np.bool_)):
                raise ValueError(f"{name} = {value!r} must be true or false")
        if isinstance(degree, bool) or int(degree) != degree or int(degree) < 0:
            raise ValueError(f"gravity_degree = {degree!r} must be 0 (the zonal model of zonal_degree) or an "
                             "integer in [2, 36] (GGM03S)")
        degree = int(degree)
        if degree:
            self._Cnm, self._Snm = spherical_harmonic_coefficients(degree, degree if order is None else order)
            self.J, self.zonal_degree = zonal_coefficients(0), 0  # point mass only: the field has the zonal terms
        else:
            self._Cnm = self._Snm = np.zeros((1, 1))
        self.gravity_degree = degree
        self._grav = np.array([float(degree), float(bool(sun_gravity)), float(bool(moon_gravity)),
                               time_utils.seconds_since_j2000(self.epoch)])

    # ---- inputs --------------------------------------------------------------------------
    def set_inputs(self, F_thrust_B=None, q_BN=None, retrograde=None, mass=None, impulse_B=None, step=0.0):
        """Inputs held until the next step (zero-order hold). impulse_B: the attitude thrusters' running
        total of impulse (N.s, B) before a step of `step` seconds, whose mean force over the previous
        step is added to F_thrust_B (propulsion.ImpulseWindow; not with retrograde)."""
        if F_thrust_B is not None:
            F = tuple(float(x) for x in F_thrust_B)
            if len(F) != 3 or not all(math.isfinite(x) for x in F):
                raise ValueError(f"F_thrust_B = {F_thrust_B!r} must be 3 finite numbers (N)")
            self.F_B = F
        if q_BN is not None:
            q = tuple(float(x) for x in q_BN)
            if len(q) != 4 or not all(math.isfinite(x) for x in q):
                raise ValueError(f"q_BN = {q_BN!r} must be 4 finite numbers (scalar last)")
            rotations.normalized(q, "q_BN")  # raises for a zero quaternion
            self.q_BN = q
        if retrograde is not None:
            self.retrograde = bool(retrograde)
        if mass is not None:
            self.mass = positive("mass", mass, "kg")
        if impulse_B is not None:  # last: a refused input leaves the window as it was
            self.F_extra_B = self.impulse.force(impulse_B, step)

    def thrust_acceleration_N(self):
        """A(q)^T F_B / m (m/s^2) for the held inputs (not used when retrograde)."""
        q = rotations.normalized(self.q_BN, "q_BN")
        Am = rotations.attitude_matrix(q)
        F, e = self.F_B, self.F_extra_B
        if e != (0.0, 0.0, 0.0):
            F = (F[0] + e[0], F[1] + e[1], F[2] + e[2])
        return tuple((Am[0][k] * F[0] + Am[1][k] * F[1] + Am[2][k] * F[2]) / self.mass for k in range(3))

    def _force_parameters(self):
        fp = np.zeros(11)
        fp[_MU] = self.mu
        fp[_REQ] = R_EQ
        fp[_DRAG] = 1.0 if self.drag else 0.0
        fp[_BC] = 0.5 * self.Cd * self.area / self.mass
        fp[_JD0] = self.jd0
        fp[_WE] = OMEGA_EARTH_WGS84  # the atmosphere co-rotates with the Earth
        if self.retrograde:
            fp[_TMAG] = math.sqrt(sum(f * f for f in self.F_B)) / self.mass
            fp[_RETRO] = 1.0
        else:
            fp[_TX], fp[_TY], fp[_TZ] = self.thrust_acceleration_N()
        return fp

    # ---- time stepping -------------------------------------------------------------------
    def advance_to(self, t):
        t = time_utils.check_time(t, "time")
        if t < self.t:
            raise ValueError(f"time = {t!r} s is before the model time {self.t!r} s (use set_state to go back)")
        if t == self.t:
            return
        if not self.reentered:
            args = (self.t_state, self.y, t, self.h, self.rtol, self.atol, self._force_parameters(), self.J,
                    self.zonal_degree, self._grav, self._Cnm, self._Snm)
            tail = (self._kdata, _A, _B, _C, _E3, _E5, self.reentry_altitude, MAX_INTERNAL_STEPS)
            cached = loaded(_CACHED_ADVANCE.get(function_of(self._kernel)))
            ts, y, h, reentered, steps, _ = (cached(*args, *tail) if cached is not None
                                             else _advance(*args, self._kernel, *tail))
            self.t_state, self.y, self.h, self.steps = float(ts), y, float(h), self.steps + int(steps)
            if reentered:
                self.reentered = True
                self.reentry_time = self.t_state
            self._outputs = None
        self.t = t

    def step(self, h):
        self.advance_to(self.t + h)

    # ---- outputs -------------------------------------------------------------------------
    def jd_state(self):
        return self.jd0 + self.t_state / DAY

    def position(self):
        return self.y[:3].copy()

    def velocity(self):
        return self.y[3:].copy()

    def outputs(self):
        """dict of every FMU output quantity for the current state (cached until the state changes)."""
        if self._outputs is None:
            r = tuple(float(x) for x in self.y[:3])
            v = tuple(float(x) for x in self.y[3:])
            jd = self.jd_state()
            lat, lon, alt = geodesy.geodetic_from_inertial(r, jd)
            a = osculating_sma(r, v, self.mu)
            e = osculating_ecc(r, v, self.mu)
            if self.density_model is not None:
                rho = float(self.density_model.density(np.array(r), jd))
            else:
                rho = 0.0
            self._outputs = {
                "r_BN_N": r, "v_BN_N": v, "altitude": alt, "altitude_spherical": geodesy.spherical_altitude(r),
                "latitude": lat, "longitude": lon, "sma": a, "ecc": e,
                "perigee_altitude": a * (1.0 - e) - R_EQ, "apogee_altitude": a * (1.0 + e) - R_EQ,
                "density": rho, "reentered": self.reentered,
            }
        return self._outputs

    # ---- state ---------------------------------------------------------------------------
    def get_state(self):
        return {"t": self.t, "t_state": self.t_state, "y": [float(x) for x in self.y], "h": self.h,
                "reentered": self.reentered, "reentry_time": self.reentry_time, "steps": self.steps,
                "F_B": self.F_B, "q_BN": self.q_BN, "retrograde": self.retrograde, "mass": self.mass,
                "F_extra_B": self.F_extra_B, "impulse": self.impulse.get_state()}

    def set_state(self, state):
        self.t = float(state["t"])
        self.t_state = float(state["t_state"])
        self.y = np.array(state["y"], dtype=float)
        self.h = float(state["h"])
        self.reentered = bool(state["reentered"])
        self.reentry_time = float(state["reentry_time"])
        self.steps = int(state["steps"])
        self.F_B = tuple(state["F_B"])
        self.q_BN = tuple(state["q_BN"])
        self.retrograde = bool(state["retrograde"])
        self.mass = float(state["mass"])
        if "impulse" in state:  # states saved before the thrusters' force reached the orbit carry none
            self.F_extra_B = tuple(state["F_extra_B"])
            self.impulse.set_state(state["impulse"])
        self._outputs = None



"""Cost and accuracy of each role's fidelities, against the highest fidelity on the same case
(the numbers of docs/fidelity.md).

    python bench/bench_fidelity.py            # about a minute

- orbit: Cowell (Orbit) vs orbit-averaged (OrbitAveraged), 420 km, Jacchia-Roberts with the
  bundled space weather, 10 days: wall time per simulated day, and the decay of the mean
  semi-major axis (Cowell: osculating a averaged over the last orbit);
- gravity: Cowell with zonal degree 2 vs 6 (drag off), 1 day: position difference;
- density: each model at 2000 points of one day on a 420 km, 51.6 deg circular orbit: time per
  call, and the mean and largest |log10(rho / rho_NRLMSIS 2.1)|;
- full gravity: the GGM03S field (8, 20, 36) and the Sun and Moon against 36x36 with both, 1 day;
- magnetic field: the tilted dipole and IGRF-14 to degree 4 against degree 13 at 500 km;
- disturbance torques: the four sources along one orbit at 420 km;
- attitude integration: the detumble system (thesis case 1) with Euler and RK4 through the
  master: wall time per simulated second, and the end state against RK4.
"""
import math
from pathlib import Path
import sys
import time

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from components.core.constants import DAY, MU_EARTH, R_EQ  # noqa: E402
from components.environment import atmosphere  # noqa: E402
from components.orbit import averaged, circular, cowell  # noqa: E402

REPO = Path(__file__).resolve().parents[1]


def osculating_sma(y):
    r, v = np.linalg.norm(y[:3]), np.linalg.norm(y[3:])
    return 1.0 / (2.0 / r - v * v / MU_EARTH)


def mean_sma_cowell(orbit, t_end, period):
    """Advance a CowellOrbit to t_end and average the osculating a over the orbit before it."""
    orbit.advance_to(t_end - period)
    samples = []
    for k in range(1, 61):
        orbit.advance_to(t_end - period + k * period / 60)
        samples.append(osculating_sma(orbit.y))
    return float(np.mean(samples))


def bench_orbit(days=10.0):
    sma0 = R_EQ + 420e3
    period = 2 * math.pi * math.sqrt(sma0 ** 3 / MU_EARTH)
    dens = atmosphere.make_density_model("jacchia_roberts")
    c = cowell.CowellOrbit(sma0=sma0, density_model=dens)
    a_start = mean_sma_cowell(c, period, period)
    w0 = time.perf_counter()
    a_end = mean_sma_cowell(c, days * DAY + period, period)
    cost_c = (time.perf_counter() - w0) / days
    a_avg = averaged.OrbitAveraged(dens, sma0=sma0)
    a_avg.advance_to(period)
    s0 = a_avg.sma
    w0 = time.perf_counter()
    a_avg.advance_to(days * DAY + period)
    cost_a = (time.perf_counter() - w0) / days
    decay_c, decay_a = a_start - a_end, s0 - a_avg.sma
    print(f"orbit    Cowell        {cost_c * 1e3:9.1f} ms per simulated day   mean-a decay over {days:g} d "
          f"{decay_c:8.1f} m (reference)")
    print(f"orbit    averaged      {cost_a * 1e3:9.1f} ms per simulated day   mean-a decay {decay_a:8.1f} m "
          f"({100 * (decay_a - decay_c) / decay_c:+.1f} %); {cost_c / cost_a:.0f}x faster")


def bench_gravity():
    out = {}
    for degree in (2, 6):
        cowell.CowellOrbit(drag=False, zonal_degree=degree).advance_to(600.0)  # compile outside the timing
    for degree in (2, 6):
        o = cowell.CowellOrbit(drag=False, zonal_degree=degree)
        w0 = time.perf_counter()
        o.advance_to(DAY)
        out[degree] = (time.perf_counter() - w0, o.y[:3].copy())
    diff = np.linalg.norm(out[2][1] - out[6][1])
    print(f"gravity  J2..J6        {out[6][0] * 1e3:9.1f} ms per simulated day   (reference)")
    print(f"gravity  J2 only       {out[2][0] * 1e3:9.1f} ms per simulated day   position after 1 d "
          f"{diff / 1e3:.2f} km from J2..J6")


def bench_density():
    orbit = circular.CircularOrbit(altitude=420e3)
    ts = np.linspace(0.0, DAY, 2000)
    rs = [orbit.position(t) for t in ts]
    jd0 = 2459945.5  # 2023-01-01
    values, costs = {}, {}
    for name in ("msis", "jacchia_roberts", "harris_priester", "exponential"):
        model = atmosphere.make_density_model(name, inclination=math.radians(51.6))
        model.density(rs[0], jd0)  # compile / load
        w0 = time.perf_counter()
        values[name] = np.array([model.density(r, jd0 + t / DAY) for r, t in zip(rs, ts)])
        costs[name] = (time.perf_counter() - w0) / len(ts)
    ref = values["msis"]
    for name, v in values.items():
        dev = np.abs(np.log10(v / ref))
        note = "(reference)" if name == "msis" else (f"mean |log10 ratio| {dev.mean():.3f} (x{10 ** dev.mean():.2f}), "
                                                     f"largest {dev.max():.3f} (x{10 ** dev.max():.2f})")
        print(f"density  {name:16s}{costs[name] * 1e6:8.1f} us per call           {note}")


def bench_attitude():
    import system_ssp

    res = {}
    with system_ssp.System(REPO / "build" / "ssp" / "detumble.ssp") as s:
        for integ in ("rk4", "euler"):
            r = s.run(parameter_sets=["parameters/detumble_case1.ssv"], parameters={"dynamics.integrator": integ},
                      outputs=[f"dynamics.q_BN[{i}]" for i in (1, 2, 3, 4)])
            q = np.array([r.final[f"dynamics.q_BN[{i}]"] for i in (1, 2, 3, 4)])
            res[integ] = (r.wall_time / r.stop_time, r.stop_time, q)
    dq = min(np.linalg.norm(res["euler"][2] - res["rk4"][2]), np.linalg.norm(res["euler"][2] + res["rk4"][2]))
    print(f"attitude RK4           {res['rk4'][0] * 1e3:9.2f} ms per simulated second (reference; detumble case 1 "
          f"ends at {res['rk4'][1]:.3f} s)")
    print(f"attitude Euler         {res['euler'][0] * 1e3:9.2f} ms per simulated second ends at "
          f"{res['euler'][1]:.3f} s, |dq| {dq:.2e} from RK4 (about {math.degrees(2 * dq):.3f} deg)")


def bench_full_gravity():
    """The GGM03S field to degree 2..36 and the Sun and Moon, one day at 420 km without drag, against
    the highest (degree 36 with both bodies): wall time per simulated day and the end position."""
    cases = {"J2..J6 (zonal, EGM96)": {}, "GGM03S 8x8": dict(gravity_degree=8),
             "GGM03S 20x20": dict(gravity_degree=20),
             "GGM03S 36x36": dict(gravity_degree=36),
             "36x36 + Sun + Moon": dict(gravity_degree=36, sun_gravity=True, moon_gravity=True)}
    out = {}
    for name, kw in cases.items():
        cowell.CowellOrbit(drag=False, **kw).advance_to(600.0)  # compile outside the timing
        o = cowell.CowellOrbit(drag=False, **kw)
        w0 = time.perf_counter()
        o.advance_to(DAY)
        out[name] = (time.perf_counter() - w0, o.y[:3].copy())
    ref = out["36x36 + Sun + Moon"][1]
    for name, (cost, r) in out.items():
        note = ("(reference)" if name.startswith("36x36 +")
                else f"position after 1 d {np.linalg.norm(r - ref):9.1f} m off")
        print(f"gravity  {name:22s}{cost * 1e3:9.1f} ms per simulated day   {note}")


def bench_magnetic_field(points=400):
    """The tilted dipole and IGRF-14 cut to lower degrees against IGRF-14 to degree 13 at 500 km,
    400 random points on 2023-01-01: cost per call and the |B| and direction errors."""
    from components.environment import igrf, magnetic_field

    rng = np.random.default_rng(400)
    rs = [u / np.linalg.norm(u) * (magnetic_field.R_REF + 500e3) for u in rng.normal(size=(points, 3))]
    epoch = "2023-01-01T00:00:00Z"
    models = {"IGRF-14 degree 13": igrf.IgrfField(epoch), "IGRF-14 degree 4": igrf.IgrfField(epoch, degree=4),
              "tilted dipole": magnetic_field.MagneticField(epoch)}
    fields, costs = {}, {}
    for name, m in models.items():
        m.field_N(rs[0])
        w0 = time.perf_counter()
        fields[name] = np.array([m.field_N(tuple(r)) for r in rs])
        costs[name] = (time.perf_counter() - w0) / points
    ref = fields["IGRF-14 degree 13"]
    for name, b in fields.items():
        if name == "IGRF-14 degree 13":
            print(f"field    {name:22s}{costs[name] * 1e6:9.1f} us per call           (reference)")
            continue
        mag = np.abs(np.linalg.norm(b, axis=1) / np.linalg.norm(ref, axis=1) - 1.0) * 100
        cos = np.sum(b * ref, axis=1) / np.linalg.norm(b, axis=1) / np.linalg.norm(ref, axis=1)
        ang = np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))
        print(f"field    {name:22s}{costs[name] * 1e6:9.1f} us per call           |B| off {np.median(mag):.1f} % "
              f"median, {np.percentile(mag, 95):.1f} % p95, {mag.max():.1f} % worst; direction "
              f"{np.median(ang):.1f} deg median, {np.percentile(ang, 95):.1f} p95, {ang.max():.1f} worst")


def bench_disturbances(samples=2000):
    """The NEIGHBOR stack's four disturbance torques along one orbit at 420 km (Jacchia-Roberts
    density, IGRF-14, the Sun with the conical shadow) in a fixed inertial attitude tilted off
    the principal axes: cost per evaluation and each source's largest and mean |torque|."""
    from components.attitude import disturbances
    from components.attitude.rigid_body import box_inertia
    from components.environment import eclipse, igrf, sun
    from components.mission.neighbor import FACETS, RESIDUAL_DIPOLE_B, SPACECRAFT

    facets = disturbances.Facets([f.normal_B for f in FACETS], [f.area for f in FACETS], [f.centre_B for f in FACETS],
                                 [f.Cd for f in FACETS], [f.specular for f in FACETS], [f.diffuse for f in FACETS])
    model = disturbances.DisturbanceTorques(box_inertia(SPACECRAFT.mass, *SPACECRAFT.edges), facets,
                                            RESIDUAL_DIPOLE_B)
    c = cowell.CowellOrbit(sma0=R_EQ + 420e3, density_model=atmosphere.make_density_model("jacchia_roberts"))
    field, ephemeris, shadow = igrf.IgrfField(), sun.SunEphemeris(), eclipse.EarthShadow()
    dens = c.density_model
    period = 2 * math.pi * math.sqrt((R_EQ + 420e3) ** 3 / MU_EARTH)
    q = (0.2, 0.3, 0.1, math.sqrt(1 - 0.14))
    com = (0.003, 0.0, 0.0)  # the tank a third empty moves the centre of mass (RigidBody center_of_mass_B)
    torques, cost = [], 0.0
    for t in np.linspace(0.0, period, samples):
        c.advance_to(t)
        r, v = c.y[:3], c.y[3:]
        s = ephemeris.position(t)
        nu = shadow.evaluate(r, s)[0]
        args = (r, v, q, dens.density(r, c.jd0 + t / DAY), s, nu, field.field_N(tuple(r), t), com)
        w0 = time.perf_counter()
        out = model.compute(*args)
        cost += time.perf_counter() - w0
        torques.append([np.linalg.norm(out[k:k + 3]) for k in (0, 3, 9, 15)])
    torques = np.array(torques)
    for k, name in enumerate(("gravity gradient", "aerodynamic", "solar pressure", "residual dipole")):
        print(f"torque   {name:22s}{cost / samples * 1e6:9.1f} us per call (all four)  largest "
              f"{torques[:, k].max():.2e} N.m, mean {torques[:, k].mean():.2e} N.m over one orbit")


def main():
    bench_orbit()
    bench_gravity()
    bench_full_gravity()
    bench_magnetic_field()
    bench_disturbances()
    bench_density()
    bench_attitude()


if __name__ == "__main__":
    main()

"""The space environment (issue 56) against independent implementations on the same inputs:
Basilisk's modules (GravityGradientEffector, facetDragDynamicEffector, facetSRPDynamicEffector,
MtbEffector, SphericalHarmonicsGravityModel with the same GGM03S file, the centred dipole) and,
for IGRF-14, the ppigrf package. Each test draws 25 random cases (attitudes, positions, epochs,
facet sets), records its worst difference (printed at the end of the run) and bounds it at
round-off: where the physics is the same, the two agree to a few units in the last place.

Basilisk and ppigrf are test extras (pyproject.toml); without them these tests skip, saying so."""
import datetime as dt
import math

import numpy as np
import pytest

from basilisk_oracle import CASES, record_worst, require_basilisk

from components.attitude import disturbances
from components.core import rotations
from components.core.constants import MU_EARTH, OMEGA_EARTH_WGS84
from components.environment import gravity, igrf, magnetic_field


def _random_facets(rng, n):
    normals = rng.normal(size=(n, 3))
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    specular = rng.uniform(0.0, 0.6, n)
    return dict(normals=normals, areas=rng.uniform(0.005, 0.1, n), centres=rng.uniform(-0.2, 0.2, (n, 3)),
                cd=rng.uniform(1.8, 2.6, n), specular=specular, diffuse=rng.uniform(0.0, 1.0 - specular))


def _random_case(rng):
    r = rng.normal(size=3)
    r *= (6378e3 + rng.uniform(300e3, 1200e3)) / np.linalg.norm(r)
    v = np.cross(r, rng.normal(size=3))
    v *= 7600.0 / np.linalg.norm(v)
    q = rng.normal(size=4)
    q /= np.linalg.norm(q)
    a, b, c = rng.uniform(0.1, 0.4, 3)  # a box's principal moments, turned: products of inertia, realizable
    R = np.array(rotations.attitude_matrix(tuple(rng.normal(size=4) / 2.0)))
    R /= np.linalg.norm(R, axis=1)[:, None]
    R, _ = np.linalg.qr(R)
    J = R @ np.diag([b * b + c * c, a * a + c * c, a * a + b * b]) @ R.T
    sun = rng.normal(size=3)
    sun *= rng.uniform(0.983, 1.017) * disturbances.ASTRONOMICAL_UNIT / np.linalg.norm(sun)
    return r, v, q, J, sun


def _mrp(q):
    """Basilisk's MRP sigma_BN of our scalar-last q_BN (same attitude matrix)."""
    from Basilisk.utilities import RigidBodyKinematics as rbk
    return np.array(rbk.C2MRP(np.array(rotations.attitude_matrix(q))))


def _basilisk_effectors(r, v, q, J, facets, density, r_sun, dipole_B=None, b_N=None):
    """Force and torque (B frame, about the centre of mass at B) of Basilisk's gravity-gradient,
    facet drag, facet SRP and (with a dipole) magnetic torque bar effectors on a hub at r, v, q."""
    from Basilisk.architecture import messaging
    from Basilisk.simulation import (GravityGradientEffector, MtbEffector, facetDragDynamicEffector,
                                     facetSRPDynamicEffector, spacecraft)
    from Basilisk.utilities import SimulationBaseClass, macros, simIncludeGravBody

    sim = SimulationBaseClass.SimBaseClass()
    sim.CreateNewProcess("p").addTask(sim.CreateNewTask("t", macros.sec2nano(1.0)))
    sc = spacecraft.Spacecraft()
    sc.hub.IHubPntBc_B = J.tolist()
    sc.hub.mHub = 12.0
    sc.hub.r_CN_NInit, sc.hub.v_CN_NInit, sc.hub.sigma_BNInit = r.tolist(), v.tolist(), _mrp(q).tolist()
    factory = simIncludeGravBody.gravBodyFactory()
    earth = factory.createEarth()
    earth.isCentralBody, earth.mu = True, MU_EARTH
    sc.gravField.gravBodies = spacecraft.GravBodyVector(list(factory.gravBodies.values()))
    gg = GravityGradientEffector.GravityGradientEffector()
    gg.addPlanetName(earth.planetName)
    drag = facetDragDynamicEffector.FacetDragDynamicEffector()
    atmosphere = messaging.AtmoPropsMsgPayload()
    atmosphere.neutralDensity = density
    keep = [messaging.AtmoPropsMsg().write(atmosphere)]
    drag.atmoDensInMsg.subscribeTo(keep[0])
    srp = facetSRPDynamicEffector.FacetSRPDynamicEffector()
    srp.setNumFacets(len(facets["areas"]))
    srp.setNumArticulatedFacets(0)
    sun = messaging.SpicePlanetStateMsgPayload()
    sun.PositionVector = list(r_sun)
    keep.append(messaging.SpicePlanetStateMsg().write(sun))
    srp.sunInMsg.subscribeTo(keep[-1])
    for i in range(len(facets["areas"])):
        n, a, c = facets["normals"][i].tolist(), float(facets["areas"][i]), facets["centres"][i].tolist()
        drag.addFacet(a, float(facets["cd"][i]), n, c)
        srp.addFacet(a, np.eye(3).tolist(), n, [0.0, 0.0, 1.0], c, float(facets["diffuse"][i]),
                     float(facets["specular"][i]))
    effectors = {"gravity_gradient": gg, "drag": drag, "srp": srp}
    if dipole_B is not None:
        mtb = MtbEffector.MtbEffector()
        config = messaging.MTBArrayConfigMsgPayload()
        config.numMTB, config.GtMatrix_B, config.maxMtbDipoles = 3, np.eye(3).ravel().tolist(), [10.0] * 3
        command = messaging.MTBCmdMsgPayload()
        command.mtbDipoleCmds = list(dipole_B)
        field = messaging.MagneticFieldMsgPayload()
        field.magField_N = list(b_N)
        keep += [messaging.MTBArrayConfigMsg().write(config), messaging.MTBCmdMsg().write(command),
                 messaging.MagneticFieldMsg().write(field)]
        mtb.mtbParamsInMsg.subscribeTo(keep[-3])
        mtb.mtbCmdInMsg.subscribeTo(keep[-2])
        mtb.magInMsg.subscribeTo(keep[-1])
        effectors["magnetic"] = mtb
    for e in effectors.values():
        sc.addDynamicEffector(e)
    sim.AddModelToTask("t", sc)
    for e in effectors.values():
        sim.AddModelToTask("t", e)
    sim.InitializeSimulation()
    out = {}
    for name, e in effectors.items():
        e.UpdateState(0)
        e.computeForceTorque(0.0, 0.0)
        out[name] = (np.array(e.forceExternal_B).ravel(), np.array(e.torqueExternalPntB_B).ravel())
    return out


def test_disturbances_equal_basilisks_effectors(record_property):
    """Gravity gradient, facet drag (the flow relative to the co-rotating atmosphere given to
    Basilisk as the hub's velocity), facet SRP (its 1368 W/m2, full Sun) and the residual dipole
    (Basilisk's torque bars with the dipole as their command): 25 random bodies, attitudes and
    positions. Relative to each case's largest term, all four agree to round-off."""
    require_basilisk()
    rng = np.random.default_rng(56)
    worst = dict.fromkeys(("gravity gradient", "drag force", "drag torque", "SRP force", "SRP torque",
                           "dipole torque"), 0.0)
    for _ in range(CASES):
        r, v, q, J, r_sun = _random_case(rng)
        f = _random_facets(rng, int(rng.integers(3, disturbances.MAX_FACETS + 1)))
        density = 10 ** rng.uniform(-14, -10)
        dipole, b_N = rng.normal(size=3) * 0.02, rng.normal(size=3) * 3e-5
        facets = disturbances.Facets(f["normals"], f["areas"], f["centres"], f["cd"], f["specular"], f["diffuse"])
        ours = disturbances.DisturbanceTorques(J, facets, dipole, solar_flux=1368.0).compute(
            r, v, q, density, r_sun, 1.0, b_N)
        v_rel = v - np.cross([0.0, 0.0, OMEGA_EARTH_WGS84], r)
        theirs = _basilisk_effectors(r, v_rel, q, J, f, density, r_sun, dipole, b_N)
        A = np.array(rotations.attitude_matrix(q))
        pairs = {"gravity gradient": (ours[0:3], theirs["gravity_gradient"][1]),
                 "drag torque": (ours[3:6], theirs["drag"][1]), "drag force": (A @ ours[6:9], theirs["drag"][0]),
                 "SRP torque": (ours[9:12], theirs["srp"][1]), "SRP force": (A @ ours[12:15], theirs["srp"][0]),
                 "dipole torque": (ours[15:18], theirs["magnetic"][1])}
        for name, (a, b) in pairs.items():
            scale = np.linalg.norm(b)
            if scale == 0.0:  # no facet faces the flow or the Sun: both zero
                assert not np.any(a), name
                continue
            worst[name] = max(worst[name], float(np.max(np.abs(a - b))) / scale)
    for name, value in worst.items():
        record_worst(record_property, f"{name} vs Basilisk (relative)", value, 1e-12)


def test_spherical_harmonic_gravity_equals_basilisks_with_the_same_file(record_property):
    """GGM03S to a random degree 2..36 at 25 random Earth-fixed positions (200-2000 km): our V/W
    recursion (Montenbruck and Gill) and Basilisk's Pines formulation of the same vendored file."""
    require_basilisk()
    from Basilisk.simulation import gravityEffector
    from Basilisk.utilities import simIncludeGravBody

    model = gravityEffector.SphericalHarmonicsGravityModel()
    simIncludeGravBody.loadGravFromFile(gravity.GGM03S_FILE, model, 36)
    model.initializeParameters()
    rng = np.random.default_rng(5636)
    worst = 0.0
    for _ in range(CASES):
        r = rng.normal(size=3)
        r *= (6378e3 + rng.uniform(200e3, 2000e3)) / np.linalg.norm(r)
        degree = int(rng.integers(2, 37))
        theirs = np.array(model.computeField(r.tolist(), degree, False)).ravel()
        ours = gravity.acceleration_harmonics(r, degree)
        worst = max(worst, float(np.max(np.abs(ours - theirs)) / np.linalg.norm(theirs)))
    record_worst(record_property, "GGM03S spherical harmonics vs Basilisk (relative to the non-central part)", worst,
                 1e-13)


def test_tilted_dipole_equals_basilisks_centred_dipole(record_property):
    """Our dipole with the IGRF-13 2020 coefficients and Basilisk's magneticFieldCenteredDipole
    given the same coefficients and our GMST Earth rotation as the planet's orientation."""
    require_basilisk()
    from Basilisk.architecture import messaging
    from Basilisk.simulation import magneticFieldCenteredDipole
    from Basilisk.utilities import SimulationBaseClass, macros

    rng = np.random.default_rng(5601)
    worst = 0.0
    for _ in range(CASES):
        year, month, day, hour = rng.integers(2020, 2030), rng.integers(1, 13), rng.integers(1, 28), rng.integers(0, 24)
        epoch = f"{year}-{month:02d}-{day:02d}T{hour:02d}:00:00Z"
        ours = magnetic_field.MagneticField(epoch)
        r = rng.normal(size=3)
        r *= (6378e3 + rng.uniform(300e3, 1000e3)) / np.linalg.norm(r)
        th = ours.gmst()
        R3 = np.array([[math.cos(th), math.sin(th), 0.0], [-math.sin(th), math.cos(th), 0.0], [0.0, 0.0, 1.0]])
        sim = SimulationBaseClass.SimBaseClass()
        sim.CreateNewProcess("p").addTask(sim.CreateNewTask("t", macros.sec2nano(1.0)))
        field = magneticFieldCenteredDipole.MagneticFieldCenteredDipole()
        field.g10, field.g11, field.h11 = (x * 1e-9 for x in (magnetic_field.G10, magnetic_field.G11,
                                                              magnetic_field.H11))
        field.planetRadius = magnetic_field.R_REF
        planet = messaging.SpicePlanetStateMsgPayload()
        planet.J20002Pfix = R3.tolist()
        state = messaging.SCStatesMsgPayload()
        state.r_BN_N = r.tolist()
        msgs = [messaging.SpicePlanetStateMsg().write(planet), messaging.SCStatesMsg().write(state)]
        field.planetPosInMsg.subscribeTo(msgs[0])
        field.addSpacecraftToModel(msgs[1])
        sim.AddModelToTask("t", field)
        sim.InitializeSimulation()
        field.UpdateState(0)
        theirs = np.array(field.envOutMsgs[0].read().magField_N)
        worst = max(worst, float(np.max(np.abs(np.array(ours.field_N(r)) - theirs)) / np.linalg.norm(theirs)))
    record_worst(record_property, "tilted dipole vs Basilisk's centred dipole (relative)", worst, 1e-13)


def test_igrf14_equals_ppigrf(record_property):
    """IGRF-14 to degree 13 against ppigrf's geocentric igrf_gc (an independent implementation of
    the same coefficients: its own Legendre functions and time interpolation) at 25 random
    positions and times 1990-2030, in nT."""
    ppigrf = pytest.importorskip("ppigrf", reason="ppigrf is not installed (a test extra): the IGRF comparison "
                                                  "is skipped")
    rng = np.random.default_rng(1414)
    field = igrf.IgrfField("1990-01-01T00:00:00Z")
    worst = 0.0
    for _ in range(CASES):
        t = rng.uniform(0.0, 40 * 365.25 * 86400.0)
        r, theta, phi = 6371.2e3 + rng.uniform(0.0, 2000e3), rng.uniform(0.001, math.pi - 0.001), rng.uniform(-3, 3)
        g, h = field.gauss_coefficients(t)
        ours = igrf.field_spherical(r, theta, phi, g, h, 13)
        date = dt.datetime(1990, 1, 1) + dt.timedelta(seconds=t)
        theirs = [float(np.ravel(x)[0]) for x in ppigrf.igrf_gc(r / 1e3, math.degrees(theta), math.degrees(phi),
                                                                 date)]
        worst = max(worst, float(np.max(np.abs(np.array(ours) - theirs))))
    record_worst(record_property, "IGRF-14 vs ppigrf (nT)", worst, 1e-6)

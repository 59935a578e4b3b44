"""FMU `DisturbanceTorques` (instance `disturbances`): the environment's torques on the spacecraft.

Wraps components.attitude.disturbances.DisturbanceTorques: gravity gradient (from the inertia the
rigid body uses), aerodynamic drag and solar radiation pressure of up to 16 flat facets (the
co-rotating atmosphere's density from an orbit or Atmosphere FMU, the Sun from SunEphemeris, the
sunlit fraction from EarthShadow) and a residual magnetic dipole in the field B_N. Each source has
a switch. torque_B is their sum, for the rigid body's disturbance_torque_B input; force_N is the
drag plus SRP force. Stateless: every output depends directly on the inputs it is computed from.

The default facets, optical coefficients and dipole are the NEIGHBOR stack's
(components.mission.neighbor.FACETS, RESIDUAL_DIPOLE_B); a facet of area 0 is unused.
"""
from neighbor_fmu_support import NeighborSlave

from components.attitude import disturbances, rigid_body
from components.core.constants import MU_EARTH, OMEGA_EARTH_WGS84, WGS84_A
from components.core.names import element_names, matrix_names
from components.mission.neighbor import FACETS, RESIDUAL_DIPOLE_B

N = disturbances.MAX_FACETS
_TORQUES = {"gravity_gradient_torque_B": 0, "aerodynamic_torque_B": 3, "srp_torque_B": 9, "magnetic_torque_B": 15}


class DisturbanceTorques(NeighborSlave):
    description = ("Environmental disturbance torques: gravity gradient, faceted aerodynamic drag and solar "
                   "radiation pressure, residual magnetic dipole; their sum torque_B for the rigid body")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.inertia_parameters("Spacecraft mass (with the box edges: the inertia of the gravity-gradient torque, as "
                                "the rigid body's)")
        for source, text in (("gravity_gradient", "gravity-gradient torque 3 mu/r^5 r_B x J r_B"),
                             ("aerodynamic", "drag force and torque of the facets in the co-rotating atmosphere"),
                             ("solar_radiation", "solar radiation pressure force and torque of the facets"),
                             ("residual_dipole", "residual magnetic dipole torque m_B x B_B")):
            self.parameter(source, True, None, f"Compute the {text} (false: zero)", bool)
        self.parameter("mu", MU_EARTH, "m3/s2", "Earth's gravitational parameter, > 0")
        self.parameter("earth_rotation_rate", OMEGA_EARTH_WGS84, "rad/s",
                       "Rotation rate of the atmosphere about N's z axis (the Earth's)")
        self.parameter("solar_flux", disturbances.SOLAR_FLUX_1AU, "W/m2",
                       "Total solar irradiance at 1 AU (IAU 2015 nominal 1361), scaled by (1 AU / distance)^2, > 0")
        self.parameter_array("residual_dipole_B", list(RESIDUAL_DIPOLE_B), "A.m2",
                             "Residual magnetic dipole moment of the spacecraft in B")
        padded = list(FACETS) + [None] * (N - len(FACETS))
        self.parameter_array("facet_area", [f.area if f else 0.0 for f in padded], "m2",
                             "Facet area (0: no facet in this slot)")
        for i, (normal, centre) in enumerate(zip(matrix_names("facet_normal_B", N, 3),
                                                 matrix_names("facet_centre_B", N, 3))):
            f = padded[i]
            for j in range(3):
                self.parameter(normal[j], f.normal_B[j] if f else (1.0 if j == 0 else 0.0), "1",
                               f"Facet {i + 1} unit outward normal in B (component {j + 1})")
                self.parameter(centre[j], f.centre_B[j] if f else 0.0, "m",
                               f"Facet {i + 1} centre of pressure in B from the centre of mass at takeover "
                               f"(component {j + 1})")
        self.parameter_array("facet_Cd", [f.Cd if f else 2.2 for f in padded], "1",
                             "Facet drag coefficient, in [0, 10]")
        self.parameter_array("facet_specular", [f.specular if f else 0.0 for f in padded], "1",
                             "Facet specular reflection coefficient, in [0, 1]")
        self.parameter_array("facet_diffuse", [f.diffuse if f else 0.0 for f in padded], "1",
                             "Facet diffuse reflection coefficient, in [0, 1] (specular + diffuse <= 1)")

        position = self.input_array("r_BN_N", [WGS84_A + 420e3, 0.0, 0.0], "m",
                                    "Spacecraft position relative to Earth's centre in N (non-zero)")
        velocity = self.input_array("v_BN_N", [0.0, 7660.0, 0.0], "m/s", "Spacecraft velocity relative to N, in N")
        attitude = self.input_array("q_BN", [0.0, 0.0, 0.0, 1.0], "1",
                                    "Attitude quaternion of B relative to N, scalar last (normalized before use)")
        density = self.input("density", 0.0, "kg/m3", "Atmospheric density at the spacecraft (>= 0)")
        sun = self.input_array("r_SN_N", [disturbances.ASTRONOMICAL_UNIT, 0.0, 0.0], "m",
                               "Sun position relative to Earth's centre in N")
        sunlit = self.input("sunlit_fraction", 1.0, "1", "Fraction of the Sun's disk visible (EarthShadow), in [0, 1]")
        field = self.input_array("B_N", [0.0, 0.0, 0.0], "T", "Geomagnetic field at the spacecraft in N")
        com = self.input_array("center_of_mass_B", [0.0, 0.0, 0.0], "m",
                               "Centre of mass in B relative to the one at takeover (the rigid body's, as the tank "
                               "empties); 0: fixed")
        depends = {"gravity_gradient_torque_B": position + attitude,
                   "aerodynamic_torque_B": position + velocity + attitude + (density,) + com,
                   "srp_torque_B": position + attitude + sun + (sunlit,) + com,
                   "magnetic_torque_B": attitude + field}
        every = tuple(dict.fromkeys(sum(depends.values(), ())))
        out = lambda: self.feedthrough(self._evaluate)  # noqa: E731
        self.output_array("torque_B", 3, lambda: disturbances.DisturbanceTorques.total_torque(out()), "N.m",
                          "Sum of the disturbance torques about the centre of mass in B (the rigid body's "
                          "disturbance_torque_B)", depends_on=every)
        self.output_array("force_N", 3, lambda: disturbances.DisturbanceTorques.total_force_N(out()), "N",
                          "Aerodynamic plus solar-pressure force in N",
                          depends_on=tuple(dict.fromkeys(depends["aerodynamic_torque_B"] + depends["srp_torque_B"])))
        texts = {"gravity_gradient_torque_B": "Gravity-gradient torque in B",
                 "aerodynamic_torque_B": "Aerodynamic torque about the centre of mass in B",
                 "srp_torque_B": "Solar radiation pressure torque about the centre of mass in B",
                 "magnetic_torque_B": "Residual-dipole torque m_B x B_B in B"}
        for name, at in _TORQUES.items():
            self.output_array(name, 3, lambda at=at: out()[at:at + 3], "N.m", texts[name], depends_on=depends[name])
        self.output_array("aerodynamic_force_N", 3, lambda: out()[6:9], "N", "Aerodynamic drag force in N",
                          depends_on=depends["aerodynamic_torque_B"])
        self.output_array("srp_force_N", 3, lambda: out()[12:15], "N", "Solar radiation pressure force in N",
                          depends_on=depends["srp_torque_B"])
        # every step of the attitude loop reads torque_B after q_BN changed: one compiled call
        self.share_values()
        self._inputs_at = self.shared_indices((("r_BN_N", 3), ("v_BN_N", 3), ("q_BN", 4), ("density", 1),
                                               ("r_SN_N", 3), ("sunlit_fraction", 1), ("B_N", 3),
                                               ("center_of_mass_B", 3)))
        self._outputs_at = self.shared_indices((("torque_B", 3), ("force_N", 3), *((name, 3) for name in _TORQUES),
                                                ("aerodynamic_force_N", 3), ("srp_force_N", 3)))

    def build_model(self):
        v = self.values
        facets = disturbances.Facets(
            [[v[e] for e in row] for row in matrix_names("facet_normal_B", N, 3)],
            [v[e] for e in element_names("facet_area", N)],
            [[v[e] for e in row] for row in matrix_names("facet_centre_B", N, 3)],
            [v[e] for e in element_names("facet_Cd", N)], [v[e] for e in element_names("facet_specular", N)],
            [v[e] for e in element_names("facet_diffuse", N)])
        sources = [s for s in disturbances.SOURCES if v[s]]
        return disturbances.DisturbanceTorques(self.inertia(rigid_body.box_inertia), facets,
                                               self.vector("residual_dipole_B", 3), sources, v["mu"],
                                               v["solar_flux"], v["earth_rotation_rate"])

    def _evaluate(self):
        return self.model.compute(self.vector("r_BN_N", 3), self.vector("v_BN_N", 3), self.vector("q_BN", 4),
                                  self.input_value("density"), self.vector("r_SN_N", 3),
                                  self.input_value("sunlit_fraction"), self.vector("B_N", 3),
                                  self.vector("center_of_mass_B", 3))

    def publish(self):
        # the getters' values (NeighborSlave.publish) in one compiled call; an input out of range
        # takes the getters' path, which names it
        if self.model.publish_into(self.shared, self._inputs_at, self._outputs_at):
            super().publish()
            return
        self.mark_published()

    def do_step(self, current_time, step_size):
        self.publish_after_step()  # as every sharing wrapper: the outputs are fresh after a step
        return True

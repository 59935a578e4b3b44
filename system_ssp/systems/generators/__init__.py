"""The system generators: one module per family of systems, each with `generate(writer)`, which
writes its parameter sets (the values derived from the mission definition) through a
`system_ssp.ssp.writer.SystemWriter` and then each of its systems from its spec,
system_ssp/systems/specs/<name>.toml (`from_spec.write_system`).

The written files are committed (system_ssp/systems/); `python -m system_ssp.systems --check`
regenerates them into a temporary folder and fails on any difference, so the committed systems
always match their generators and the FMUs they were generated from.
"""
from . import (acs_modes, air_bearing, atmosphere, attitude_determination, cubesat_3u, deorbit, maneuvers,
               mission, sun_avoidance, sun_eclipse, sunline)

# name -> module, in the order they are written
GENERATORS = {
    "maneuvers": maneuvers,  # detumble, slew and the thesis validation cases
    "sun_avoidance": sun_avoidance,
    "sunline": sunline,
    "sun_eclipse": sun_eclipse,
    "attitude_determination": attitude_determination,
    "air_bearing": air_bearing,
    "acs_modes": acs_modes,
    "deorbit": deorbit,
    "atmosphere": atmosphere,
    "mission": mission,
    "cubesat_3u": cubesat_3u,  # the second reference spacecraft (components.mission.cubesat_3u)
}


def generate_all(writer, only=None):
    """Run every generator (or those named in `only`) into `writer`; returns the files written."""
    unknown = sorted(set(only or ()) - set(GENERATORS))
    if unknown:
        raise ValueError(f"unknown generator(s) {', '.join(unknown)}; known: {', '.join(GENERATORS)}")
    for name, module in GENERATORS.items():
        if only is None or name in only:
            module.generate(writer)
    return list(writer.written)

"""A shipped system written from its spec (system_ssp/systems/specs/<name>.toml)."""
from ...ssp.spec import compose
from ...ssp.writer import GeneratorError
from .. import PARAMETERS_DIR, SPECS_DIR


def write_system(writer, name):
    """<name>.ssd in the writer's folder from the shipped spec specs/<name>.toml, its components'
    connectors from the writer's FMUs and its parameter files the ones the generator has just
    written into the writer's parameters/ folder."""
    # a set another generator writes (spacecraft.ssv) is the committed one when only this one runs
    composition = compose(SPECS_DIR / f"{name}.toml", writer.fmu_dir, [writer.parameters, PARAMETERS_DIR],
                          SPECS_DIR)
    if composition.name != name:
        raise GeneratorError(f"{composition.spec_path}: system.name is {composition.name!r}, expected {name!r}")
    for stem, source in composition.ssv_files.items():
        if isinstance(source, tuple):  # values given in the spec itself
            writer.ssv(stem, *source)
    writer.ssd(name, composition.writer_spec)

"""The static side of one component of a loaded system: its SSD declaration, its FMU's model
description and the folder the FMU is extracted to."""
import copy

from fmpy import read_model_description

from .. import archive

from ..errors import SSPError
from ..ssp.fmi3_view import element_view
from ..ssp.interface import unit_definitions, variable_unit
from .names import near


class ComponentInfo:
    """Per System (not per run): one component's declaration, variables, units and output
    dependencies."""

    def __init__(self, index, decl, md, unzipdir):
        self.index = index
        self.name = decl.name
        self.decl = decl
        self.fmi3_md = self.fmi3_elements = None
        self.left_out = {}  # FMI 3.0 variables the master does not transfer -> why
        self.arrays = {}  # FMI 3.0 array variable -> its elements' names (row-major)
        if md.fmiVersion.startswith("3."):
            # the master sees an FMI 3.0 FMU through its element view (system_ssp.ssp.fmi3_view)
            variables, outputs, self.fmi3_elements, self.left_out = element_view(md)
            self.fmi3_md = md
            for v in variables:
                base, bracket, _ = v.name.partition("[")
                if bracket and self.fmi3_elements[v.valueReference].size > 1:
                    self.arrays.setdefault(base, []).append(v.name)
            md = copy.copy(md)
            md.modelVariables, md.outputs = variables, outputs
            self.md_view_vars = {v.valueReference: v for v in variables}
        self.md = md
        self.unzipdir = unzipdir
        self.vars = {v.name: v for v in md.modelVariables}
        self.unit_defs = unit_definitions(md)
        # output name -> set of input names it depends on directly (None = all inputs)
        self.deps = {}
        for unknown in md.outputs:
            d = unknown.dependencies
            self.deps[unknown.variable.name] = None if d is None else {v.name for v in d}
        self.inputs = [v.name for v in md.modelVariables if v.causality == "input"]

    def whole(self, name):
        """The elements of `name` connected whole: an FMI 3.0 array's, or the vector or matrix an
        FMI 2.0 FMU spells element by element (name[1] .., name[1,1] ..; ours: q_BN[1] ..
        q_BN[4]), in declaration order; None when `name` is neither."""
        if name in self.arrays:
            return self.arrays[name]
        if name in self.vars:
            return None
        prefix = name + "["
        elements = [v for v in self.vars if v.startswith(prefix) and v.endswith("]")]
        return elements or None

    def not_a_variable(self, var):
        """Why `var` is no variable of this component, for an error message that already said
        "has no variable 'var'": an FMI 3.0 variable the master does not transfer, or the names
        nearest to it."""
        if var in self.left_out:
            return (f": the FMU's variable is {self.left_out[var]}, which this master does not transfer (it connects "
                    "Float, Int, Boolean, String and Enumeration variables, arrays element by element)")
        return near(var, self.vars)

    def fmu_unit(self, v):
        return variable_unit(v)

    def depends_on_inputs(self, out_name, connected_inputs):
        d = self.deps.get(out_name, None)
        if out_name not in self.deps or d is None:
            return bool(self.inputs)
        return bool(d & connected_inputs) if connected_inputs is not None else bool(d)


def unsupported_fmu(md):
    """Why this master cannot run the FMU of model description `md` (FMPy's), or None: FMI 2.0
    and 3.0 co-simulation FMUs run (FMI 3.0 through system_ssp.master.fmi3).

    FMI 1.0 is refused rather than imported: it was superseded by FMI 2.0 in 2014, the tools our
    users export from (Dymola, OpenModelica, Simulink, 20-sim) all write FMI 2.0 or 3.0, and its
    co-simulation API differs in every call (instantiate, initialize, no state, no dependencies)."""
    kind = "co-simulation" if md.coSimulation is not None else "model-exchange"
    if md.fmiVersion == "2.0":
        if md.coSimulation is None:
            return ("is an FMI 2.0 model-exchange FMU; this master runs co-simulation FMUs (export it for "
                    "co-simulation, with its own solver)")
        return None
    if md.fmiVersion.startswith("3."):
        if md.coSimulation is None:
            return (f"is an FMI {md.fmiVersion} {kind} FMU; this master runs co-simulation FMUs (export it for "
                    "co-simulation, with its own solver)")
        return None
    if md.fmiVersion.startswith("1."):
        return (f"is an FMI {md.fmiVersion} {kind} FMU; this master runs FMI 2.0 and 3.0 co-simulation FMUs and "
                "does not import FMI 1.0 (superseded in 2014): export it as FMI 2.0 or 3.0")
    return (f"is an FMI {md.fmiVersion} {kind} FMU; this master runs FMI 2.0 and 3.0 co-simulation FMUs")


def load_components(desc, extract_root, namer, validate):
    """[ComponentInfo] for the SSD's components: model descriptions read (and schema-checked
    when `validate`), FMUs extracted under `extract_root`, connectors checked against the FMUs."""
    comps = []
    for i, decl in enumerate(desc.components):
        if not decl.fmu_path.is_file():
            raise SSPError(f"{decl.origin}: component {decl.name!r}: FMU file not found "
                           f"(source={decl.source!r}, tried {namer(decl.fmu_path)}); the product's "
                           "systems are packed with their FMUs into the build folder by `neighbor-cosim build` (python "
                           "build_fmus.py in a checkout); name one by its name, e.g. `detumble`")
        unzipdir = str(archive.extract(decl.fmu_path, extract_root / f"{i}_{decl.name}",
                                       f"component {decl.name!r}: {namer(decl.fmu_path)}"))
        try:
            md = read_model_description(unzipdir, validate=validate)
        except Exception as exc:  # fmpy raises various exceptions for broken FMUs
            raise SSPError(f"component {decl.name!r}: cannot read the model description of "
                           f"{namer(decl.fmu_path)}: {exc}") from None
        refusal = unsupported_fmu(md)
        if refusal:
            raise SSPError(f"component {decl.name!r}: {namer(decl.fmu_path)} {refusal}")
        info = ComponentInfo(i, decl, md, unzipdir)
        for cname, conn in decl.connectors.items():
            v = info.vars.get(cname)
            if v is None and info.whole(cname):  # an array connector: its elements' type is checked
                v = info.vars[info.whole(cname)[0]]
            if v is None:
                raise SSPError(f"{conn.origin}: connector {cname!r} of component {decl.name!r} has no matching "
                               f"variable in {namer(decl.fmu_path)}{info.not_a_variable(cname)}")
            if conn.type and conn.type != v.type and not (conn.type == "Integer" and v.type == "Enumeration") \
                    and not (info.fmi3_md is not None and _fmi3_connector_type(conn.type, info, v)):
                raise SSPError(f"{conn.origin}: connector {decl.name}.{cname} is declared {conn.type} but the "
                               f"FMU variable is {v.type}")
        comps.append(info)
    return comps


def _fmi3_connector_type(connector_type, info, v):
    """An SSP connector's type matches an element of an FMI 3.0 FMU's view: the master's type, or
    the FMI 3.0 type itself (SSP 2.0 connectors name Float64, Int32, ...)."""
    fmi3_type = info.fmi3_elements[v.valueReference].type
    return connector_type == fmi3_type or connector_type in ("Real", "Integer") and v.type == connector_type

"""The static side of one component of a loaded system: its SSD declaration, its FMU's model
description and the folder the FMU is extracted to."""
import copy
import logging
import os

from lxml import etree

from .. import archive

from ..errors import SSPError
from ..ssp import model_description
from ..ssp.fmi3_view import element_view
from ..ssp.interface import unit_definitions, variable_unit
from .names import near

LOG = logging.getLogger("system_ssp.master")


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
        self.fmi1 = md.fmiVersion.startswith("1.")
        self.unzipdir = unzipdir
        self.vars = {v.name: v for v in md.modelVariables}
        self.unit_defs = unit_definitions(md)
        # output name -> set of input names it depends on directly (None = all inputs); an output
        # not in it depends on all inputs too (FMI 2.0 and 3.0 ModelStructure; FMI 1.0 DirectDependency)
        if self.fmi1:
            self.deps, variable_step = fmi1_structure(unzipdir)
            md.coSimulation.canHandleVariableCommunicationStepSize = variable_step  # FMPy reads it as False
        else:
            self.deps = {}
            for unknown in md.outputs:
                d = unknown.dependencies
                self.deps[unknown.variable.name] = None if d is None else {v.name for v in d}
        self.inputs = [v.name for v in md.modelVariables if v.causality == "input"]
        outputs = [v.name for v in md.modelVariables if v.causality == "output"]
        # the outputs the FMU does not say the dependencies of: taken to depend on every input
        self.undeclared = [o for o in outputs if self.deps.get(o) is None] if self.inputs else []

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


def fmi1_structure(unzipdir):
    """What FMPy does not read of an FMI 1.0 FMU's model description: {output: set of the inputs
    it depends on directly}, from the DirectDependency elements of its outputs (an output without
    one depends on every input, FMI 1.0 section 2.10, and is left out), and whether its
    Capabilities say canHandleVariableCommunicationStepSize (nc:Schedule needs it)."""
    root = etree.parse(os.path.join(unzipdir, "modelDescription.xml")).getroot()
    deps = {}
    for sv in root.iterfind("ModelVariables/ScalarVariable"):
        direct = sv.find("DirectDependency")
        if sv.get("causality") == "output" and direct is not None:
            deps[sv.get("name")] = {(n.text or "").strip() for n in direct.iterfind("Name")}
    capabilities = root.find("Implementation/*/Capabilities")
    variable_step = capabilities is not None and capabilities.get("canHandleVariableCommunicationStepSize") in (
        "true", "1")
    return deps, variable_step


def unsupported_fmu(md):
    """Why this master cannot run the FMU of model description `md` (FMPy's), or None: FMI 1.0,
    2.0 and 3.0 co-simulation FMUs run (FMI 1.0 through system_ssp.master.fmi1, FMI 3.0 through
    system_ssp.master.fmi3)."""
    if not md.fmiVersion.startswith(("1.", "2.", "3.")):
        return f"is an FMI {md.fmiVersion} FMU; this master runs FMI 1.0, 2.0 and 3.0 co-simulation FMUs"
    if md.coSimulation is None:
        return (f"is an FMI {md.fmiVersion} model-exchange FMU; this master runs co-simulation FMUs (export it for "
                "co-simulation, with its own solver)")
    return None


def undeclared_dependencies_warning(info, label):
    """The one warning for an FMU with inputs that does not declare on which of them some of its
    outputs depend, or None."""
    if not info.undeclared:
        return None
    where = "DirectDependency" if info.fmi1 else ("ModelStructure/Outputs" if not info.fmi3_md else "ModelStructure")
    some = ", ".join(info.undeclared[:4]) + (f" and {len(info.undeclared) - 4} more" if len(info.undeclared) > 4
                                            else "")
    return (f"{label}: declares no output dependencies ({where}) for {len(info.undeclared)} of its outputs ({some}): "
            "each is taken to depend directly on every input, so Gauss-Seidel steps the components feeding it first "
            "and a loop through it is an algebraic loop")


def load_components(desc, extract_root, namer, validate, strict=False, warnings=None):
    """[ComponentInfo] for the SSD's components: model descriptions read (and checked when
    `validate`: leniently, a warning naming what was let through, unless `strict`; see
    system_ssp.ssp.model_description), FMUs extracted under `extract_root`, connectors checked
    against the FMUs. Every warning is logged and appended to `warnings`."""
    comps = []
    for i, decl in enumerate(desc.components):
        if not decl.fmu_path.is_file():
            raise SSPError(f"{decl.origin}: component {decl.name!r}: FMU file not found "
                           f"(source={decl.source!r}, tried {namer(decl.fmu_path)}); the product's "
                           "systems are packed with their FMUs into the build folder by `neighbor-cosim build` (python "
                           "build_fmus.py in a checkout); name one by its name, e.g. `detumble`")
        label = f"component {decl.name!r}: {namer(decl.fmu_path)}"
        unzipdir = str(archive.extract(decl.fmu_path, extract_root / f"{i}_{decl.name}", label))
        md, warning = model_description.read(unzipdir, label, validate, strict)
        refusal = unsupported_fmu(md)
        if refusal:
            raise SSPError(f"{label} {refusal}")
        _refuse_duplicate_names(md, label)
        info = ComponentInfo(i, decl, md, unzipdir)
        for text in (warning, undeclared_dependencies_warning(info, label)):
            if text:
                LOG.warning("%s", text)
                if warnings is not None:
                    warnings.append(text)
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


def _refuse_duplicate_names(md, label):
    """Two variables of one name: no connection, value or recorded column could say which is meant,
    so no option runs it (FMPy's validation finds it too; this also holds without validation)."""
    first = {}
    for v in md.modelVariables:
        if v.name in first:
            raise SSPError(f"{label}: its modelDescription.xml declares the variable {v.name!r} twice (lines "
                           f"{first[v.name].sourceline} and {v.sourceline}): a connection, a value or a result column "
                           "could not say which is meant")
        first[v.name] = v


def _fmi3_connector_type(connector_type, info, v):
    """An SSP connector's type matches an element of an FMI 3.0 FMU's view: the master's type, or
    the FMI 3.0 type itself (SSP 2.0 connectors name Float64, Int32, ...)."""
    fmi3_type = info.fmi3_elements[v.valueReference].type
    return connector_type == fmi3_type or connector_type in ("Real", "Integer") and v.type == connector_type

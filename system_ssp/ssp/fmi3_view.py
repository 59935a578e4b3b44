"""FMI 3.0 model descriptions seen as the master and the interface tools see an FMU: the element
view. Scalars as themselves; an array variable as its elements `name[1]` .. (a matrix
`name[1,1]` .., row-major as FMI 3.0 serializes arrays; sizes from `Dimension start` or a
structural parameter's start value); types as the master transfers them (Float64, Float32 ->
Real; Int8 .. UInt64 -> Integer; Enumeration, Boolean, String). Binary and Clock variables, the
independent variable and structural parameters are left out, each with the reason. An FMU and
its FMI 2.0 twin (ours spell arrays element by element) have the same view."""
from fmpy.model_description import ModelVariable, Unknown
import numpy as np

KIND = {"Float64": "Real", "Float32": "Real", "Int8": "Integer", "UInt8": "Integer", "Int16": "Integer",
        "UInt16": "Integer", "Int32": "Integer", "UInt32": "Integer", "Int64": "Integer", "UInt64": "Integer",
        "Boolean": "Boolean", "String": "String", "Enumeration": "Enumeration"}
NOT_TRANSFERRED = {"Binary": "a Binary variable", "Clock": "a Clock"}


class Element:
    """Where an element of the view lives in the FMU: its variable's type and value reference,
    its offset in the variable's values and the variable's number of values."""
    __slots__ = ("type", "vr", "offset", "size")

    def __init__(self, type_, vr, offset, size):
        self.type, self.vr, self.offset, self.size = type_, vr, offset, size


def _size(dimension):
    if dimension.start is not None:
        return int(dimension.start)
    return int(dimension.variable.start)  # a structural parameter's start value


def _index_names(name, shape):
    """name[1] .. (row-major) for an array of `shape`."""
    return [f"{name}[{','.join(str(i + 1) for i in ix)}]" for ix in np.ndindex(*shape)]


def element_view(md):
    """(variables, outputs, {element value reference: Element}, {name: why it is not in the
    view}) of FMI 3.0 model description `md`: ModelVariables with FMI 2.0 type names (Real,
    Integer, ...) and value references numbering the elements, and the outputs' Unknowns over
    them."""
    variables, elements, left_out, of_var = [], {}, {}, {}
    for v in md.modelVariables:
        if v.causality == "independent":
            left_out[v.name] = "the independent variable (time)"
            continue
        if v.causality == "structuralParameter":
            left_out[v.name] = "a structural parameter (set in configuration mode, which this master does not use)"
            continue
        if v.type not in KIND:
            left_out[v.name] = NOT_TRANSFERRED.get(v.type, f"of type {v.type}")
            continue
        shape = tuple(_size(d) for d in v.dimensions)
        size = int(np.prod(shape)) if shape else 1
        names = _index_names(v.name, shape) if shape else [v.name]
        starts = None if v.start is None else str(v.start).split() if v.type != "String" else [v.start] * size
        if starts is not None and len(starts) != size:
            starts = [starts[0]] * size if len(starts) == 1 else None
        of_var[v.name] = []
        for offset, name in enumerate(names):
            ev = len(elements)
            elements[ev] = Element(v.type, v.valueReference, offset, size)
            element = ModelVariable(name=name, valueReference=ev, type=KIND[v.type], description=v.description,
                                    causality=v.causality, variability=v.variability, initial=v.initial,
                                    declaredType=v.declaredType, unit=v.unit, displayUnit=v.displayUnit,
                                    min=v.min, max=v.max, nominal=v.nominal,
                                    start=None if starts is None else starts[offset])
            variables.append(element)
            of_var[v.name].append(element)
    outputs = []
    for unknown in md.outputs:
        deps = None
        if unknown.dependencies is not None:
            deps = [e for d in unknown.dependencies for e in of_var.get(d.name, [])]
        for element in of_var.get(unknown.variable.name, []):
            outputs.append(Unknown(variable=element, dependencies=deps))
    return variables, outputs, elements, left_out

"""Reading an FMU's modelDescription.xml as the tools that export FMUs need it read.

FMPy's validation refuses a model description at its first problem. Some problems do not change
what a co-simulation computes, and tools that users cannot change write them (Simulink's FMI Kit
leaves out the variability of Enumeration and Integer variables, which then defaults to
"continuous"); FMPy's `simulate_fmu(validate=False)` and OMSimulator run such FMUs. The master
reads them leniently: each problem of the list below is named in one warning per FMU and the run
goes on; any other problem, or any problem at all with `strict`, refuses the FMU in one line that
names the option that changes it (`--no-validate` skips the checks, `--strict` refuses every
problem). docs/interoperability.md, "FMUs other tools wrote", keeps the same list.
"""
import re
from typing import List, NamedTuple, Optional, Tuple

from fmpy import read_model_description
from fmpy.model_description import ValidationError
from fmpy.validation import validate_model_description

from ..errors import SSPError, option


class Leniency(NamedTuple):
    pattern: "re.Pattern[str]"  # matches FMPy's text of the problem
    effect: str  # what the master does instead of refusing, for the warning


# The problems read leniently: none changes a value the master passes or a variable it may set.
LENIENT = (
    Leniency(re.compile(r'is of type (Integer|Boolean|Enumeration|String|Int\w*|UInt\w*) and must have variability '
                        r'!= "continuous"'),
             "read as discrete (FMI 2.0 gives a variable without a variability attribute \"continuous\", which "
             "only Reals may be; Simulink's FMI Kit writes Enumerations so)"),
    Leniency(re.compile(r'has no start value'),
             "the FMU's own initial value stands until a connection or a parameter set gives one"),
    Leniency(re.compile(r'^The unit "[^"]*" of variable'),
             "the unit name is kept; a conversion it needs takes its definition from the system's units or the "
             "product's unit table, and is refused where none defines it"),
    Leniency(re.compile(r'^The display unit'), "display units are not used"),
    Leniency(re.compile(r'has initial="calculated" but provides a start value'),
             "the start value is ignored (the master never sets a calculated variable)"),
    Leniency(re.compile(r'has causality="independent" but provides a start value'),
             "the start value is ignored (the master passes the time itself)"),
)


_DUPLICATE = re.compile(r'^The variable name "[^"]*" \(line \d+\) is not unique')


class Description(NamedTuple):
    md: object  # fmpy's ModelDescription
    warning: Optional[str]  # the one warning of a leniently read FMU, or None


def lenient_effect(problem: str) -> Optional[str]:
    """What the master does about FMPy's `problem` text when it reads leniently; None: refused."""
    for leniency in LENIENT:
        if leniency.pattern.search(problem):
            return leniency.effect
    return None


def read(source: str, label: str, validate: bool = True, strict: bool = False) -> Description:
    """The model description of the FMU at `source` (an .fmu or its extracted folder); `label`
    names it in messages ("component 'sw': resources/OpenSW.fmu"). SSPError for a description
    that cannot be read, or is refused (see the module's text)."""
    try:
        return Description(read_model_description(source, validate=validate), None)
    except ValidationError as exc:
        problems: List[str] = list(exc.problems)
    except Exception as exc:  # fmpy raises various exceptions for broken FMUs
        raise SSPError(f"{label}: cannot read the model description: {_one_line(str(exc))}") from None
    listed = "; ".join(_one_line(p) for p in problems)
    if strict:
        raise SSPError(f"{label}: modelDescription.xml does not conform to the FMI standard: {listed} (refused "
                       f"under {option('--strict', 'strict=True')}; without it, problems that do not change the "
                       "run are read with a warning)")
    md, semantic = _semantic_problems(source)
    skip = option("--no-validate", "validate=False")
    if md is None or semantic != problems:  # the XML schema refused it: FMPy cannot be trusted to read it
        raise SSPError(f"{label}: modelDescription.xml does not follow the FMI schema: {listed} ({skip} reads it "
                       "without the checks)")
    # two variables of one name: left to the master's own check, which refuses them whatever the
    # options (system_ssp.master.components), so no advice here names an option that cannot help
    problems = [p for p in problems if not _DUPLICATE.search(p)]
    refused = [p for p in problems if lenient_effect(p) is None]
    if refused:
        raise SSPError(f"{label}: modelDescription.xml does not conform to the FMI standard: "
                       f"{'; '.join(_one_line(p) for p in refused)} (this would make the run wrong; {skip} reads it "
                       "without the checks)")
    if not problems:
        return Description(md, None)
    shown = "; ".join(f"{_one_line(p).rstrip('.')} ({lenient_effect(p)})" for p in problems)
    return Description(md, f"{label}: read leniently, as other tools read it ({option('--strict', 'strict=True')} "
                           f"refuses it): its modelDescription.xml breaks the FMI standard where the run does not "
                           f"depend on it: {shown}")


def _semantic_problems(source: str) -> Tuple[Optional[object], List[str]]:
    """(the description read without the schema, FMPy's problems with it), or (None, []) when
    FMPy cannot read it at all that way."""
    try:
        md = read_model_description(source, validate=False)
    except Exception:
        return None, []
    return md, list(validate_model_description(md))


def _one_line(text: str) -> str:
    return " ".join(str(text).split())

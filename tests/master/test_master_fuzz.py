"""Property-based hardening (issue 15): the shipped detumble system's SSD and parameter sets,
mutated as a careless or hostile user might (elements deleted, duplicated or retyped, attributes
deleted, numbers made NaN/inf/huge/negative/zero, names changed), either run or are refused with
an SSPError that says where: a file and line, or the component. Never another exception type, a
hang or a crash. Half the examples skip the XML schemas, so that the master's own checks meet
what the schemas would have caught. Each example loads the system and runs 4 steps (about 0.1 s)."""
import re
import shutil

from hypothesis import HealthCheck, given, settings, strategies as st
from lxml import etree
import pytest

import system_ssp
from system_ssp import SSPError
from system_ssp.master.planning import make_plan

from paths import SYSTEMS

SSD = SYSTEMS / "detumble.ssd"
PARAMETER_FILES = ["detumble_gains.ssv", "thrusters.ssv", "detumble_initial_state.ssv", "spacecraft.ssv"]
FMUS = ["DetumbleController", "RcsThrusters", "RigidBody"]
NUMBERS = ["nan", "NaN", "inf", "-inf", "1e308", "-1", "0", "-0.0", "1e-300", "abc", "", "  2 ", "0x10", "1,5"]
NAMES = ["", "x", "detumble", "dynamics.q0[9]", "Kp[0]", "ghost", " ", "thrusters", "a.b.c", "ü"]
# Where an SSPError must point: file and line (just the file for a whole-file problem such as a
# system without components), or the component or variable it is about
WHERE = re.compile(r"\.(ssd|ssv|ssm)(:\d+)?: |component '|\b(detumble|thrusters|dynamics)\.[A-Za-z_]")


@pytest.fixture(scope="module")
def system_folder(ssp_paths, tmp_path_factory):
    """A folder with the detumble system's FMUs and parameter files (the SSD is written per example)."""
    folder = tmp_path_factory.mktemp("fuzz")
    (folder / "resources").mkdir()
    (folder / "parameters").mkdir()
    fmus = ssp_paths["detumble"].parent.parent / "fmus"
    for name in FMUS:
        shutil.copy(fmus / f"{name}.fmu", folder / "resources" / f"{name}.fmu")
    for name in PARAMETER_FILES:
        shutil.copy(SYSTEMS / "parameters" / name, folder / "parameters" / name)
    return folder


def _mutate(root, data):
    """Apply 1 to 3 random mutations to the XML tree `root` (in place)."""
    for _ in range(data.draw(st.integers(1, 3), label="mutations")):
        elements = [e for e in root.iter() if isinstance(e.tag, str)]
        el = data.draw(st.sampled_from(elements), label="element")
        what = data.draw(st.sampled_from(["delete", "duplicate", "retype", "attr-delete", "attr-number",
                                          "attr-name", "text"]), label="mutation")
        parent = el.getparent()
        if what == "delete" and parent is not None:
            parent.remove(el)
        elif what == "duplicate" and parent is not None:
            parent.insert(parent.index(el), etree.fromstring(etree.tostring(el)))
        elif what == "retype":
            qname = etree.QName(el)
            local = data.draw(st.sampled_from(["Real", "Integer", "Boolean", "String", "Enumeration", "Connector",
                                               "Parameter", "Component", "Unit", "Order"]), label="tag")
            el.tag = f"{{{qname.namespace}}}{local}" if qname.namespace else local
        elif what.startswith("attr") and el.attrib:
            key = data.draw(st.sampled_from(sorted(el.attrib)), label="attribute")
            if what == "attr-delete":
                del el.attrib[key]
            elif what == "attr-number":
                el.attrib[key] = data.draw(st.sampled_from(NUMBERS), label="number")
            else:
                el.attrib[key] = data.draw(st.sampled_from(NAMES + NUMBERS), label="name")
        elif what == "text":
            el.text = data.draw(st.sampled_from(NAMES + NUMBERS), label="text")


@settings(max_examples=200, deadline=None, derandomize=True, suppress_health_check=list(HealthCheck))
@given(data=st.data())
def test_mutated_system_runs_or_says_where(system_folder, data):
    target = data.draw(st.sampled_from(["SystemStructure.ssd"] + [f"parameters/{n}" for n in PARAMETER_FILES]),
                       label="file")
    for name in PARAMETER_FILES:  # the originals, then the one mutated
        shutil.copy(SYSTEMS / "parameters" / name, system_folder / "parameters" / name)
    shutil.copy(SSD, system_folder / "SystemStructure.ssd")
    path = system_folder / target
    tree = etree.parse(str(path))
    _mutate(tree.getroot(), data)
    path.write_bytes(etree.tostring(tree, xml_declaration=True, encoding="UTF-8"))
    validate = data.draw(st.booleans(), label="validate")  # without the schemas: our own checks alone
    try:
        with system_ssp.System(system_folder / "SystemStructure.ssd", validate=validate) as system:
            make_plan(system)  # the SSD's own experiment and master settings, checked without running them
            system.run(stop_time=0.06)
    except SSPError as exc:
        assert WHERE.search(str(exc)), f"{type(exc).__name__} does not say where: {exc}"

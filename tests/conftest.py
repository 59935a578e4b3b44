"""Shared fixtures: the product's FMUs and SSPs, built (incrementally) once per session."""
import ctypes
from pathlib import Path

from fmpy.fmi1 import printLogMessage
from fmpy.fmi2 import fmi2CallbackFunctions, fmi2CallbackLoggerTYPE
from fmpy.logging import addLoggerProxy
import pytest

# FMPy routes the messages of every FMU instance that uses its logger proxy (the default one
# included) to the Python logger registered last (one global in its logging library). A test that
# passes a logger of its own to fmpy.simulate_fmu leaves that global pointing at a callback that
# is gone once the call returns, and the next FMU message crashes the process. After every test
# the global is pointed at a logger that lives as long as the session.
_FMPY_CALLBACKS = fmi2CallbackFunctions()
_FMPY_LOGGER = fmi2CallbackLoggerTYPE(printLogMessage)


@pytest.fixture(autouse=True)
def fmpy_logger_alive():
    yield
    _FMPY_CALLBACKS.logger = _FMPY_LOGGER  # addLoggerProxy swaps it for its proxy: set it again
    addLoggerProxy(ctypes.byref(_FMPY_CALLBACKS))


@pytest.fixture(scope="session")
def built():
    """(fmu paths by name, ssp paths by system name) from build_fmus.build_all()."""
    import build_fmus

    fmus, ssps = build_fmus.build_all(verbose=False)
    return {p.stem: p for p in fmus}, {p.stem: p for p in ssps}


@pytest.fixture(scope="session")
def build_one(tmp_path_factory):
    """build_one("neighbor_orbit.py") -> path of that one wrapper's FMU, built once per session
    into a private folder (for FMU tests that need no other FMU and no SSP)."""
    import build_fmus

    cache = {}

    def build(script_name):
        if script_name not in cache:
            dest = tmp_path_factory.mktemp(Path(script_name).stem)
            cache[script_name] = build_fmus.build_fmu(build_fmus.FMU_SOURCES / script_name, dest)
        return cache[script_name]

    return build


@pytest.fixture(scope="session")
def fmu_paths(built):
    return built[0]


@pytest.fixture(scope="session")
def fmu3_paths(built):
    """The same FMUs as FMI 3.0 (build/fmus3), built with the FMI 2.0 ones."""
    folder = next(iter(built[0].values())).parent.parent / "fmus3"
    return {name: folder / f"{name}.fmu" for name in built[0]}


@pytest.fixture(scope="session")
def ssp3_paths(built):
    """The same systems packed with the FMI 3.0 FMUs (build/ssp3)."""
    folder = next(iter(built[1].values())).parent.parent / "ssp3"
    return {name: folder / f"{name}.ssp" for name in built[1]}


@pytest.fixture(scope="session")
def ssp_paths(built):
    return built[1]


@pytest.fixture(scope="session")
def thesis_cases(ssp_paths):
    """The thesis' detumble and slew cases (euler), run once for every test that reads them."""
    from system_ssp.neighbor import thesis

    return thesis.run_cases(ssp_paths["detumble"].parent, "euler")


@pytest.fixture(scope="session")
def mission_420km(ssp_paths, tmp_path_factory):
    """(summary, result, results folder) of one 420 km mission run (orbit-averaged, about a minute)."""
    from system_ssp.neighbor import mission

    out = tmp_path_factory.mktemp("mission")
    summary, result = mission.run_mission("420km", "averaged", ssp_dir=ssp_paths["neighbor_mission"].parent, out=out,
                                          gnc="thesis", requirements=mission.REQUIREMENTS)
    return summary, result, out


# The longest tests first: with pytest-xdist they run beside the many short ones instead of alone
# at the end (the ten dispersed missions are the suite's critical path)
LONG_FIRST = ("tests/systems/test_mission_dispersion.py", "tests/systems/test_mission_system.py",
              "tests/systems/test_budgets.py")

# The validation table's guard: the test node ids that ran (their reports reach this process,
# also from pytest-xdist's workers) and, per published number, the ids of the tests that checked
# it (system_ssp.neighbor.validation.CHECKED, filled in the process that ran the test: a worker
# sends its own at its end)
RAN = set()
CHECKED_BY_WORKERS = {}


def pytest_collection_modifyitems(config, items):
    items.sort(key=lambda item: 0 if item.nodeid.startswith(LONG_FIRST) else 1)  # stable: the rest keep their order


# What the comparisons with other tools measured (a test's record_property("worst difference",
# text)), printed at the end of the run, also from pytest-xdist's workers
WORST_DIFFERENCES = []


def pytest_runtest_logreport(report):
    if report.when == "call":
        RAN.add(report.nodeid.split("[")[0])
        WORST_DIFFERENCES.extend(value for key, value in report.user_properties if key == "worst difference")


def pytest_terminal_summary(terminalreporter):
    if WORST_DIFFERENCES:
        terminalreporter.section("worst differences against the reference implementations")
        for line in sorted(WORST_DIFFERENCES):
            terminalreporter.line(line)


@pytest.hookimpl(optionalhook=True)
def pytest_testnodedown(node, error):
    """pytest-xdist: a worker's checked numbers, merged here."""
    for key, nodeids in getattr(node, "workeroutput", {}).get("validation_checked", {}).items():
        CHECKED_BY_WORKERS.setdefault(key, set()).update(nodeids)


def pytest_sessionfinish(session, exitstatus):
    """The validation table's guard: every published number whose guarding test ran in this
    session must have been checked by that test (system_ssp.neighbor.validation.assert_reproduces)."""
    from system_ssp.neighbor import validation

    if session.config.option.collectonly:
        return  # nothing ran (pytest --co)
    workeroutput = getattr(session.config, "workeroutput", None)
    if workeroutput is not None:  # a pytest-xdist worker: the controller checks
        workeroutput["validation_checked"] = {key: sorted(ids) for key, ids in validation.CHECKED.items()}
        return
    checked = {key: set(ids) for key, ids in validation.CHECKED.items()}
    for key, ids in CHECKED_BY_WORKERS.items():
        checked.setdefault(key, set()).update(ids)
    missing = []
    for number in validation.NUMBERS:
        if number.test not in RAN:
            continue  # a partial run (-k, one file): not this session's business
        if not any(nodeid.split("[")[0] == number.test for nodeid in checked.get(number.key, ())):
            missing.append(f"{number.key} (by {number.test})")
    if missing:
        session.config.get_terminal_writer().line(
            "validation table: not checked by the test that guards it: " + ", ".join(missing), red=True)
        session.exitstatus = 1

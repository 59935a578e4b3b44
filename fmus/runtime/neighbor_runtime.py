"""The Python side of a neighbor-cosim FMU's binary (neighbor_fmi2.c): loads the model.

The binary executes this file from the FMU's resources into a module of its own, named after a
hash of this code and the FMU's GUID (it is never imported, so the loaders of different FMU builds
cannot collide; a library loaded again reuses it) and calls `instantiate`, `reset`,
`drain` and `describe`. The model's code is one package with a name private to the FMU build
(resources/<package>/, named in neighbor_runtime.txt): two FMUs, or two builds of one FMU, in one
process never share code or data; two instances of the same build share the loaded modules.
"""
import importlib
import importlib.util
import os
import site
import sys
import traceback

NONE = None
# Errors after which no instance of the interpreter can be trusted: fmi2Fatal. Everything else
# (a bad parameter or input, a model error) is fmi2Error for the instance that raised it.
FATAL = (MemoryError, SystemError, RecursionError)
EXPECTED = (ValueError, TypeError, ImportError, KeyError, ArithmeticError)


def _config(resources):
    """neighbor_runtime.txt as {key: [values]} (key=value lines)."""
    cfg = {}
    with open(os.path.join(resources, "neighbor_runtime.txt"), encoding="utf-8") as f:
        for line in f:
            key, sep, value = line.rstrip("\r\n").partition("=")
            if sep:
                cfg.setdefault(key, []).append(value)
    return cfg


def _make_packages_importable(cfg):
    """In an interpreter the binary started: the folders of NEIGHBOR_FMU_PYTHONPATH, then the
    site-packages of the environment the FMU was built in (where they exist, and only for the
    Python version it was built with: another version cannot load their compiled modules)."""
    extra = [p for p in os.environ.get("NEIGHBOR_FMU_PYTHONPATH", "").split(os.pathsep) if p]
    here = f"{sys.version_info[0]}.{sys.version_info[1]}"
    built = cfg.get("site_packages", []) if cfg.get("python_version", [""])[0] == here else []
    for folder in extra + built:
        if os.path.isdir(folder) and folder not in sys.path:
            site.addsitedir(folder)


def _package(resources, name):
    """Import the FMU's private package from this extraction of the FMU. When the same build was
    loaded before (maybe from a folder that is gone now), its modules stay and its packages look
    in this extraction first for modules not imported yet."""
    folder = os.path.join(resources, name)
    package = sys.modules.get(name)
    if package is None:
        spec = importlib.util.spec_from_file_location(name, os.path.join(folder, "__init__.py"),
                                                      submodule_search_locations=[folder])
        package = importlib.util.module_from_spec(spec)
        sys.modules[name] = package
        try:
            spec.loader.exec_module(package)
        except BaseException:
            del sys.modules[name]
            raise
        return package
    for module_name, module in list(sys.modules.items()):
        if module_name == name or module_name.startswith(name + "."):
            path = getattr(module, "__path__", None)
            if path is not None:
                here = os.path.join(folder, *module_name.split(".")[1:])
                module.__path__ = [here] + [p for p in path if p != here and os.path.isdir(p)]
    return package


def instantiate(resources, instance_name, guid, visible, embedded, logging_on):
    """The model's slave object for one FMU instance."""
    cfg = _config(resources)
    built_guid = cfg.get("guid", [""])[0]
    if guid != built_guid:
        raise ValueError(f"fmuGUID {guid!r} is not this FMU's GUID {built_guid!r}: the model description "
                         "and the binary come from different builds")
    if embedded:
        _make_packages_importable(cfg)
    version = sys.version.split()[0]
    try:
        import numpy
    except ImportError as exc:
        raise ImportError(
            f"the model needs numpy, which Python {version} (prefix {sys.prefix}) cannot import ({exc}): install "
            f"it for that Python (python{sys.version_info[0]}.{sys.version_info[1]} -m pip install numpy) or set "
            "NEIGHBOR_FMU_PYTHONPATH to a site-packages folder that has it") from None
    package, module, class_name = cfg["slave"][0].split()
    _package(resources, package)
    cls = getattr(importlib.import_module(f"{package}.{module}"), class_name)
    kwargs = dict(instance_name=instance_name, resources=resources, visible=bool(visible))
    slave = cls(**kwargs)
    slave._neighbor_init = kwargs
    host = "a Python this FMU started" if embedded else "the Python already running in this process"
    slave.log(f"{cls.__name__} in {host}: Python {version} ({sys.prefix}), numpy {numpy.__version__}")
    return slave


def reset(slave):
    """fmi2Reset: the slave as fmi2Instantiate left it (the binary keeps its log queue)."""
    queue = slave.log_queue
    slave.__init__(**slave._neighbor_init)
    queue.extend(slave.log_queue)
    slave.log_queue = queue


def drain(slave):
    """The queued messages as (status, category, text), and the queue emptied."""
    queue = slave.log_queue
    out = [(int(m.status), str(m.category), str(m.msg)) for m in queue]
    del queue[:]
    return out


def describe(exc_type, exc, tb, call):
    """(FMI status, message) for an exception raised in `call`: the exception's text, and where it
    was raised when it is not an expected kind of error."""
    status = 4 if isinstance(exc, FATAL) else 3
    if exc_type is None:
        return status, f"{call} failed"
    text = f"{exc_type.__name__}: {exc}" if str(exc) else exc_type.__name__
    if not isinstance(exc, EXPECTED) and tb is not None:
        frame = traceback.extract_tb(tb)[-1]
        text += f" (at {os.path.basename(frame.filename)}:{frame.lineno} in {frame.name})"
    return status, f"{call}: {text}"

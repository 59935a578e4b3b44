"""The Python side of a neighbor-cosim FMU's binary (neighbor_fmi2.c or neighbor_fmi3.c): loads
the model.

The binary executes this file from the FMU's resources into a module of its own, named after a
hash of this code and the FMU's GUID or instantiation token (it is never imported, so the loaders
of different FMU builds cannot collide; a library loaded again reuses it) and calls `instantiate`,
`reset`, `drain`, `describe` and `shared_memory`; the FMI 3.0 binary also `get_values` and
`set_values`, which expand array variables into the model's elements. The model's code is one
package with a name private to the FMU build
(resources/<package>/, named in neighbor_runtime.txt): two FMUs, or two builds of one FMU, in one
process never share code or data; two instances of the same build share the loaded modules.
"""
import importlib
import importlib.abc
import importlib.machinery
import importlib.util
import marshal
import math
import os
import site
import sys
import tempfile
import threading
import traceback
import types

NONE = None
# One lock for the import work of every FMU build of ours in this process (each build has its
# own loader module, so the lock lives where they all see it): instantiation and reset import
# modules and rewrite package paths, and hosts instantiate from several threads at once. Only
# this work is serialized; steps and gets of different instances run as the GIL lets them.
_LOCK = sys.__dict__.setdefault("_neighbor_cosim_import_lock", threading.RLock())
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


# ---- the private package's bytecode, kept across extractions ----------------------------------
# A host extracts the FMU to a new folder for each run (FMPy, our master) or each process, where
# Python would compile the package's modules again every time (a fifth of a short run's start).
# The package's name carries the digest of its code, so its modules' bytecode is kept per user
# and Python version (NEIGHBOR_FMU_CACHE, else the user's cache folder) as hash-checked .pyc files
# (PEP 552: the source's hash is in the file and checked at every load; a stale or damaged one is
# compiled again). Where the folder cannot be written, modules are compiled as before. It is a
# cache like numba's, beside no source, so PYTHONDONTWRITEBYTECODE (which keeps __pycache__ out
# of source folders) does not turn it off; NEIGHBOR_FMU_BYTECODE_CACHE=0 does.
KEEP_BYTECODE = os.environ.get("NEIGHBOR_FMU_BYTECODE_CACHE", "1") != "0"

def _bytecode_root():
    explicit = os.environ.get("NEIGHBOR_FMU_CACHE")
    if explicit:
        return os.path.join(explicit, "bytecode")
    if sys.platform == "win32":
        base = os.environ.get("LOCALAPPDATA") or os.path.join(os.path.expanduser("~"), "AppData", "Local")
    elif sys.platform == "darwin":
        base = os.path.join(os.path.expanduser("~"), "Library", "Caches")
    else:
        base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return os.path.join(base, "neighbor-cosim", "fmu-bytecode")


def _relocated(code, path):
    """`code` (and the functions and classes in it) as compiled from `path`: numba's caches and
    tracebacks name the file of the extraction that runs, not of the one that compiled it."""
    consts = tuple(_relocated(c, path) if isinstance(c, types.CodeType) else c for c in code.co_consts)
    return code.replace(co_filename=path, co_consts=consts)


class _KeptBytecodeLoader(importlib.machinery.SourceFileLoader):
    """A module of the private package, its bytecode read from and written to `pyc`."""

    def __init__(self, fullname, path, pyc):
        super().__init__(fullname, path)
        self.pyc = pyc

    def get_code(self, fullname):
        path = self.get_filename(fullname)
        source = self.get_data(path)
        digest = importlib.util.source_hash(source)
        header = importlib.util.MAGIC_NUMBER + (3).to_bytes(4, "little") + digest  # checked hash-based
        try:
            with open(self.pyc, "rb") as f:
                kept = f.read()
            if kept[:16] == header:
                return _relocated(marshal.loads(kept[16:]), path)
        except (OSError, ValueError, EOFError, TypeError):
            pass
        code = self.source_to_code(source, path)
        if KEEP_BYTECODE:
            try:
                os.makedirs(os.path.dirname(self.pyc), exist_ok=True)
                fd, tmp = tempfile.mkstemp(dir=os.path.dirname(self.pyc), suffix=".tmp")
                try:
                    with os.fdopen(fd, "wb") as f:
                        f.write(header + marshal.dumps(code))
                    os.replace(tmp, self.pyc)  # whole or not at all, whichever process writes it
                except BaseException:
                    os.unlink(tmp)
                    raise
            except OSError:
                pass  # a read-only or full cache: compiled each time, as Python would
        return code


class _PackageFinder(importlib.abc.MetaPathFinder):
    """Finds the modules of one private package (this FMU build's only) as Python's path finder
    does, and loads their source through _KeptBytecodeLoader."""

    def __init__(self, package):
        self.package = package
        self.root = os.path.join(_bytecode_root(), package, sys.implementation.cache_tag)

    def find_spec(self, fullname, path=None, target=None):
        if fullname != self.package and not fullname.startswith(self.package + "."):
            return None
        spec = importlib.machinery.PathFinder.find_spec(fullname, path)
        if KEEP_BYTECODE and spec is not None and type(spec.loader) is importlib.machinery.SourceFileLoader:
            self.use(spec)
        return spec

    def use(self, spec):
        inside = spec.name.split(".")[1:] + (["__init__"] if spec.submodule_search_locations is not None else [])
        spec.loader = _KeptBytecodeLoader(spec.name, spec.origin, os.path.join(self.root, *inside) + ".pyc")


def _finder(package):
    """This package's finder, in sys.meta_path once per process (several extractions of a build
    share it: the code is the same)."""
    for finder in sys.meta_path:
        if isinstance(finder, _PackageFinder) and finder.package == package:
            return finder
    finder = _PackageFinder(package)
    sys.meta_path.insert(0, finder)
    return finder


def _package(resources, name):
    """Import the FMU's private package from this extraction of the FMU. When the same build was
    loaded before (maybe from a folder that is gone now), its modules stay and its packages look
    in this extraction first for modules not imported yet."""
    folder = os.path.join(resources, name)
    package = sys.modules.get(name)
    if package is None:
        spec = importlib.util.spec_from_file_location(name, os.path.join(folder, "__init__.py"),
                                                      submodule_search_locations=[folder])
        if KEEP_BYTECODE:
            _finder(name).use(spec)
        package = importlib.util.module_from_spec(spec)
        sys.modules[name] = package
        try:
            spec.loader.exec_module(package)
        except BaseException:
            del sys.modules[name]
            raise
        return package
    # a snapshot taken in one C call: iterating sys.modules itself (or building a list of its
    # items, which can start a garbage collection that lets another thread import) fails when
    # another thread imports meanwhile
    for module_name, module in sys.modules.copy().items():
        if module_name == name or module_name.startswith(name + "."):
            path = getattr(module, "__path__", None)
            if path is not None:
                here = os.path.join(folder, *module_name.split(".")[1:])
                module.__path__ = [here] + [p for p in path if p != here and os.path.isdir(p)]
    return package


def instantiate(resources, instance_name, guid, visible, embedded, logging_on):
    """The model's slave object for one FMU instance."""
    with _LOCK:
        return _instantiate(resources, instance_name, guid, visible, embedded, logging_on)


def _instantiate(resources, instance_name, guid, visible, embedded, logging_on):
    if not os.path.isdir(resources):
        raise ValueError(f"the resource location {resources!r} is not a folder: the host gave a wrong "
                         "fmuResourceLocation (FMI 2.0) or resourcePath (FMI 3.0)")
    cfg = _config(resources)
    built_guid = cfg.get("guid", [""])[0]
    if guid != built_guid:
        raise ValueError(f"fmuGUID {guid!r} is not this FMU's GUID {built_guid!r}: the model description "
                         "and the binary come from different builds")
    if embedded or getattr(sys, "_neighbor_cosim_started_python", False):  # a Python one of our FMUs started
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
    if "arrays" in cfg:
        _fmi3_variables(slave, cfg)
    host = "a Python this FMU started" if embedded else "the Python already running in this process"
    slave.log(f"{cls.__name__} in {host}: Python {version} ({sys.prefix}), numpy {numpy.__version__}")
    return slave


def _fmi3_variables(slave, cfg):
    """FMI 3.0: the arrays ({value reference: elements}; the elements are the model's variables
    from that value reference on), the value references inside arrays (not FMI 3.0 variables),
    and time (the independent variable, which the model does not declare: kept from doStep)."""
    arrays = {}
    for item in cfg["arrays"][0].split():
        vr, n = item.split(":")
        arrays[int(vr)] = int(n)
    slave._neighbor_arrays = arrays
    slave._neighbor_inner = {vr + k for vr, n in arrays.items() for k in range(1, n)}
    import numpy  # imported by _instantiate

    slave._neighbor_time_vr = int(cfg["time"][0])
    # the time after the last step, NaN before the first: an array the binary also writes when it
    # takes a native step (shared_memory), kept in the FMU state (NeighborSlave._get_fmu_state)
    slave._neighbor_clock = numpy.full(1, math.nan)
    step = slave.do_step

    def do_step(current_time, step_size):
        done = step(current_time, step_size)
        if done:
            slave._neighbor_clock[0] = current_time + step_size
        return done

    slave.do_step = do_step


def _elements(slave, vrs):
    """The model's value references of the FMI 3.0 variables `vrs`, arrays expanded."""
    arrays, inner = slave._neighbor_arrays, slave._neighbor_inner
    out = []
    for vr in vrs:
        if vr in inner:
            raise ValueError(f"value reference {vr} is not a variable of this FMU (it is inside an array)")
        n = arrays.get(vr)
        if n is None:
            out.append(vr)
        else:
            out.extend(range(vr, vr + n))
    return out


KINDS = ("real", "integer", "boolean", "string")


def get_values(slave, kind, vrs):
    """FMI 3.0 get of the variables `vrs` of `kind` (0 Float64, 1 Int32, 2 Boolean, 3 String): the
    values, arrays serialized in row-major order."""
    if kind == 0 and slave._neighbor_time_vr in vrs:
        clock = float(slave._neighbor_clock[0])
        time = slave.start_time if math.isnan(clock) else clock
        i = vrs.index(slave._neighbor_time_vr)
        return get_values(slave, kind, vrs[:i]) + [time] + get_values(slave, kind, vrs[i + 1:])
    return getattr(slave, f"get_{KINDS[kind]}")(_elements(slave, vrs))


def set_values(slave, kind, vrs, values):
    """FMI 3.0 set: `values` hold every element of every variable, in order."""
    if kind == 0 and slave._neighbor_time_vr in vrs:
        raise ValueError("time (the independent variable) cannot be set")
    elements = _elements(slave, vrs)
    if len(values) != len(elements):
        raise ValueError(f"{len(values)} values given for {len(elements)} elements of value references {vrs}")
    getattr(slave, f"set_{KINDS[kind]}")(elements, values)


def shared_memory(slave):
    """(address of the values, of the codes, of the flags, number of value references, address of
    the spans or 0, address of the native step's slots or 0: NeighborSlave.arm_native, address of
    the FMI 3.0 clock or 0) of the arrays a slave shares with the binary (NeighborSlave.share_values), or
    None: its values then cross through get_*/set_*. For FMI 3.0 the spans give how many elements
    each value reference stands for (an array's, 1 for a scalar, 0 inside an array). The arrays
    stay the slave's (the binary asks again after a reset)."""
    shared = getattr(slave, "shared", None)
    if shared is None:
        return None
    values, codes, flags = shared, slave.share_codes, slave.share_flags
    if not (values.dtype.str == "<f8" and codes.dtype.str == "<i4" and flags.dtype.str == "<i4"
            and values.flags.c_contiguous and codes.flags.c_contiguous and len(codes) == len(values)
            and len(flags) >= 2):
        raise TypeError("the slave's shared arrays are not float64/int32 C arrays of one length")
    spans = 0
    arrays = getattr(slave, "_neighbor_arrays", None)
    if arrays is not None:
        inner = slave._neighbor_inner
        span_array = [0 if vr in inner else arrays.get(vr, 1) for vr in range(len(values))]
        slave.share_spans = codes.copy()  # int32, kept with the slave
        slave.share_spans[:] = span_array
        spans = slave.share_spans.ctypes.data
    native = getattr(slave, "share_native", None)
    native = 0 if native is None else native.ctypes.data
    clock = getattr(slave, "_neighbor_clock", None)  # FMI 3.0: a native step advances the time too
    clock = 0 if clock is None else clock.ctypes.data
    return values.ctypes.data, codes.ctypes.data, flags.ctypes.data, len(values), spans, native, clock


def reset(slave):
    """fmi2Reset/fmi3Reset: the slave as instantiation left it (the binary keeps its log queue)."""
    queue = slave.log_queue
    with _LOCK:
        slave.__init__(**slave._neighbor_init)
    if hasattr(slave, "_neighbor_clock"):
        slave._neighbor_clock[0] = math.nan
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

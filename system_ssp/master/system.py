"""A loaded SSP system: `System(path)` reads and checks it once; `run()` simulates it any
number of times, each with fresh FMU instances."""
import dataclasses
import logging
from pathlib import Path
import shutil
import tempfile
import time
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple, Union

from .. import archive, builder
from ..errors import RealTimeOverrun, RunInterrupted, RunTimedOut, SimulationError, SSPError
from ..ssp import reader
from .components import load_components
from .connections import (FeedthroughGraph, UnitTable, check_connector_units, parameter_connections,
                          resolve_connections)
from .execution import execute
from .info import describe_system
from .names import split_name
from .parameters import collect_parameters, unmapped_warnings
from .observers import Observer
from .plan import RunOptions
from .planning import make_plan
from .result import Result, check_output_file, partial_path, write_result

PathLike = Union[str, Path]
LOG = logging.getLogger("system_ssp.master")


class System:
    """A loaded SSP system. Call `run()` any number of times; each run uses fresh FMU instances.

    `path` is a `.ssp` archive (SystemStructure.ssd at its root), a `.ssd` file (references
    resolved relative to its folder), a folder holding SystemStructure.ssd, or the name of a
    shipped system (`"slew"`: the packed one in the build folder, built first if it is not
    there, see system_ssp.locations). Loading checks the
    SSD, SSV and SSM files against the SSP 1.0 schemas (`validate`), reads every FMU's model
    description, extracts the FMUs, resolves the connections with their unit conversions and
    the direct-feedthrough graph. Use as a context manager (or call `close()`) to delete the
    extracted files.

    A model description with problems that do not change the run (system_ssp.ssp.model_description
    lists them) is read with one warning per FMU, logged and kept in `warnings` with the other
    warnings of loading (FMUs that declare no output dependencies); `strict` refuses it instead."""

    def __init__(self, path: PathLike, validate: bool = True, scratch: Optional[PathLike] = None,
                 strict: bool = False):
        # scratch: the folder to extract into (default: the system's temporary folder)
        tmp = Path(tempfile.mkdtemp(prefix="system_ssp_", dir=scratch))
        self._tmp: Optional[Path] = tmp
        self.warnings: List[str] = []
        try:
            self._load(builder.resolve_system(str(path)), validate, strict, tmp)
        except BaseException:
            self.close()
            raise

    def _load(self, path: Path, validate: bool, strict: bool, tmp: Path) -> None:
        self.path = path
        self.validate = validate
        self.archive_root = None
        if path.is_dir():
            ssd_path = path / "SystemStructure.ssd"
            self.namer = reader.FileNamer()
        elif path.suffix.lower() == ".ssp":
            root = tmp / "ssp"
            archive.extract(path, root)
            ssd_path = root / "SystemStructure.ssd"
            if not ssd_path.is_file():
                raise SSPError(f"{path}: archive has no SystemStructure.ssd at its root")
            self.namer = reader.FileNamer(root, str(path))
            self.archive_root = root
        else:
            ssd_path = path
            self.namer = reader.FileNamer()
        self.desc = reader.parse_ssd(ssd_path, self.namer, validate)
        if not self.desc.components:
            raise SSPError(f"{self.desc.display}: the system has no components")
        self.comps = load_components(self.desc, tmp / "fmu", self.namer, validate, strict, self.warnings)
        self.by_name = {c.name: c for c in self.comps}
        self.units = UnitTable(self.desc, self.comps)
        check_connector_units(self.comps, self.units)
        self.links = resolve_connections(self.desc, self.comps, self.by_name, self.units)
        self.parameter_links = parameter_connections(self.desc, self.by_name)
        fed = {(lk.dst, lk.dst_var) for lk in self.links}
        for name, targets in self.parameter_links.items():
            for comp, var, origin in targets:
                if (comp.index, var) in fed:
                    raise SSPError(f"{origin}: {comp.name}.{var} gets the value of system input {name!r} and is "
                                   "also connected to an output: an input is fed by one connection")
        self.graph = FeedthroughGraph(self.comps, self.links)
        for text in unmapped_warnings(self):
            LOG.warning("%s", text)
            self.warnings.append(text)

    # ---- queries ------------------------------------------------------------------------
    def default_order(self) -> List[str]:
        """Component names in dependency order (feedthrough edges), ties by SSD order.

        Raises SSPError naming the components of an algebraic loop."""
        return [self.comps[i].name for i in self.graph.order()]

    def split_name(self, name: str, what: str = "variable") -> Tuple[Any, str]:
        """'component.variable' -> (ComponentInfo, variable name); SSPError with suggestions."""
        comp, var = split_name(self.comps, name, what)
        return comp, var

    def var_unit(self, comp: Any, var: str) -> Optional[str]:
        unit: Optional[str] = self.units.var_unit(comp, var)
        return unit

    def collect_parameters(self, parameter_sets: Optional[Sequence[PathLike]] = None,
                           parameters: Optional[Mapping[str, Any]] = None) -> Dict[Tuple[int, str], Any]:
        """All start values for a run: {(comp index, var): value}, later sources overriding earlier."""
        values: Dict[Tuple[int, str], Any] = collect_parameters(self, parameter_sets, parameters)
        return values

    def info(self) -> str:
        """Human-readable description (components, connectors with units, bindings, experiment)."""
        text: str = describe_system(self)
        return text

    # ---- running ------------------------------------------------------------------------
    def run(self, options: Optional[RunOptions] = None, *, observers: Sequence[Observer] = (),
            output_file: Optional[PathLike] = None, progress: bool = False, timeout: Optional[float] = None,
            real_time: Optional[float] = None, stop_on_overrun: bool = False, **settings: Any) -> Result:
        """Run one simulation with fresh FMU instances and return its `Result`.

        `options` (`RunOptions`) says what to run; keyword `settings` are a shorthand for its
        fields (`run(stop_time=10.0)` is `run(RunOptions(stop_time=10.0))`; given with `options`
        they replace those fields). The rest is about this call, not the run's values:
        `observers` are called after initialization, after every macro step and at the end,
        after the master's own (see `Observer`); `output_file` (.csv or .parquet) is checked
        before the first step and written at the end, or with the rows so far when the run
        stops early; `progress` shows a progress bar on stderr; `timeout` (s of wall time) stops
        the run with RunTimedOut (rows so far in err.result); `real_time` paces the communication
        points to wall time at that factor (1: real time; the overruns in `Result.pacing`) and
        `stop_on_overrun` ends the run with RealTimeOverrun at the first (see master.pacing)."""
        if real_time is not None and not (isinstance(real_time, (int, float)) and not isinstance(real_time, bool)
                                          and 0 < real_time < float("inf")):
            raise SSPError(f"real_time = {real_time!r}: expected a factor > 0 (1: real time, 100: a hundred "
                           "times faster)")
        wall0 = time.perf_counter()
        plan = make_plan(self, run_options(options, settings))
        if output_file is not None:
            check_output_file(output_file)  # before the first step, not after the whole run
        LOG.info("%s: %d components, %s, t = %g .. %g s%s", self.desc.display, len(self.comps), plan.algorithm,
                 plan.start, plan.stop, f", {plan.n_steps} steps of {plan.step_size:g} s" if plan.schedule is None
                 else ", nc:Schedule")
        try:
            result: Result = execute(self, plan, progress, timeout, observers, real_time, stop_on_overrun)
        except (SimulationError, RunInterrupted, RunTimedOut, RealTimeOverrun) as err:
            if err.result is not None:
                err.result.wall_time = time.perf_counter() - wall0
                if output_file is not None:
                    partial = partial_path(output_file)
                    try:
                        write_result(err.result.data, partial, err.result.units)
                        err.partial_file = partial
                    except SSPError as write_error:  # the run's own failure stays the message
                        err.partial_note = f"its rows could not be kept: {write_error}"
            raise
        result.wall_time = time.perf_counter() - wall0
        LOG.info("%s: %s after %d steps, %.3f s wall", self.desc.display, result.stop_reason, result.steps,
                 result.wall_time)
        if output_file is not None:
            write_result(result.data, output_file, result.units)
        return result

    # ---- cleanup ------------------------------------------------------------------------
    def close(self) -> None:
        tmp = getattr(self, "_tmp", None)
        if tmp is not None:
            shutil.rmtree(tmp, ignore_errors=True)
            self._tmp = None

    def __enter__(self) -> "System":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __del__(self) -> None:
        try:
            self.close()
        except Exception:
            pass


def run_options(options: Optional[RunOptions], settings: Mapping[str, Any]) -> RunOptions:
    """`options` with the keyword `settings` applied to its fields; a keyword that is not a field
    is refused with the list of those that are."""
    unknown = sorted(set(settings) - set(RunOptions.field_names()))
    if unknown:
        raise TypeError(f"unknown run setting(s) {', '.join(unknown)} (RunOptions fields: "
                        f"{', '.join(RunOptions.field_names())}; also observers, output_file, progress, timeout, "
                        "real_time, stop_on_overrun)")
    base = options if options is not None else RunOptions()
    return dataclasses.replace(base, **settings) if settings else base


def simulate(path: PathLike, options: Optional[RunOptions] = None, *, validate: bool = True, strict: bool = False,
             observers: Sequence[Observer] = (), output_file: Optional[PathLike] = None, progress: bool = False,
             timeout: Optional[float] = None, real_time: Optional[float] = None, stop_on_overrun: bool = False,
             **settings: Any) -> Result:
    """Load and run an SSP system; returns a `Result`. `validate` checks the files against the
    SSP schemas and the FMUs' model descriptions, `strict` refuses an FMU whose description has any
    problem (see `System`); the rest as `System.run` (keyword settings: the fields of `RunOptions`)."""
    with System(path, validate=validate, strict=strict) as system:
        return system.run(options, observers=observers, output_file=output_file, progress=progress, timeout=timeout,
                          real_time=real_time, stop_on_overrun=stop_on_overrun, **settings)

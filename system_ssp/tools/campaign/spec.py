"""A campaign spec (TOML): the system, the runs, fixed parameters, dispersions, sweeps, metrics
and probabilities, checked when it is loaded (errors name the file, the key and what is
allowed); and what run `i` gets: its seed and parameter values, from the campaign seed and `i`
alone (numpy SeedSequence), so a run draws the same values on any worker in any order."""
from dataclasses import dataclass, field
import itertools
import math
from pathlib import Path
import re
import sys
from typing import Optional

import numpy as np

from ...errors import SSPError
from ...master.events import parse_events
from .spacecraft import KINDS as SPACECRAFT_KINDS, SpacecraftDispersion, spacecraft_dispersion
from ...limits import read_text_input, refuse_over
from ... import builder
from ...locations import system_names

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

DISTRIBUTIONS = {"uniform": ("low", "high"), "normal": ("mean", "std"),
                 "truncnormal": ("mean", "std", "low", "high"), "choice": ("values",),
                 "integers": ("low", "high")}  # integers: low..high inclusive (e.g. a sensor's noise seed)
METRIC_KINDS = ("stop_time", "stop_reason", "steps", "final", "min", "max", "time_when", "time_in", "duration")
TEXT_METRICS = ("stop_reason",)
SIGNAL_METRICS = ("final", "min", "max", "time_when", "time_in")  # kind:comp.var
HELPERS = {"solar_activity": "scales every F10.7 of the space-weather file by @f107_scale and points the "
                             "orbit's space_weather_file at the scaled copy"}
PROBABILITY = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_]*)\s*(<=|>=|<|>|==)\s*([-+0-9.eE]+|true|false)\s*$")
CAMPAIGN_KEYS = {"system", "parameter_sets", "runs", "seed", "stop_time", "step_size", "timeout_s", "helper",
                 "keep_timeseries", "extends",
                 "min_success",
                 "description"}
TOP_KEYS = {"campaign", "parameters", "dispersions", "sweep", "metrics", "probabilities", "faults", "events"}
EVENT_FIELD = re.compile(r"^events\[(\d+)\]\.(at|value)$")  # a dispersed or swept field of [[events]] i (1-based)
FAULT = "fault"  # the result column naming a run's fault case ("none" without one)
FAULT_STREAM = 1  # the fault draw's random stream: adding [faults] leaves every other draw as it was


@dataclass(frozen=True)
class Dispersion:
    name: str
    kind: str
    args: dict
    also: tuple = ()  # other parameters that get the same drawn value

    @property
    def columns(self):
        """The parameters it draws (one; a spacecraft dispersion draws several)."""
        return (self.name,)

    def draw(self, rng):
        a = self.args
        if self.kind == "uniform":
            return float(rng.uniform(a["low"], a["high"]))
        if self.kind == "integers":
            return int(rng.integers(a["low"], a["high"], endpoint=True))
        if self.kind == "normal":
            return float(rng.normal(a["mean"], a["std"]))
        if self.kind == "truncnormal":
            for _ in range(10000):  # rejection: exact for any bounds with mass
                x = rng.normal(a["mean"], a["std"])
                if a["low"] <= x <= a["high"]:
                    return float(x)
            raise SSPError(f"dispersion {self.name}: truncnormal bounds hold almost no probability")
        values = a["values"]
        return values[int(rng.integers(len(values)))]


@dataclass(frozen=True)
class Faults:
    """[faults]: in each run, with `probability`, one of the `cases` (equally likely), each a set of
    parameter values (component.variable = value) that injects it."""
    probability: float
    cases: dict  # name -> {parameter: value}

    def draw(self, rng):
        """The run's case name, or "none"."""
        if rng.uniform() >= self.probability:
            return "none"
        names = list(self.cases)
        return names[int(rng.integers(len(names)))]


@dataclass(frozen=True)
class Metric:
    name: str
    kind: str
    variable: Optional[str] = None
    equals: Optional[float] = None  # time_when/time_in:comp.var==value: the signal equal to it (else true)
    mode: Optional[str] = None  # duration:mode: the simulated time the run spent in this nc:Schedule mode


@dataclass
class CampaignSpec:
    path: Path
    system: Path
    runs: int
    seed: int
    parameter_sets: list = field(default_factory=list)
    stop_time: Optional[float] = None
    step_size: Optional[float] = None
    timeout_s: Optional[float] = None
    min_success: Optional[float] = None  # the campaign fails (exit 1) below this success rate
    keep_timeseries: bool = False  # store each run's recorded signals (series/run-<i>.parquet)
    keep_signals: tuple = ()  # recorded (and kept) besides the metrics' signals
    helper: Optional[str] = None
    description: str = ""
    parameters: dict = field(default_factory=dict)
    dispersions: list = field(default_factory=list)  # [Dispersion], in spec order
    sweeps: list = field(default_factory=list)  # [(name, [values])]
    metrics: list = field(default_factory=list)  # [Metric]
    probabilities: list = field(default_factory=list)  # [(name, metric, op, threshold)]
    faults: Optional[Faults] = None
    events: list = field(default_factory=list)  # [[events]] tables (system_ssp.master.events), as read
    text: str = ""  # the spec file as read (stored beside the results)

    @property
    def points(self):
        """The sweep's full-factorial points: [{name: value}] (one empty point without sweeps)."""
        names = [n for n, _ in self.sweeps]
        return [dict(zip(names, combo)) for combo in itertools.product(*[v for _, v in self.sweeps])]

    @property
    def total_runs(self):
        return self.runs * len(self.points)

    def inputs(self, index):
        """(seed entropy, {parameter: value} swept and dispersed) of run `index`: sweep point
        index // runs, draws from SeedSequence(seed, spawn_key=(index,))."""
        if not 0 <= index < self.total_runs:
            raise IndexError(index)
        values = dict(self.points[index // self.runs])
        ss = np.random.SeedSequence(self.seed, spawn_key=(index,))
        rng = np.random.default_rng(ss)
        for d in self.dispersions:
            if isinstance(d, SpacecraftDispersion):
                values.update(d.draw(rng))
            else:
                values[d.name] = d.draw(rng)
        if self.faults is not None:
            values[FAULT] = self.faults.draw(np.random.default_rng(
                np.random.SeedSequence(self.seed, spawn_key=(index, FAULT_STREAM))))
        return int(ss.generate_state(1)[0]), values

    def recorded(self):
        """The signals each run records: the metrics' and, with keep_timeseries, the kept ones."""
        return tuple(sorted({m.variable for m in self.metrics if m.variable} | set(self.keep_signals)))

    def run_events(self, values):
        """The [[events]] of a run, with its drawn `events[i].at` / `events[i].value` (None: none)."""
        if not self.events:
            return None
        events = [dict(e) for e in self.events]
        for name, value in values.items():
            m = EVENT_FIELD.match(name)
            if m:
                events[int(m.group(1)) - 1][m.group(2)] = value
        return events

    def overrides(self, values):
        """The system parameters for a run's drawn values: fixed parameters, then the values (and
        the names that share them); helper inputs (@name) are left to the helper."""
        out = dict(self.parameters)
        for d in self.dispersions:
            for other in d.also:
                out[other] = values[d.name]
        out.update({k: v for k, v in values.items() if not k.startswith("@") and k != FAULT
                    and not EVENT_FIELD.match(k)})
        if values.get(FAULT, "none") != "none":
            out.update(self.faults.cases[values[FAULT]])
        return out


def _number(path, key, value, low=-math.inf, integer=False, positive=False):
    ok = isinstance(value, (int, float)) and not isinstance(value, bool) and abs(value) < 1e300
    if ok and integer:
        ok = float(value).is_integer()
    if ok and (value < low or (positive and value <= 0)):
        ok = False
    if not ok:
        need = "an integer" if integer else "a finite number"
        if positive:
            need += " > 0"
        elif low > -math.inf:
            need += f" >= {low:g}"
        raise SSPError(f"{path}: {key} = {value!r}: expected {need}")
    return int(value) if integer else float(value)


def _runs(path, value):
    runs = _number(path, "campaign.runs", value, integer=True, positive=True)
    refuse_over("max_runs", runs, f"{path}: campaign.runs")
    return runs


def _read_doc(path, where):
    text = read_text_input(path, where, "the campaign spec",
                           "a campaign spec is TOML, which is UTF-8: save it as UTF-8")
    try:
        return tomllib.loads(text), text
    except tomllib.TOMLDecodeError as exc:
        raise SSPError(f"{path}: not valid TOML: {exc}") from None


def _extended(path, doc, text, seen=()):
    """A spec whose [campaign] has `extends = "other.toml"` (a spec in the same folder): that
    spec's tables with this one's entries over them, key by key ([campaign] keys, parameters,
    dispersions by parameter, metrics, probabilities by name). The text (what a resumed campaign
    compares, stored as spec.toml) is this file's followed by the base's as comments, so it stays
    valid TOML and a change to either is seen."""
    c = doc.get("campaign")
    base = c.get("extends") if isinstance(c, dict) else None
    if base is None:
        return doc, text
    if not isinstance(base, str) or Path(base).name != base or not base.endswith(".toml"):
        raise SSPError(f"{path}: campaign.extends = {base!r}: expected the file name of a campaign spec (.toml) in "
                       "the same folder")
    base_path = path.parent / base
    if base_path.resolve() in seen or base_path.resolve() == path.resolve():
        raise SSPError(f"{path}: campaign.extends = {base!r}: the specs extend each other in a cycle")
    if not base_path.is_file():
        raise SSPError(f"{path}: campaign.extends = {base!r}: no such file in {path.parent}")
    base_doc, base_text = _read_doc(base_path, f"{path}: campaign.extends {base!r}")
    base_doc, base_text = _extended(base_path, base_doc, base_text, tuple(seen) + (path.resolve(),))
    merged = {}
    for key in list(base_doc) + [k for k in doc if k not in base_doc]:
        below, above = base_doc.get(key), doc.get(key)
        merged[key] = {**below, **above} if isinstance(below, dict) and isinstance(above, dict) else (
            above if key in doc else below)
    merged["campaign"] = {k: v for k, v in merged["campaign"].items() if k != "extends"}
    quoted = "".join(f"# {line}" if line.strip() else "#\n" for line in base_text.splitlines(keepends=True))
    return merged, f"{text.rstrip()}\n\n# ---- campaign.extends: {base}, as it was read ----\n{quoted.rstrip()}\n"


def load_spec(path):
    """Read and check a campaign spec; SSPError naming the file, the key and what is allowed."""
    path = Path(path)
    doc, text = _read_doc(path, str(path))
    doc, text = _extended(path, doc, text)
    unknown = sorted(set(doc) - TOP_KEYS)
    if unknown:
        raise SSPError(f"{path}: unknown table(s) {', '.join(unknown)} (allowed: {', '.join(sorted(TOP_KEYS))})")
    spec = _campaign_table(path, doc.get("campaign"), text)
    params = doc.get("parameters", {})
    if not isinstance(params, dict) or any(isinstance(v, (dict, list)) for v in params.values()):
        raise SSPError(f"{path}: [parameters] holds component.variable = value pairs")
    spec.parameters = dict(params)
    for name, d in doc.get("dispersions", {}).items():
        spec.dispersions.extend(_dispersions(path, name, d, spec.helper))
    for name, s in doc.get("sweep", {}).items():
        key = f"sweep.{name!r}"
        if not isinstance(s, dict) or set(s) != {"values"} or not isinstance(s["values"], list) or not s["values"]:
            raise SSPError(f"{path}: [{key}] needs exactly values = [a non-empty list]")
        spec.sweeps.append((name, list(s["values"])))
    refuse_over("max_runs", spec.runs * math.prod(len(v) for _, v in spec.sweeps),
                f"{path}: campaign.runs" + (" times the sweep points" if spec.sweeps else ""))
    names = [c for d in spec.dispersions for c in d.columns] + [n for n, _ in spec.sweeps]
    spec.events = _events(path, doc, names)
    twice = sorted({n for n in names if names.count(n) > 1} | (set(names) & set(spec.parameters)))
    if twice:
        raise SSPError(f"{path}: {', '.join(twice)}: set more than once (parameters, dispersions, sweeps)")
    if "faults" in doc:
        spec.faults = _faults(path, doc["faults"])
    metrics = doc.get("metrics", {})
    if not metrics:
        raise SSPError(f"{path}: needs a [metrics] table (name = \"stop_time\", \"final:comp.var\", ...)")
    for name, m in metrics.items():
        spec.metrics.append(_metric(path, name, m))
    mnames = {m.name for m in spec.metrics}
    for name, expr in doc.get("probabilities", {}).items():
        match = PROBABILITY.match(expr) if isinstance(expr, str) else None
        threshold = match.group(3) if match else ""
        if threshold not in ("true", "false"):
            try:
                threshold = float(threshold)
            except ValueError:
                match = None
        if match is None or match.group(1) not in mnames:
            raise SSPError(f"{path}: probabilities.{name} = {expr!r}: expected \"<metric> <op> <number>\" with a "
                           f"metric of [metrics] ({', '.join(sorted(mnames))}) and op one of < <= > >= ==")
        if next(m for m in spec.metrics if m.name == match.group(1)).kind in TEXT_METRICS:
            raise SSPError(f"{path}: probabilities.{name} = {expr!r}: metric {match.group(1)} is text (stop_reason); "
                           "a probability takes a numeric or Boolean metric")
        spec.probabilities.append((name, match.group(1), match.group(2),
                                   threshold == "true" if threshold in ("true", "false") else threshold))
    return spec


def _events(path, doc, names):
    """The [[events]] tables (checked as scenario events), and the events' fields that `names`
    (dispersed or swept) draw: events[i].at or events[i].value."""
    events = doc.get("events", [])
    if "events" in doc:
        if not isinstance(events, list) or not events:
            raise SSPError(f"{path}: [[events]]: expected event tables (at or when, and set, fault or release)")
        parse_events(events, [f"{path}: events[{i + 1}]" for i in range(len(events))])
    for name in names:
        m = EVENT_FIELD.match(name)
        if name.startswith("events[") and (m is None or not 1 <= int(m.group(1)) <= len(events)):
            raise SSPError(f"{path}: {name}: an event's field is events[i].at or events[i].value, i from 1 to "
                           f"{len(events)} (the [[events]] in order)")
        if m and m.group(2) == "at" and "at" not in events[int(m.group(1)) - 1]:
            raise SSPError(f"{path}: {name}: events[{m.group(1)}] has no `at` to disperse (it has `when`)")
    return list(events)


def _campaign_table(path, c, text):
    """The [campaign] table as a CampaignSpec (the other tables added by load_spec)."""
    if not isinstance(c, dict):
        raise SSPError(f"{path}: needs a [campaign] table with system, runs and seed")
    unknown = sorted(set(c) - CAMPAIGN_KEYS)
    if unknown:
        raise SSPError(f"{path}: [campaign] has unknown key(s) {', '.join(unknown)} (allowed: "
                       f"{', '.join(sorted(CAMPAIGN_KEYS))})")
    for key in ("system", "runs", "seed"):
        if key not in c:
            raise SSPError(f"{path}: [campaign] needs {key}")
    if not isinstance(c["system"], str) or not c["system"]:
        raise SSPError(f"{path}: campaign.system = {c['system']!r}: expected a path or a built system's name")
    spec = CampaignSpec(path=path, system=resolve_system(c["system"], path),
                        runs=_runs(path, c["runs"]),
                        seed=_number(path, "campaign.seed", c["seed"], low=0, integer=True), text=text)
    ps = c.get("parameter_sets", [])
    if not isinstance(ps, list) or not all(isinstance(p, str) for p in ps):
        raise SSPError(f"{path}: campaign.parameter_sets = {ps!r}: expected a list of file names")
    spec.parameter_sets = ps
    if c.get("stop_time") is not None:
        spec.stop_time = _number(path, "campaign.stop_time", c["stop_time"], positive=True)
    if c.get("step_size") is not None:
        spec.step_size = _number(path, "campaign.step_size", c["step_size"], positive=True)
    if c.get("timeout_s") is not None:
        spec.timeout_s = _number(path, "campaign.timeout_s", c["timeout_s"], positive=True)
    keep = c.get("keep_timeseries", False)
    if isinstance(keep, list) and keep and all(isinstance(k, str) for k in keep):
        spec.keep_timeseries, spec.keep_signals = True, tuple(keep)
    elif isinstance(keep, bool):
        spec.keep_timeseries = keep
    else:
        raise SSPError(f"{path}: campaign.keep_timeseries = {keep!r}: expected true (the metrics' signals) or a "
                       "list of component.variable names (recorded besides them)")
    if c.get("min_success") is not None:
        spec.min_success = _number(path, "campaign.min_success", c["min_success"], low=0)
        if spec.min_success > 1:
            raise SSPError(f"{path}: campaign.min_success = {c['min_success']!r}: expected a fraction in [0, 1]")
    if c.get("helper") is not None:
        if c["helper"] not in HELPERS:
            raise SSPError(f"{path}: campaign.helper = {c['helper']!r}: expected one of {', '.join(HELPERS)}")
        spec.helper = c["helper"]
    spec.description = str(c.get("description", ""))
    return spec


def _faults(path, d):
    """[faults] probability = p, and [faults.cases.<name>] tables of component.variable = value."""
    if not isinstance(d, dict) or set(d) != {"probability", "cases"}:
        raise SSPError(f"{path}: [faults] needs exactly probability = a fraction and [faults.cases.<name>] tables")
    p = _number(path, "faults.probability", d["probability"], low=0)
    if p > 1:
        raise SSPError(f"{path}: faults.probability = {d['probability']!r}: expected a fraction in [0, 1]")
    cases = d["cases"]
    if not isinstance(cases, dict) or not cases:
        raise SSPError(f"{path}: [faults.cases] needs at least one [faults.cases.<name>] table")
    for name, values in cases.items():
        if name == "none":
            raise SSPError(f"{path}: faults.cases.none: \"none\" names the runs without a fault; pick another name")
        if not isinstance(values, dict) or not values or any(isinstance(v, (dict, list)) for v in values.values()):
            raise SSPError(f"{path}: [faults.cases.{name}] holds component.variable = value pairs (at least one)")
    return Faults(p, {name: dict(values) for name, values in cases.items()})


def _dispersions(path, name, d, helper):
    """One dispersion, or with `elements = n` one per element name[1]..name[n] of a vector
    parameter, each drawn on its own from the same distribution (in element order); a spacecraft
    dispersion (inertia, attitude, rate, cone: spacecraft.py) draws several parameters at once."""
    if isinstance(d, dict) and d.get("distribution") in SPACECRAFT_KINDS:
        return [spacecraft_dispersion(path, name, d)]
    if not isinstance(d, dict) or "elements" not in d:
        return [_dispersion(path, name, d, helper)]
    n = _number(path, f"dispersions.{name!r}.elements", d["elements"], integer=True, positive=True)
    refuse_over("max_vector_elements", n, f"{path}: dispersions.{name!r}.elements")
    if "[" in name or d.get("also"):
        raise SSPError(f"{path}: [dispersions.{name!r}]: elements = {n} names a vector parameter without an index "
                       "and takes no `also`")
    rest = {k: v for k, v in d.items() if k != "elements"}
    return [_dispersion(path, f"{name}[{i}]", rest, helper) for i in range(1, n + 1)]


def _value_kind(value):
    """'number', 'boolean' or 'string' (None for a table or a list, which no parameter takes)."""
    if isinstance(value, bool):
        return "boolean"
    if isinstance(value, (int, float)):
        return "number"
    return "string" if isinstance(value, str) else None


def _dispersion(path, name, d, helper):
    key = f"dispersions.{name!r}"
    if not isinstance(d, dict) or "distribution" not in d:
        raise SSPError(f"{path}: [{key}] needs distribution = one of {', '.join(DISTRIBUTIONS)}")
    kind = d["distribution"]
    if kind not in DISTRIBUTIONS:
        raise SSPError(f"{path}: {key}.distribution = {kind!r}: expected one of {', '.join(DISTRIBUTIONS)}, or for "
                       f"the spacecraft {', '.join(SPACECRAFT_KINDS)}")
    need = DISTRIBUTIONS[kind]
    extra = sorted(set(d) - set(need) - {"distribution", "also"})
    missing = [k for k in need if k not in d]
    if missing or extra:
        raise SSPError(f"{path}: [{key}] ({kind}) needs {', '.join(need)}"
                       + (f"; missing {', '.join(missing)}" if missing else "")
                       + (f"; unknown {', '.join(extra)}" if extra else ""))
    if name.startswith("@") and helper is None:
        raise SSPError(f"{path}: [{key}]: {name} is a helper input, but campaign.helper is not set")
    if kind == "choice":
        if not isinstance(d["values"], list) or not d["values"]:
            raise SSPError(f"{path}: {key}.values: expected a non-empty list")
        kinds = {_value_kind(v) for v in d["values"]}
        if len(kinds) != 1 or None in kinds:  # one column of the results, one type of the parameter
            raise SSPError(f"{path}: {key}.values = {d['values']!r:.100}: expected numbers only, true/false only or "
                           "strings only")
        args = {"values": list(d["values"])}
    else:
        args = {k: _number(path, f"{key}.{k}", d[k], integer=kind == "integers") for k in need}
        if "std" in args and args["std"] < 0:
            raise SSPError(f"{path}: {key}.std = {args['std']!r}: expected a number >= 0")
        if "low" in args and not (args["low"] <= args["high"] if kind == "integers" else args["low"] < args["high"]):
            raise SSPError(f"{path}: [{key}]: low {args['low']!r} must be below high {args['high']!r}")
    also = d.get("also", [])
    if not isinstance(also, list) or not all(isinstance(a, str) for a in also):
        raise SSPError(f"{path}: {key}.also: expected a list of component.variable names")
    return Dispersion(name, kind, args, tuple(also))


def _metric(path, name, m):
    if not isinstance(m, str):
        raise SSPError(f"{path}: metrics.{name} = {m!r}: expected a string")
    kind, _, var = m.partition(":")
    equals = None
    if kind in ("time_when", "time_in") and "==" in var:
        var, _, value = var.partition("==")
        var = var.strip()
        try:
            equals = float(value)
        except ValueError:
            var = ""  # reported below
    if kind not in METRIC_KINDS or (kind in SIGNAL_METRICS or kind == "duration") != bool(var):
        raise SSPError(f"{path}: metrics.{name} = {m!r}: expected \"stop_time\", \"stop_reason\", \"steps\", "
                       "\"final:comp.var\", \"min:comp.var\", \"max:comp.var\", \"time_when:comp.var\" (first time "
                       "true), \"time_when:comp.var==number\" (first time equal), \"time_in:comp.var\" or "
                       "\"time_in:comp.var==number\" (simulated time true or equal) or \"duration:mode\" (simulated "
                       "time in an nc:Schedule mode)")
    if kind == "duration":
        return Metric(name, kind, mode=var)
    return Metric(name, kind, var or None, equals)


def resolve_system(name, spec_path):
    """A campaign's system: a path (relative to the working directory or the spec's folder), or
    the name of a shipped system (its packed file in the build folder, built first if missing)."""
    for candidate in (Path(name), Path(spec_path).parent / name):
        if candidate.exists():
            return candidate.resolve()
    try:
        return builder.resolve_system(Path(name).stem if Path(name).suffix == ".ssp" else name).resolve()
    except SSPError:
        raise SSPError(f"{spec_path}: campaign.system = {name!r}: no such file here or beside the spec, and no "
                       f"system of that name (systems: {', '.join(system_names())})") from None

"""system_ssp: a co-simulation master for flat SSP 1.0 systems of FMI 2.0 co-simulation FMUs.

Python API
----------
    result = system_ssp.simulate(path, stop_time=None, step_size=None, start_time=None,
                                 parameters=None, parameter_sets=None, outputs=None,
                                 algorithm="gauss-seidel", order=None, step_multiples=None,
                                 stop_when=None, output_file=None, progress=False, validate=True,
                                 record_every=1)

    with system_ssp.System(path) as system:      # load once (schemas, FMUs, connections)
        r1 = system.run(stop_time=10, step_size=0.1)   # each run: fresh FMU instances
        r2 = system.run(stop_time=10, parameters={"dynamics.omega0[1]": r1.final["dynamics.omega[1]"]})

`path` is a `.ssp` archive (SystemStructure.ssd at its root), a `.ssd` file (references
resolved relative to its folder) or a folder holding SystemStructure.ssd.

Errors: `SSPError` (bad files, names, values, arguments; the message names the file and line,
the component, the variable or the connection) and its subclass `SimulationError` (an FMU
failed; the message carries the messages the FMU logged, e.g. the Python exception text of
a pythonfmu FMU).

Parameters, in order of application (later wins): the SSD's component bindings, the root
system's bindings (names `component.variable`), the caller's `parameter_sets` (.ssv files,
paths or names inside the .ssp, names `component.variable`), the caller's `parameters`
({"component.variable": value}). Values are type-checked against the FMU variable; Real values
must be finite; an ssv:Real with a `unit` is converted to the variable's unit.

Connections: `ssc:LinearTransformation` (applied in the data-flow direction; if the connection
is written end->start relative to the data flow it is inverted), Boolean/Integer mapping
transformations, and unit conversion between the two ends (SSD connector unit, else the FMU
variable's unit; units defined by ssd:Units, the FMUs' UnitDefinitions, or a built-in table of
common SI-derived units). Dimension mismatch is refused. Unconnected inputs keep their start
values. System connectors are resolved as pass-throughs (output -> system connector -> inputs).

Algorithms, fixed communication step h, time t_n = start + n*h from an integer counter; the
last step is shortened so that the run ends exactly at stop_time:
- "jacobi": every component steps from the same input values (outputs of the previous
  communication point); equals libcosim's fixed-step algorithm.
- "gauss-seidel": components step in an order; each sees the outputs of those already stepped.
  After all stepped to t+h, inputs are propagated once more in order (no doStep), so direct-
  feedthrough outputs reflect t+h before recording and stop conditions. Default order: the
  topological order of feedthrough edges (P->C when C reads an output of P that depends directly
  on P's inputs, per ModelStructure/Outputs dependencies; no dependencies attribute = depends on
  all inputs), ties in SSD order. A cycle is an algebraic loop and is refused.
- Step multiples k: a component steps only every k-th communication step, with step k*h.

Initialization: instantiate, setupExperiment, enterInitializationMode, set parameters/start
values, propagate along connections in dependency order, exitInitializationMode, propagate
again; the first recorded row is the start time.

Annotation `org.neighbor-cosim.master`
--------------------------------------
On the root ssd:System (its ssd:Annotations, the last child of ssd:System) and/or on
ssd:DefaultExperiment (the DefaultExperiment one wins where both set something):

    <ssd:Annotations>
      <ssc:Annotation type="org.neighbor-cosim.master">
        <nc:Master xmlns:nc="https://neighbor-cosim.org/ssp/master"
                   stepSize="0.015" algorithm="gauss-seidel">
          <nc:Order>detumble thrusters dynamics</nc:Order>
          <nc:StepMultiple component="dynamics" multiple="10"/>
          <nc:StopCondition component="detumble" connector="done"/>
        </nc:Master>
      </ssc:Annotation>
    </ssd:Annotations>

All attributes and children are optional. stepSize: default communication step (SSP 1.0
DefaultExperiment has none). algorithm: "gauss-seidel" or "jacobi". nc:Order: whitespace-
separated component names, each exactly once. nc:StepMultiple: per-component multiple k >= 1.
nc:StopCondition: a Boolean output; the run stops at the first communication point where any
is true. Arguments of simulate()/run() override the annotation. Other tools (libcosim) ignore
unknown annotation types; the content is schema-valid (ssc:Annotation allows any element).

Mode-dependent communication steps (nc:Schedule)
------------------------------------------------
A mission spends years coasting and minutes in 15 ms attitude manoeuvres in one run, so a
system may declare its steps per mode inside nc:Master:

    <nc:Schedule>
      <nc:Mode name="attitude" stepSize="0.015" recordEvery="20">
        <nc:When component="mission" connector="mode" values="4"/>
        <nc:When component="mission" connector="phase" values="2 3 4"/>
      </nc:Mode>
      <nc:Mode name="coast" stepSize="3600" active="mission host orbit power data"/>
      <nc:NextEvent component="mission" connector="next_event_time"/>
    </nc:Schedule>

After initialization and after every macro step the master takes the first nc:Mode whose
nc:When conditions all hold (an Integer, Enumeration or Boolean output in `values`; a mode
without conditions matches always and must be last). The next step is the mode's stepSize,
shortened to end exactly on the earliest nc:NextEvent time ahead (Real outputs by which FMUs
announce timers: a daily wake-up, the end of a grace period) and on the stop time. `active`
lists the components stepped in that mode (default: all); the others are suspended: not
stepped, outputs held, inputs not set, and their next doStep starts at the then-current time
(FMI 2.0 does not require contiguous communication points; every component must declare
canHandleVariableCommunicationStepSize). `every="comp:k ..."` steps a slow component only every
k-th step of the mode, ahead of the master by k stepSize with its inputs held (like step
multiples); otherwise each component's communication points are contiguous. Gauss-Seidel only; no step multiples. Rows are
recorded every `recordEvery` steps of a mode, at each mode change, at a stop and at the end.
`Result.modes` gives steps and simulated time per mode; `profile=True` adds `Result.profile`
(wall seconds per component for set + doStep + get, and the master's own share).
`run(..., schedule=False)` ignores the schedule and runs with the fixed step.

Result
------
`.data` numpy structured array ('time', then 'component.variable' fields: float64 / int64 /
bool), `.stop_time`, `.stop_reason` ("reached stop time" or "stop condition comp.var at t=... s"),
`.steps`, `.final` (all inputs and outputs at the end), `.wall_time`, `.order`, `.messages`.
With `output_file`, a CSV (header `time,component.variable,...`) is written through a temporary
file renamed on success: a failing run leaves no partial file and an existing file untouched.
"""
from .errors import SimulationError, SSPError
from .master import Result, System, simulate, write_csv_atomic

__all__ = ["simulate", "System", "Result", "SSPError", "SimulationError", "write_csv_atomic"]

"""The NEIGHBOR thesis' attitude validation cases, run through the master.

    python -m system_ssp thesis [--integrator euler|rk4] [--ssp-dir build/ssp]

Each case is the packed detumble or slew system with that case's parameter set
(system_ssp/systems/parameters/<case>.ssv). The thesis ran its slews from the end state of a
detumble case (slew 1 after detumble 1, slew 2 after detumble 2, slew 3 after detumble 1), and
slew case 3 as three successive 180 deg rotations, each from where the previous one ended, to
targets computed from the start attitude (Appendix G, Eq. 57-59). This module chains the runs
the same way: the final q_BN and omega_BN_B of one run become q0 and omega0 of the next.

Durations count communication steps of 15 ms from the start of a run to the first
communication point where the controller's `done` holds (the state after n integration
steps has time n * 15 ms). The detumble script of Appendix D breaks before stepping its clock,
so its printed time counts one step less (664 updates: 9.96 s here, 9.945 s by the script's
clock; the thesis prints "about 9.97 s"). Propellant is Eq. 74 over the summed pair firing
time.
"""
import math
import sys
from dataclasses import dataclass, field
from typing import Any, Dict, Optional
from pathlib import Path

from components.core import rotations

from ..master import System
from ..tools.console import ArgumentParser, positive_float, DEFAULT_SSP_DIR, add_console_arguments, console_settings


# Published results (thesis Eq. 34, 38, 47, 50, 62, 64, 66 and section 3.3.9), q as printed,
# omega in deg/s as printed, the printed "Euler angles" (Eq. 31: rates integrated, deg),
# durations in s, propellant in g.
THESIS: Dict[str, Dict[str, Any]] = {
    "detumble_case1": dict(duration=9.97, propellant=2.36, q=(0.1460, 0.4400, 0.2256, 0.8573),
                           omega=(0.0019, 0.0013, -0.0003), euler=(22.32, 53.52, 21.71),
                           source="Eq. 34, section 3.3.9"),
    "detumble_case2": dict(duration=9.97, propellant=2.36, q=(0.5928, 0.5193, 0.5026, 0.3566),
                           omega=(0.0019, 0.0013, -0.0003), euler=(101.83, 97.64, 9.85),
                           source="Eq. 38, section 3.3.9"),
    "slew_case1": dict(duration=24.84, propellant=4.51, q=(0.00017, 0.00041, 0.00043, 1.00060),
                       omega=(-0.0053, -0.0054, -0.0021), euler=(8.63, 2.19, -9.74),
                       source="Eq. 47, section 3.3.9"),
    "slew_case2": dict(duration=38.25, propellant=9.96, q=(0.00027, 0.00039, -0.00012, 1.00125),
                       omega=(-0.0028, -0.0038, -0.0100), euler=(20.72, 33.33, -79.84),
                       source="Eq. 50, section 3.3.9"),
    "slew_case3_x": dict(duration=32.81, propellant=None, q=(0.8585, 0.2267, -0.4405, -0.1451),
                         omega=(0.0019, -0.0004, -0.0018), euler=(202.17, 53.53, 21.68),
                         source="Eq. 62"),
    "slew_case3_y": dict(duration=82.5, propellant=None, q=(-0.4412, 0.1453, -0.8585, 0.2282),
                         omega=(0.0001, -0.0004, 0.0028), euler=(202.24, -126.57, 21.85),
                         source="Eq. 64"),
    "slew_case3_z": dict(duration=50.96, propellant=None, q=(0.1460, 0.4413, 0.2254, 0.8601),
                         omega=(-0.0034, -0.0083, 0.0029), euler=(202.15, -126.08, 201.56),
                         source="Eq. 66"),
    "slew_case3": dict(duration=166.26, propellant=16.03, q=None, omega=None, euler=None,
    source="section 3.3.7, 3.3.9"),
}

AXES = {"x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "z": (0.0, 0.0, 1.0)}


@dataclass
class CaseResult:
    name: str
    converged: bool
    duration: float  # s
    propellant: float  # g
    q: Optional[tuple] = None
    omega_deg: Optional[tuple] = None
    euler_deg: Optional[tuple] = None  # Eq. 31's integrated angles at the end (deg), as the thesis prints them
    steps: int = 0
    wall_time: float = 0.0
    parts: list = field(default_factory=list)

    @property
    def thesis(self):
        return THESIS[self.name]


def _state(result):
    """The end state a following maneuver starts from: q, omega and the Eq. 31 angles (rad)."""
    q = tuple(result.final[f"dynamics.q_BN[{i}]"] for i in range(1, 5))
    w = tuple(result.final[f"dynamics.omega_BN_B[{i}]"] for i in range(1, 4))
    e = tuple(result.final[f"dynamics.euler_integrated[{i}]"] for i in range(1, 4))
    return q, w, e


def _initial(q, w, e):
    """Start where the previous maneuver ended; the thesis' slews carry on integrating the
    detumble's angles (Eq. 39 = Eq. 34)."""
    out = {f"dynamics.q0[{i}]": v for i, v in enumerate(q, 1)}
    out.update({f"dynamics.omega0[{i}]": v for i, v in enumerate(w, 1)})
    out["dynamics.euler0_from_q0"] = False
    out.update({f"dynamics.euler0[{i}]": v for i, v in enumerate(e, 1)})
    return out


def _case(name, system, integrator, stop_time, parameters=None, progress=False):
    params = {"dynamics.integrator": integrator}
    params.update(parameters or {})
    if progress:  # which case runs: the run's own bar shows its simulated time once it lasts a second
        print(f"thesis: {name}", file=sys.stderr, flush=True)
    result = system.run(parameter_sets=[f"parameters/{name}.ssv"], parameters=params, stop_time=stop_time,
                        progress=progress)
    q, w, e = end = _state(result)
    converged = result.stop_reason.startswith("stop condition")
    duration = result.stop_time - float(result.data["time"][0])
    res = CaseResult(name, converged, duration, result.final["thrusters.propellant_mass"] * 1e3, q,
                     _degrees(w), _degrees(e), result.steps, result.wall_time)
    return res, end


def _degrees(values):
    return tuple(math.degrees(x) for x in values)


def slew_case3(slew, start, integrator="euler", stop_time=None, progress=False):
    """Appendix G: 180 deg about x, then y, then z; targets from the start attitude (Eq. 57-59)."""
    end = start
    target = start[0]
    parts = []
    for axis in "xyz":
        target = rotations.circle_cross(rotations.from_axis_angle(AXES[axis], math.pi), target)
        params = _initial(*end)
        params.update({f"slew.q_d[{i}]": v for i, v in enumerate(target, 1)})
        part, end = _case(f"slew_case3_{axis}", slew, integrator, stop_time, params, progress)
        parts.append(part)
        if not part.converged:
            break
    q, w, e = end
    total = CaseResult("slew_case3", all(p.converged for p in parts) and len(parts) == 3,
                       sum(p.duration for p in parts), sum(p.propellant for p in parts), q,
                       _degrees(w), _degrees(e), sum(p.steps for p in parts),
                       sum(p.wall_time for p in parts), parts)
    return total


def run_cases(ssp_dir=DEFAULT_SSP_DIR, integrator="euler", slew_stop_time=None, cases=None, progress=False):
    """Run the thesis cases (all, or the names in `cases`); returns {name: CaseResult}."""
    ssp_dir = Path(ssp_dir)
    wanted = set(cases or ("detumble_case1", "detumble_case2", "slew_case1", "slew_case2", "slew_case3"))
    out = {}
    with System(ssp_dir / "detumble.ssp") as detumble, System(ssp_dir / "slew.ssp") as slew:  # built if missing
        ends = {}
        for k in (1, 2):
            if {f"detumble_case{k}", f"slew_case{k}"} & wanted or (k == 1 and "slew_case3" in wanted):
                res, ends[k] = _case(f"detumble_case{k}", detumble, integrator, None, progress=progress)
                out[res.name] = res
        for k in (1, 2):
            if f"slew_case{k}" in wanted:
                res, _ = _case(f"slew_case{k}", slew, integrator, slew_stop_time, _initial(*ends[k]), progress)
                out[res.name] = res
        if "slew_case3" in wanted:
            total = slew_case3(slew, ends[1], integrator, slew_stop_time, progress)
            for part in total.parts:
                out[part.name] = part
            out["slew_case3"] = total
    return {k: v for k, v in out.items() if k in wanted or k.startswith("slew_case3")}


def _fmt(values, digits):
    return "[" + ", ".join(f"{v:.{digits}f}" for v in values) + "]" if values is not None else "-"


def report(results, integrator):
    lines = [f"NEIGHBOR thesis attitude validation cases, integrator={integrator}, 15 ms Gauss-Seidel steps",
             f"{'case':<15}{'done':<6}{'time s':>9}{'thesis':>9}{'prop g':>8}{'thesis':>8}  final q / thesis q;"
             " final omega deg/s / thesis;",
             f"{'':<55}  Eq. 31 angles deg (rates integrated, not the attitude's 1-2-3 angles) / thesis"]
    for name, r in results.items():
        t = r.thesis
        digits = 5 if name in ("slew_case1", "slew_case2") else 4
        prop = f"{t['propellant']:.2f}" if t["propellant"] is not None else "-"
        lines.append(f"{name:<15}{'yes' if r.converged else 'NO':<6}{r.duration:>9.3f}{t['duration']:>9.2f}"
                     f"{r.propellant:>8.3f}{prop:>8}  {_fmt(r.q, digits)} / {_fmt(t['q'], digits)}")
        if t["omega"] is not None:
            lines.append(f"{'':<55}  {_fmt(r.omega_deg, 4)} / {_fmt(t['omega'], 4)}")
        if t["euler"] is not None:
            lines.append(f"{'':<55}  {_fmt(r.euler_deg, 2)} / {_fmt(t['euler'], 2)}")
    return "\n".join(lines)


def main(argv=None):
    ap = ArgumentParser(prog="neighbor-cosim thesis", description=__doc__.split("\n\n")[0])
    ap.add_argument("--integrator", choices=["euler", "rk4"], default="euler",
                    help="the rigid body's integrator: euler (the thesis' Appendix D loop; default) or rk4")
    ap.add_argument("--ssp-dir", default=str(DEFAULT_SSP_DIR),
                    help="folder of the built systems (default: %(default)s)")
    ap.add_argument("--slew-stop-time", type=positive_float, default=None,
                    help="limit of each slew run in s (default: the SSD's 1500 s, Appendix G)")
    add_console_arguments(ap)
    args = ap.parse_args(argv)
    progress = console_settings(args)
    results = run_cases(args.ssp_dir, args.integrator, args.slew_stop_time, progress=progress)
    print(report(results, args.integrator))
    unfinished = [name for name, r in results.items() if not r.converged and not r.parts]
    for name in unfinished:
        print(f"{name}: did not finish: its stop condition was still false at t = {results[name].duration:g} s, "
              "the run's limit (--slew-stop-time sets the slews'); the thesis' numbers are for its Euler loop"
              + (", and with --integrator rk4 the trajectory differs" if args.integrator != "euler" else ""),
              file=sys.stderr)
    return 1 if unfinished else 0

"""Run an SSP with libcosim's fixed-step algorithm and write the trajectories as JSON.

Usage: python libcosim_run.py SSP STEP_SIZE_S N_STEPS OUT_JSON comp.var [comp.var ...]
(SSP: a folder or .ssp file; STEP_SIZE_S "file": the step the system gives, as libcosim reads it)
Run in its own process (a process holding both libcosim and fmpy instances once aborted at exit).
"""
import json
import sys

from libcosimpy.CosimExecution import CosimExecution
from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
from libcosimpy.CosimObserver import CosimObserver

log_output_level(CosimLogLevel.WARNING)


def main():
    ssp, h, n, out = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4]
    names = sys.argv[5:]
    step = None if h == "file" else int(round(float(h) * 1e9))
    ex = CosimExecution.from_ssp_file(ssp, step_size=step)
    obs = CosimObserver.create_last_value()
    ex.add_observer(obs)
    refs = []
    for name in names:
        comp, var = name.split(".", 1)
        idx = ex.slave_index_from_instance_name(comp)
        vr = next(v.reference for v in ex.slave_variables(idx) if v.name.decode() == var)
        refs.append((idx, vr))
    rows = []
    ex.step(1)  # libcosim initializes on its first step
    # values after initialization are not observable separately; record after each step
    rows.append([obs.last_real_values(i, [vr])[0] for i, vr in refs])
    for _ in range(n - 1):
        ex.step(1)
        rows.append([obs.last_real_values(i, [vr])[0] for i, vr in refs])
    with open(out, "w") as f:
        json.dump(rows, f)


if __name__ == "__main__":
    main()

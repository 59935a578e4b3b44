"""Build every FMU and pack every system into build/ (the checkout's builder script; the builder
itself is system_ssp.builder, which `neighbor-cosim build` runs too).

    python build_fmus.py            # rebuild what changed
    python build_fmus.py --clean    # rebuild everything
    python build_fmus.py --check    # also run fmpy's validation on every FMU
    python build_fmus.py --compat   # also write the compatibility bundle (build/compat/<Model>/)
"""
import sys

# the tests and the system generators use these through this script's name
from system_ssp.builder import BuildError, FMU_SOURCES, build_all, build_fmu, pack_ssp, wrapper_scripts  # noqa: F401
from system_ssp.tools.release import build_main as main

if __name__ == "__main__":
    sys.exit(main())

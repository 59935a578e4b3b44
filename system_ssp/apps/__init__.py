"""The product's applications on top of the master: the thesis validation cases (`thesis`), the
de-orbit lifetime study (`deorbit_study`) and the NEIGHBOR mission (`mission`). Each has a
`main(argv)` behind a subcommand of `neighbor-cosim` / `python -m system_ssp`."""
from pathlib import Path

# Where `python build_fmus.py` packs the systems, in a source checkout (the documented install).
DEFAULT_SSP_DIR = Path(__file__).resolve().parents[2] / "build" / "ssp"

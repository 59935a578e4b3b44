"""The product's systems: the committed .ssd files and their parameter sets (data, packed into
build/ssp/<name>.ssp by build_fmus.py), the system specs they are written from (specs/<name>.toml,
the TOML a user's `neighbor-cosim compose` reads: components, connections, master settings), and
the generator package that writes the parameter sets from the mission definition and each
system from its spec (`python -m system_ssp.systems`, see `system_ssp.systems.generators`)."""
from pathlib import Path

SYSTEMS_DIR = Path(__file__).resolve().parent
PARAMETERS_DIR = SYSTEMS_DIR / "parameters"
SPECS_DIR = SYSTEMS_DIR / "specs"

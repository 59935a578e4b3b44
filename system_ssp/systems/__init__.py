"""The product's systems: the committed .ssd files and their parameter sets (data, packed into
build/ssp/<name>.ssp by build_fmus.py), and the generator package that writes them
(`python -m system_ssp.systems`, see `system_ssp.systems.generators`)."""
from pathlib import Path

SYSTEMS_DIR = Path(__file__).resolve().parent
PARAMETERS_DIR = SYSTEMS_DIR / "parameters"

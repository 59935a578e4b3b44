"""Where the product finds its sources and its built FMUs and systems.

The sources (components/, fmus/, system_ssp/systems/) sit side by side wherever the package is:
in a source checkout, or in the site-packages folder a wheel installed them into. What the
builder makes (FMUs, packed systems, the compiled runtime, compatibility information) goes to:
- `$NEIGHBOR_COSIM_BUILD` when it is set;
- `build/` in a source checkout (the folder holding build_fmus.py and pyproject.toml);
- else the user's data folder, one per product version (platformdirs: on Linux
  `~/.local/share/neighbor-cosim/<version>`), filled by the first command that needs it or by
  `neighbor-cosim build`.
"""
import os
from pathlib import Path

import platformdirs

from .version import __version__

ROOT = Path(__file__).resolve().parents[1]
FMU_SOURCES = ROOT / "fmus"
COMPONENTS = ROOT / "components"
SYSTEM_SOURCES = ROOT / "system_ssp" / "systems"
BUILD_ENV = "NEIGHBOR_COSIM_BUILD"


def is_checkout() -> bool:
    """True when the package runs from a source checkout (an editable install or the tests)."""
    return (ROOT / "build_fmus.py").is_file() and (ROOT / "pyproject.toml").is_file()


def build_dir() -> Path:
    """The folder the builder writes into and the commands read the built FMUs and systems from."""
    chosen = os.environ.get(BUILD_ENV)
    if chosen:
        return Path(chosen).expanduser().resolve()
    if is_checkout():
        return ROOT / "build"
    return Path(platformdirs.user_data_dir("neighbor-cosim", appauthor=False)) / __version__


BUILD = build_dir()
FMU_DIR = BUILD / "fmus"
SSP_DIR = BUILD / "ssp"
COMPAT_DIR = BUILD / "compat"
COMPAT3_DIR = BUILD / "compat3"  # the same for the FMI 3.0 FMUs


def system_names() -> list:
    """The systems the product ships (system_ssp/systems/<name>.ssd), built or not."""
    return sorted(p.stem for p in SYSTEM_SOURCES.glob("*.ssd"))

"""The product's applications on top of the master: the thesis validation cases (`thesis`), the
de-orbit lifetime study (`deorbit_study`) and the NEIGHBOR mission (`mission`). Each has a
`main(argv)` behind a subcommand of `neighbor-cosim` / `python -m system_ssp`."""
import logging
from pathlib import Path
import sys

# Where `python build_fmus.py` packs the systems, in a source checkout (the documented install).
DEFAULT_SSP_DIR = Path(__file__).resolve().parents[2] / "build" / "ssp"


LOG_LEVELS = ("error", "warning", "info", "debug")


def add_console_arguments(ap, progress=True):
    """--progress / --quiet and --log-level, the same for `run` and every application (no progress
    options for an application of short runs)."""
    ap.set_defaults(progress=False, quiet=not progress)
    if progress:
        bar = ap.add_mutually_exclusive_group()
        bar.add_argument("--progress", action="store_true",
                         help="show the progress bar (default: when stderr is a terminal)")
        bar.add_argument("--quiet", "--no-progress", dest="quiet", action="store_true", help="no progress bar")
    ap.add_argument("--log-level", choices=LOG_LEVELS, default="warning",
                    help="messages of the master and the FMUs shown on stderr: error, warning (default), info (the "
                    "FMUs run with logging on) or debug (also the traceback of an unexpected error)")


def console_settings(args):
    """Apply --log-level to the `system_ssp` loggers (one handler on stderr); True when the
    progress bar should show."""
    log = logging.getLogger("system_ssp")
    log.setLevel(getattr(logging, args.log_level.upper()))
    for handler in [h for h in log.handlers if getattr(h, "_neighbor_console", False)]:
        log.removeHandler(handler)
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(logging.Formatter("%(levelname)s %(name)s: %(message)s"))
    handler._neighbor_console = True
    # an FMU's error and fatal messages are part of the error line the command prints
    handler.addFilter(lambda record: not (record.name == "system_ssp.fmu" and record.levelno >= logging.ERROR))
    log.addHandler(handler)
    if args.quiet:
        return False
    return bool(args.progress) or sys.stderr.isatty()

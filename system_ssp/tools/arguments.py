"""The command line's options, shared by every subcommand: argument types, the parser whose
refusal is one line, --progress/--quiet and --log-level and what they set. Nothing here imports
numpy, FMPy or the master, so that `neighbor-cosim --help` and `--version` start in a blink."""
import argparse
import logging
import math
import sys


LOG_LEVELS = ("error", "warning", "info", "debug")


def finite_float(text: str) -> float:
    """An option's number: finite (NaN, inf refused as the option is read)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"{text!r}: expected a finite number")
    return value


def positive_float(text: str) -> float:
    """A duration or a limit: a finite number > 0."""
    value = finite_float(text)
    if value <= 0:
        raise argparse.ArgumentTypeError(f"{text!r}: expected a number > 0")
    return value


def whole_number(lowest: int):
    """An option type: a whole number >= `lowest`."""
    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            value = lowest - 1
        if value < lowest:
            raise argparse.ArgumentTypeError(f"{text!r}: expected a whole number >= {lowest}")
        return value
    return parse


positive_int = whole_number(1)  # a count
run_index = whole_number(0)  # a campaign's run


class ArgumentParser(argparse.ArgumentParser):
    """argparse's parser whose refusal is one line (not the usage and then the error), exit 2,
    like every other refusal of the commands."""

    def error(self, message):
        self.exit(2, f"error: {self.prog}: {message} (--help shows the options)\n")


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


def release_console():
    """Remove the stderr handler `console_settings` added (the stream it holds may be gone after
    the command: a caller's captured stderr)."""
    log = logging.getLogger("system_ssp")
    for handler in [h for h in log.handlers if getattr(h, "_neighbor_console", False)]:
        log.removeHandler(handler)


def console_settings(args):
    """Apply --log-level to the `system_ssp` loggers (one handler on stderr); True when the
    progress bar should show."""
    log = logging.getLogger("system_ssp")
    log.setLevel(getattr(logging, args.log_level.upper()))
    release_console()
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(logging.Formatter("%(levelname)s %(name)s: %(message)s"))
    handler._neighbor_console = True
    # an FMU's error and fatal messages are part of the error line the command prints
    handler.addFilter(lambda record: not (record.name == "system_ssp.fmu" and record.levelno >= logging.ERROR))
    log.addHandler(handler)
    if args.quiet:
        return False
    return bool(args.progress) or sys.stderr.isatty()

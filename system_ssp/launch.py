"""The first code of the `neighbor-cosim` command (and `python -m system_ssp`): it installs the
signal handlers before the second or so of imports, so that Ctrl-C, SIGTERM or SIGHUP then end
the command at once with one line and the signal's exit code instead of a traceback. Nothing has
been written at that point; the command line (system_ssp.cli) takes the signals over once the
subcommand's module and its imports are loaded."""
import os
import signal
import sys

SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


def _during_startup(signum, frame):
    os.write(2, f"interrupted ({signal.Signals(signum).name})\n".encode())
    os._exit(128 + signum)


def console_main():
    """Entry point of the `neighbor-cosim` command."""
    for sig in SIGNALS:
        signal.signal(sig, _during_startup)
    from .cli import main  # the imports (numpy, fmpy, lxml, the models) take about a second

    sys.exit(main())

"""`neighbor-cosim plot RESULT [SIGNAL ...] [--out FILE.png|.svg|.html]`: draw signals of a result
file against time.

RESULT is what `run --output` (or `Result.write`) wrote: a CSV file with its `<name>.units.json`
sidecar, or a Parquet file (units in its metadata). SIGNALs are `component.variable` names or
shell-style globs (`dynamics.q_BN*`, `*.omega_BN_B[[]1]`); none: every column (see
system_ssp.master.plotting).
"""
from pathlib import Path
import sys
from typing import Optional, Sequence

from ..atomic import check_output_place
from ..master.plotting import FORMATS, default_signals, drawable, plot, read_result, select
from .console import ArgumentParser


def main(argv: Optional[Sequence[str]] = None) -> int:
    ap = ArgumentParser(prog="neighbor-cosim plot", description=__doc__.split("\n\n")[0])
    ap.add_argument("result", help="a result file: .csv (with its .units.json) or .parquet")
    ap.add_argument("signals", nargs="*", help="component.variable names or globs (default: every column)")
    ap.add_argument("--out", help="the figure: .png (default: beside RESULT), .svg, or .html (interactive, one file)")
    ap.add_argument("--title", default=None, help="the figure's title (default: the result file's name)")
    args = ap.parse_args(argv)
    out = Path(args.out) if args.out else Path(args.result).with_suffix(".png")
    check_output_place(out, "--out" if args.out else "figure", FORMATS)
    columns, units = read_result(args.result)
    note = ""
    if args.signals:
        signals = select(list(columns), args.signals, f"{args.result}: ")
    else:
        signals, note = default_signals(drawable(columns, list(columns)), units)
    path = plot(columns, units, signals, out, args.title if args.title is not None else Path(args.result).name)
    print(f"{len(signals)} signal(s) of {args.result} in {path}" + (f" ({note})" if note else ""))
    return 0


if __name__ == "__main__":
    sys.exit(main())

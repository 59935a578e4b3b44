"""Regenerate the product's systems, or check that the committed ones are up to date.

    python -m system_ssp.systems                  # rewrite system_ssp/systems/ in place
    python -m system_ssp.systems --out DIR        # write into DIR (DIR/<name>.ssd, DIR/parameters/)
    python -m system_ssp.systems --check          # regenerate into a temporary folder and compare

The generators read the FMUs' connectors from build/fmus (`python build_fmus.py` first).
`--check` exits 1 and names every committed file that differs from its generator's output,
every generated file that is not committed, and every committed .ssd/.ssv no generator writes.
"""
import argparse
import difflib
from pathlib import Path
import sys
import tempfile

from ..locations import FMU_DIR as DEFAULT_FMU_DIR
from ..ssp.writer import GeneratorError, SystemWriter
from . import SYSTEMS_DIR
from .generators import GENERATORS, generate_all


def committed_files(directory):
    directory = Path(directory)
    return sorted(p.relative_to(directory) for p in [*directory.glob("*.ssd"), *directory.glob("parameters/*.ssv")])


def check(fmu_dir, only=None, committed_dir=SYSTEMS_DIR):
    """Regenerate into a temporary folder and compare with `committed_dir`; returns the problems,
    each naming a file."""
    committed_dir = Path(committed_dir)
    problems = []
    with tempfile.TemporaryDirectory(prefix="neighbor_systems_") as tmp:
        writer = SystemWriter(tmp, fmu_dir)
        generated = sorted(p.relative_to(tmp) for p in generate_all(writer, only))
        for rel in generated:
            committed = committed_dir / rel
            if not committed.is_file():
                problems.append(f"{committed}: generated but not committed")
                continue
            new, old = (Path(tmp) / rel).read_text(), committed.read_text()
            if new != old:
                diff = list(difflib.unified_diff(old.splitlines(), new.splitlines(), f"committed {rel}",
                                                 f"generated {rel}", lineterm="", n=0))
                problems.append(f"{committed}: differs from its generator's output ("
                                f"{sum(1 for d in diff if d[:1] in '+-') - 2} lines); first lines:\n  "
                                + "\n  ".join(diff[2:8]))
        if only is None:
            for rel in committed_files(committed_dir):
                if rel not in set(generated):
                    problems.append(f"{committed_dir / rel}: committed but no generator writes it")
    return problems


def main(argv=None):
    ap = argparse.ArgumentParser(prog="python -m system_ssp.systems", description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, default=SYSTEMS_DIR, help="folder to write into (default: %(default)s)")
    ap.add_argument("--fmu-dir", type=Path, default=DEFAULT_FMU_DIR, help="built FMUs (default: %(default)s)")
    ap.add_argument("--check", action="store_true", help="compare the committed files with a fresh generation")
    ap.add_argument("--only", action="append", choices=list(GENERATORS), help="run only this generator (repeatable)")
    args = ap.parse_args(argv)
    try:
        if args.check:
            problems = check(args.fmu_dir, args.only)
            for p in problems:
                print(f"out of date: {p}", file=sys.stderr)
            if problems:
                print("regenerate with `python -m system_ssp.systems` and commit the result", file=sys.stderr)
                return 1
            print(f"the committed systems in {SYSTEMS_DIR} match their generators")
            return 0
        written = generate_all(SystemWriter(args.out, args.fmu_dir), args.only)
    except (GeneratorError, ValueError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    print(f"wrote {len(written)} files into {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""fmusim, the Modelica Reference-FMUs' C simulator (vendored sources: tests/fmus/fmusim/README.md),
compiled once per source version and run the way a user runs it: its own process, no Python in
its environment (the FMU's runtime finds one on the machine)."""
import csv
import hashlib
import os
import re
from pathlib import Path
import shutil
import subprocess

import numpy as np

SOURCES = Path(__file__).with_name("fmusim")
# A C host's environment: nothing that points at a Python.
CLEAN_ENV = {"PATH": "/usr/bin:/bin", "HOME": os.environ.get("HOME", "/tmp")}


class MissingPackages(RuntimeError):
    """What this machine lacks to compile fmusim: the Debian packages, named (the tests skip)."""


# Debian packages fmusim's compilation needs, each with the file that shows it is installed
NEEDS = {"gcc": "/usr/bin/gcc", "libxml2-dev": "/usr/include/libxml2/libxml/parser.h",
         "libminizip-dev": "/usr/include/minizip/unzip.h", "zlib1g-dev": "/usr/include/zlib.h"}


def missing_packages():
    """The Debian packages of NEEDS that this machine lacks (empty when fmusim can be compiled)."""
    return [name for name, landmark in NEEDS.items()
            if not (shutil.which("gcc") if name == "gcc" else Path(landmark).is_file())]


def build(dest_dir):
    """The fmusim executable compiled from the vendored sources into `dest_dir` (kept per source
    digest). Needs gcc, libxml2, minizip and zlib (NEEDS); MissingPackages names what is not
    installed."""
    files = sorted(p for p in SOURCES.rglob("*") if p.suffix in (".c", ".h"))
    digest = hashlib.sha256(b"".join(p.read_bytes() for p in files)).hexdigest()[:12]
    exe = Path(dest_dir) / f"fmusim-{digest}"
    if exe.is_file():
        return exe
    missing = missing_packages()
    if missing:
        raise MissingPackages(f"fmusim cannot be compiled here: apt install {' '.join(missing)} "
                              "(as .ci/run does)")
    exe.parent.mkdir(parents=True, exist_ok=True)
    tmp = exe.with_name(exe.name + f".{os.getpid()}.tmp")
    cmd = ["gcc", "-O1", "-w", '-DFMUSIM_VERSION="0.0.39"', f"-I{SOURCES / 'fmusim'}", f"-I{SOURCES / 'include'}",
           "-I/usr/include/libxml2", "-I/usr/include/minizip",
           *[str(p) for p in sorted((SOURCES / "fmusim").glob("*.c"))], str(SOURCES / "no_cvode.c"),
           *[str(p) for p in sorted((SOURCES / "src").glob("*.c"))],
           "-o", str(tmp), "-lxml2", "-lminizip", "-lz", "-ldl", "-lm"]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0:
        raise RuntimeError(f"compiling fmusim failed:\n{proc.stderr[-3000:]}")
    os.replace(tmp, exe)
    return exe


def command(exe, fmu, out_csv, stop_time, step):
    """fmusim's command line: `fmu` as co-simulation to `stop_time`, communication step `step`,
    the result into `out_csv`."""
    return [str(exe), "--interface-type", "cs", "--stop-time", repr(stop_time), "--output-interval", repr(step),
            "--output-file", str(out_csv), "--log-level", "error", str(fmu)]


def run(exe, fmu, out_csv, stop_time, step):
    """Run `fmu` in fmusim with no Python in its environment; the completed process."""
    return subprocess.run(command(exe, fmu, out_csv, stop_time, step), capture_output=True, text=True,
                          env=CLEAN_ENV, timeout=120)


def read(out_csv):
    """{variable: rows x elements array} of fmusim's CSV: an FMI 3.0 array's cell ("a b c") and an
    FMI 2.0 FMU's element columns (name[1], name[2], .. or name[1,1], name[1,2], .. in the
    order written) both become the variable's elements, so twins compare directly."""
    with open(out_csv, newline="") as f:
        rows = list(csv.reader(f))
    header, body = rows[0], rows[1:]
    columns = {}
    for k, name in enumerate(header):
        cells = [row[k] for row in body]
        base = re.sub(r"\[[\d,]+\]$", "", name)
        values = np.array([[_number(x) for x in cell.split()] or [float("nan")] for cell in cells], dtype=object)
        columns.setdefault(base, []).append(values)
    return {base: np.hstack(parts) for base, parts in columns.items()}


def _number(text):
    text = text.strip()
    if text in ("true", "false"):
        return float(text == "true")
    try:
        return float(text)
    except ValueError:
        return text

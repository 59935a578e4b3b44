"""How much an input may make the tools allocate: a hostile or mistyped number (`runs = 1e12`) or
a small archive that unpacks to gigabytes is refused in one line before any work, instead of
ending in MemoryError or a full disk.

Each limit has a default sized far above any NEIGHBOR system or campaign and an environment
variable that raises (or lowers) it, e.g. `NEIGHBOR_COSIM_MAX_RUNS=50000000 neighbor-cosim campaign ...`.
The README's Errors section lists them (a test keeps it equal to LIMITS)."""
from dataclasses import dataclass
import os
from pathlib import Path
from typing import Dict

from .errors import SSPError


@dataclass(frozen=True)
class Limit:
    name: str
    default: int
    what: str

    @property
    def variable(self) -> str:
        return f"NEIGHBOR_COSIM_{self.name.upper()}"


LIMITS: Dict[str, Limit] = {limit.name: limit for limit in (
    Limit("max_runs", 1_000_000, "runs of one campaign (campaign.runs times its sweep points)"),
    Limit("max_vector_elements", 100_000, "elements of one vector dispersion (`elements = n`)"),
    Limit("max_spec_bytes", 10 * 2**20, "size of a campaign spec or a mission summary file"),
    Limit("max_archive_members", 100_000, "members of one .ssp or .fmu archive"),
    Limit("max_archive_bytes", 4 * 2**30, "bytes one .ssp or .fmu archive unpacks to (all members together)"),
    Limit("max_compression_ratio", 200, "unpacked over packed size of one archive member over 1 MiB (text and "
                                        "binaries pack 3 to 20 to 1, a zip bomb 1000 to 1 and more)"),
)}


def limit(name: str) -> int:
    """The limit `name`, from its environment variable when set there (a positive integer)."""
    entry = LIMITS[name]
    text = os.environ.get(entry.variable)
    if text is None or not text.strip():
        return entry.default
    try:
        value = int(float(text)) if text.strip().lower() not in ("inf", "nan") else -1
    except ValueError:
        value = -1
    if value <= 0:
        raise SSPError(f"{entry.variable}={text!r}: expected a positive whole number (the limit on {entry.what}; "
                       f"default {entry.default})")
    return value


def refuse_over(name: str, value: float, what: str) -> None:
    """SSPError when `value` is over the limit `name`; `what` names the input (file and key)."""
    most = limit(name)
    if value > most:
        shown = f"{value:,}" if isinstance(value, int) else f"{value:,.0f}"
        raise SSPError(f"{what}: {shown} is over the limit of {most:,} {LIMITS[name].what.split(' (')[0]} "
                       f"(set {LIMITS[name].variable} to allow more)")


def read_text_input(path: Path, where: str, kind: str, hint: str) -> str:
    """The UTF-8 text of a small input file (a campaign spec, a mission summary), its size bounded
    by max_spec_bytes; SSPError beginning with `where` (the file, or the option and the file):
    cannot read `kind`, too big, or not UTF-8 (with the line and the byte, then `hint`)."""
    try:
        refuse_over("max_spec_bytes", path.stat().st_size, f"{where}: {kind}'s size in bytes")
        return path.read_text(encoding="utf-8")
    except OSError as exc:
        raise SSPError(f"{where}: cannot read {kind} ({exc.strerror or exc})") from None
    except UnicodeDecodeError as exc:
        line = exc.object[:exc.start].count(b"\n") + 1
        raise SSPError(f"{where}:{line}: not UTF-8 text (byte {exc.object[exc.start]:#04x}); {hint}") from None


def markdown_table() -> str:
    """The limits as the README's table."""
    rows = ["| limit | default | environment variable |", "|---|---|---|"]
    for entry in LIMITS.values():
        rows.append(f"| {entry.what} | {entry.default:,} | `{entry.variable}` |")
    return "\n".join(rows)

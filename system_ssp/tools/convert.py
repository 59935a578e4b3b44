"""`neighbor-cosim convert SYSTEM --ssp-version 2.0 --out NEW.ssp`: the same system in the other
SSP version, for tools that read only one.

SSP 2.0 keeps SSP 1.0's namespaces and elements; a file says which it is by its root's version
attribute. To 2.0: every SSD, SSV and SSM of the system (and the parameter sets and mappings
written inline in the SSD) says version="2.0". To 1.0: also SSP 2.0's sized scalar types become
SSP 1.0's (Float64, Float32 -> Real; Int8 .. UInt64 -> Integer); what SSP 1.0 cannot say (clocks,
arrays) is refused by the reader before anything is written. The result is loaded by the master
(checked against the target version's schemas, FMUs and connections) before it is kept.
"""
from pathlib import Path
import tempfile

from lxml import etree

from ..atomic import check_output_place
from ..errors import SSPError
from ..master import System
from ..ssp.reader import NS_SSC, NS_SSD, NS_SSM, NS_SSV, SSP2_TYPES
from .console import ArgumentParser, system_path
from .replace import _pack, _unpack

VERSIONS = ("1.0", "2.0")
ROOTS = {f"{{{NS_SSD}}}SystemStructureDescription", f"{{{NS_SSV}}}ParameterSet", f"{{{NS_SSM}}}ParameterMapping"}


def convert_system(source, version, out):
    """Write `out` (.ssp): the system at `source` in SSP `version` ("1.0" or "2.0"). Returns the
    files rewritten, relative to the system's folder."""
    if version not in VERSIONS:
        raise SSPError(f"--ssp-version {version!r}: expected one of {', '.join(VERSIONS)}")
    out = check_output_place(out, "--out", (".ssp",))
    with System(source):  # it loads as it is: a refusal names the source's own files and lines
        pass
    with tempfile.TemporaryDirectory(prefix="neighbor_convert_") as tmp:
        root = Path(tmp) / "system"
        ssd = _unpack(source, root)
        files = [ssd] + sorted(p for p in root.rglob("*") if p.suffix.lower() in (".ssv", ".ssm") and p.is_file())
        rewritten = []
        for path in files:
            tree = etree.parse(str(path))
            if tree.getroot().tag not in ROOTS:
                continue  # not an SSP file (a tool's own XML next to the system)
            for el in tree.getroot().iter():
                if el.tag in ROOTS:
                    el.set("version", version)
                elif version == "1.0" and isinstance(el.tag, str):
                    q = etree.QName(el)
                    if q.namespace in (NS_SSC, NS_SSV) and q.localname in SSP2_TYPES:
                        el.tag = f"{{{q.namespace}}}{SSP2_TYPES[q.localname]}"
            tree.write(str(path), xml_declaration=True, encoding="UTF-8")
            rewritten.append(path.relative_to(root).as_posix())
        try:  # the converted system loads: the target version's schemas, FMUs, connections
            with System(ssd):
                pass
        except SSPError as exc:
            raise SSPError(f"{source} in SSP {version} does not load: {exc}") from None
        _pack(root, ssd, out)
    return rewritten


def main(argv=None):
    ap = ArgumentParser(prog="neighbor-cosim convert", description=__doc__.split("\n\n")[0])
    ap.add_argument("system", help=".ssp, .ssd, a folder with SystemStructure.ssd, or a shipped system's name")
    ap.add_argument("--ssp-version", required=True, choices=VERSIONS, help="the SSP version to write")
    ap.add_argument("--out", required=True, help="the converted system (.ssp)")
    args = ap.parse_args(argv)
    files = convert_system(system_path(args.system), args.ssp_version, args.out)
    print(f"wrote {args.out}: SSP {args.ssp_version} ({len(files)} files: {', '.join(files)})")
    return 0

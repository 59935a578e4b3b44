"""Helpers for the master's tests: build the fixture FMUs once per session, write SSDs."""
import json
from pathlib import Path
import shutil
import subprocess
import sys
import zipfile

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[2]
PY = sys.executable
SCRIPTS = {"gain": "mf_gain.py", "integrator": "mf_integrator.py", "threshold": "mf_threshold.py",
           "timer": "mf_timer.py", "text": "mf_text.py"}

_BUILD_SCRIPT = r"""
import json, sys
from pathlib import Path
repo, dest, scripts = sys.argv[1], sys.argv[2], json.loads(sys.argv[3])
sys.path.insert(0, repo)
sys.path.insert(0, str(Path(repo) / "fmus"))
out = {}
from build_fmus import build_fmu
for key, script in scripts.items():
    out[key] = str(build_fmu(script, dest))
out["_builder"] = "build_fmus.build_fmu"
print(json.dumps(out))
"""

_cache = {}


def build_fixture_fmus(dest):
    """Build the fixture FMUs into `dest` (once per process); returns {key: Path}."""
    if "fmus" in _cache:
        return _cache["fmus"]
    dest = Path(dest)
    dest.mkdir(parents=True, exist_ok=True)
    scripts = {k: str(HERE / v) for k, v in SCRIPTS.items()}
    proc = subprocess.run([PY, "-c", _BUILD_SCRIPT, str(REPO), str(dest), json.dumps(scripts)],
                          capture_output=True, text=True, timeout=300)
    if proc.returncode != 0:
        raise RuntimeError(f"building fixture FMUs failed:\n{proc.stdout}\n{proc.stderr}")
    out = json.loads(proc.stdout.strip().splitlines()[-1])
    builder = out.pop("_builder")
    fmus = {k: Path(v) for k, v in out.items()}
    _cache["fmus"] = fmus
    _cache["builder"] = builder
    return fmus


def builder_used():
    return _cache.get("builder")


def libcosim_rows(system, step, n, names, tmp_path):
    """libcosim's values of `names` after each of `n` steps of `step` s ("file": the system's
    own), run in a subprocess (see libcosim_run.py)."""
    import numpy as np
    out = tmp_path / "libcosim.json"
    proc = subprocess.run([PY, str(HERE / "libcosim_run.py"), str(system), str(step), str(n), str(out), *names],
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-3000:]
    return np.array(json.loads(out.read_text()))


SSD_HEAD = """<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription version="1.0" name="{name}"
    xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription"
    xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon"
    xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues"
    xmlns:ssm="http://ssp-standard.org/SSP1/SystemStructureParameterMapping">
"""


def component(name, fmu, connectors="", bindings=""):
    conn = f"<ssd:Connectors>{connectors}</ssd:Connectors>" if connectors else ""
    bind = f"<ssd:ParameterBindings>{bindings}</ssd:ParameterBindings>" if bindings else ""
    return (f'<ssd:Component name="{name}" type="application/x-fmu-sharedlibrary" '
            f'source="resources/{fmu}">{conn}{bind}</ssd:Component>\n')


def connection(a, b, inner=""):
    ae, ac = a.split(".", 1)
    be, bc = b.split(".", 1)
    return (f'<ssd:Connection startElement="{ae}" startConnector="{ac}" endElement="{be}" '
            f'endConnector="{bc}">{inner}</ssd:Connection>\n')


def ssd_text(elements, connections="", units="", experiment="", system_extra="", name="test", system_head=""):
    conns = f"<ssd:Connections>{connections}</ssd:Connections>" if connections else ""
    return (SSD_HEAD.format(name=name)
            + f'<ssd:System name="root">{system_head}<ssd:Elements>{elements}</ssd:Elements>{conns}'
            + f'{system_extra}</ssd:System>\n'
            + (f"<ssd:Units>{units}</ssd:Units>\n" if units else "")
            + experiment
            + "</ssd:SystemStructureDescription>\n")


def write_system(folder, fmus, uses, text, extra_files=None):
    """Write `text` as folder/SystemStructure.ssd and copy the FMUs {file name in resources: key}."""
    folder = Path(folder)
    (folder / "resources").mkdir(parents=True, exist_ok=True)
    for fname, key in uses.items():
        shutil.copy(fmus[key], folder / "resources" / fname)
    for rel, content in (extra_files or {}).items():
        p = folder / rel
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_text(content)
    ssd = folder / "SystemStructure.ssd"
    ssd.write_text(text)
    return ssd


def pack_ssp(folder, dest):
    """Zip a system folder into an .ssp archive."""
    folder = Path(folder)
    with zipfile.ZipFile(dest, "w") as z:
        for p in sorted(folder.rglob("*")):
            if p.is_file():
                z.write(p, p.relative_to(folder).as_posix())
    return Path(dest)


SSV_HEAD = ('<?xml version="1.0" encoding="UTF-8"?>\n<ssv:ParameterSet version="1.0" name="{name}" '
            'xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues" '
            'xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon">\n')


def ssv_text(params, units="", name="set"):
    """params: [(name, type, value, unit or None)]."""
    body = "".join(
        f'<ssv:Parameter name="{n}"><ssv:{t} value="{v}"{f" unit=&quot;{u}&quot;" if False else ""}'
        + (f' unit="{u}"' if u else "") + "/></ssv:Parameter>\n" for n, t, v, u in params)
    u = f"<ssv:Units>{units}</ssv:Units>" if units else ""
    return SSV_HEAD.format(name=name) + f"<ssv:Parameters>{body}</ssv:Parameters>{u}</ssv:ParameterSet>\n"

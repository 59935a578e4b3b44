"""The project's import structure: no import cycles anywhere, no project import hidden inside a
function, no module directly under components/ besides its __init__ (models live in domain
packages)."""
import ast
import re

from paths import REPO

PACKAGES = ("components", "system_ssp")


def module_name(path):
    parts = list(path.relative_to(REPO).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def project_modules():
    mods = {}
    for pkg in PACKAGES:
        for p in sorted((REPO / pkg).rglob("*.py")):
            mods[module_name(p)] = p
    return mods


def imports_of(name, path, modules):
    """(imported project module, line, inside a function) for every import statement of `path`."""
    tree = ast.parse(path.read_text(), str(path))
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    in_function = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            in_function.update(id(sub) for sub in ast.walk(node) if sub is not node)
    out = []
    for node in ast.walk(tree):
        targets = []
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[:len(base) - (node.level - 1)]
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module
            for a in node.names:
                # `from pkg import sub` imports the submodule sub; `from mod import name`, mod itself
                targets.append(f"{mod}.{a.name}" if f"{mod}.{a.name}" in modules else mod)
        for t in targets:
            if t in modules:
                out.append((t, node.lineno, id(node) in in_function))
    return out


def find_cycle(graph):
    """One cycle [a, b, ..., a] in a {node: set(nodes)} graph, or None (iterative DFS)."""
    color = {}
    for root in sorted(graph):
        if color.get(root):
            continue
        stack = [(root, iter(sorted(graph[root])))]
        path = [root]
        color[root] = 1
        while stack:
            node, it = stack[-1]
            nxt = next(it, None)
            if nxt is None:
                color[node] = 2
                stack.pop()
                path.pop()
            elif color.get(nxt) == 1:
                return path[path.index(nxt):] + [nxt]
            elif not color.get(nxt):
                color[nxt] = 1
                stack.append((nxt, iter(sorted(graph.get(nxt, ())))))
                path.append(nxt)
    return None


def test_no_import_cycles():
    modules = project_modules()
    graph = {name: {t for t, _, _ in imports_of(name, path, modules) if t != name} for name, path in modules.items()}
    assert len(modules) > 80  # the walk found the project
    cycle = find_cycle(graph)
    assert cycle is None, "import cycle: " + " -> ".join(cycle)


def test_find_cycle_finds_one():
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]
    assert find_cycle({"a": {"b"}, "b": set()}) is None


# The imports that must wait for a function to run: the command's first code installs its signal
# handlers and only then imports the command line (a second of numpy, fmpy, lxml; the package's
# __init__ gives the master's names on first use for the same reason, by importlib); the master
# imports its compiled loop, and numba with it (about a second), only for a run the loop repays.
DEFERRED = {("system_ssp.launch", "system_ssp.cli"), ("system_ssp.master.algorithms", "system_ssp.master.compiled")}


def test_no_project_import_inside_a_function():
    modules = project_modules()
    hidden = [f"{path.relative_to(REPO)}:{line} imports {t}" for name, path in modules.items()
              for t, line, inside in imports_of(name, path, modules) if inside and (name, t) not in DEFERRED]
    assert hidden == []


def test_components_has_only_domain_packages():
    loose = sorted(p.name for p in (REPO / "components").glob("*.py") if p.name != "__init__.py")
    assert loose == []
    domains = sorted(p.name for p in (REPO / "components").iterdir() if (p / "__init__.py").is_file())
    assert domains == ["acs", "attitude", "core", "environment", "mission", "orbit", "sensing"]


def _imports_from(prefix, forbidden):
    """`file:line imports X` for every import of a module under `forbidden` by a module under `prefix`."""
    modules = project_modules()
    return [f"{path.relative_to(REPO)}:{line} imports {t}" for name, path in modules.items()
            if name == prefix or name.startswith(prefix + ".")
            for t, line, _ in imports_of(name, path, modules)
            if any(t == f or t.startswith(f + ".") for f in forbidden)]


def test_master_and_ssp_know_no_models_and_no_application():
    """The master and the SSP files serve any system: nothing of the models or of NEIGHBOR."""
    for pkg in ("system_ssp.master", "system_ssp.ssp"):
        assert _imports_from(pkg, ("components", "system_ssp.neighbor", "system_ssp.tools")) == []


def test_generic_tools_know_no_application():
    """The tools serve any SSP system. The one model they use is the space-weather file the
    campaign's `solar_activity` helper scales (an Earth-orbit helper, not a NEIGHBOR one)."""
    assert _imports_from("system_ssp.tools", ("system_ssp.neighbor",)) == []
    assert [re.sub(r":\d+ ", " ", found) for found in _imports_from("system_ssp.tools", ("components",))] == [
        "system_ssp/tools/campaign/worker.py imports components.environment.space_weather"]

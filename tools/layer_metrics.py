"""Layering metrics of the package: import circles, function-level imports,
casts of study parameters and long functions, measured from the source with :mod:`ast`.

Run from the repository root::

    python tools/layer_metrics.py            # summary
    python tools/layer_metrics.py --details  # plus every circle, deferred import and long function

Import circles are the strongly connected components (more than one module) of the graph of
imports between the package's own modules, module-level and function-level imports alike (a
function-level import hides a circle from Python, not from the design). A module imports its
package's ``__init__`` implicitly; those edges are left out (they are not in the source), but an explicit
``from package import name`` in a submodule is an edge: with a package that imports the submodule back it is
a circle that Python reports as a partially initialised module.
"""

from __future__ import annotations

import argparse
import ast
import sys
from pathlib import Path

LONG = 80  # lines: a function longer than this counts as long


def module_name(path: Path, root: Path) -> str:
    parts = list(path.relative_to(root).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def resolve(node: ast.ImportFrom, mod: str, is_pkg: bool) -> str:
    if node.level == 0:
        return node.module or ""
    base = mod.split(".")
    base = base if is_pkg else base[:-1]
    base = base[: len(base) - (node.level - 1)]
    return ".".join(base + ([node.module] if node.module else []))


def targets(node: ast.AST, mod: str, is_pkg: bool, known: set[str]) -> list[str]:
    """The package modules an import statement names (``from . import x`` names submodule x)."""
    out: list[str] = []
    if isinstance(node, ast.Import):
        out = [a.name for a in node.names]
    elif isinstance(node, ast.ImportFrom):
        base = resolve(node, mod, is_pkg)
        for a in node.names:
            sub = f"{base}.{a.name}"
            out.append(sub if sub in known else base)
    return [t for t in out if t in known]


def scc(graph: dict[str, set[str]]) -> list[list[str]]:
    """Tarjan's strongly connected components, iterative."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    comps: list[list[str]] = []
    counter = 0
    for root in graph:
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on.add(root)
        while work:
            v, it = work[-1]
            advanced = False
            for w in it:
                if w not in index:
                    index[w] = low[w] = counter
                    counter += 1
                    stack.append(w)
                    on.add(w)
                    work.append((w, iter(sorted(graph[w]))))
                    advanced = True
                    break
                if w in on:
                    low[v] = min(low[v], index[w])
            if advanced:
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[v])
            if low[v] == index[v]:
                comp = []
                while True:
                    w = stack.pop()
                    on.discard(w)
                    comp.append(w)
                    if w == v:
                        break
                if len(comp) > 1:
                    comps.append(sorted(comp))
    return comps


def _is_study_param(arg: ast.AST) -> bool:
    """``x.param(...)``, ``x.params.key``, ``x.params[...]``, ``x.raw_params[...]``: a study parameter."""
    if isinstance(arg, ast.Call) and isinstance(arg.func, ast.Attribute):
        return arg.func.attr in {"param", "get_param"}
    if isinstance(arg, (ast.Attribute, ast.Subscript)) and isinstance(arg.value, ast.Attribute):
        return arg.value.attr in {"params", "raw_params"}
    return False


def is_param_cast(node: ast.AST) -> bool:
    """``float(study.param(...))``, ``int(study.params.n)``, ``float(v) for v in study.params.x`` and the like: a
    cast of a study parameter (study code receives its typed Params and never casts)."""
    if not (isinstance(node, ast.Call) and isinstance(node.func, ast.Name)):
        return False
    if node.func.id not in {"float", "int", "bool", "str", "tuple", "list"} or len(node.args) != 1:
        return False
    arg = node.args[0]
    if node.func.id in {"float", "int", "bool", "str"} and _is_study_param(arg):
        return True
    # a cast applied to every element: float(v) for v in study.params.x; map(float, study.params.x)
    if isinstance(arg, ast.GeneratorExp):
        gen = arg.generators[0]
        elt = arg.elt
        return (
            _is_study_param(gen.iter)
            and isinstance(elt, ast.Call)
            and isinstance(elt.func, ast.Name)
            and elt.func.id in {"float", "int"}
        )
    return False


def _is_elementwise_cast(node: ast.AST) -> bool:
    """``[float(v) for v in study.params.x]`` or ``map(float, study.params.x)``."""
    if isinstance(node, ast.ListComp):
        elt, it = node.elt, node.generators[0].iter
        return (
            _is_study_param(it)
            and isinstance(elt, ast.Call)
            and isinstance(elt.func, ast.Name)
            and elt.func.id in {"float", "int"}
        )
    if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id == "map" and len(node.args) == 2:
        f, it = node.args
        return isinstance(f, ast.Name) and f.id in {"float", "int"} and _is_study_param(it)
    return False


def measure(root: Path, package: str, extra: list[Path]) -> dict:
    files = sorted((root / package).rglob("*.py"))
    mods = {module_name(f, root): f for f in files}
    known = set(mods)
    graph: dict[str, set[str]] = {m: set() for m in mods}
    external: dict[str, set[str]] = {m: set() for m in mods}  # module -> the outside packages it imports
    deferred, deferred_own, casts, long_funcs, unexplained = [], [], [], [], []
    for mod, f in mods.items():
        text = f.read_text()
        lines = text.split("\n")
        tree = ast.parse(text, filename=str(f))
        is_pkg = f.name == "__init__.py"
        for node in ast.walk(tree):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                n = node.end_lineno - node.lineno + 1
                if n > LONG:
                    long_funcs.append((n, f"{f.relative_to(root)}:{node.lineno} {node.name}"))
                for sub in ast.walk(node):
                    if isinstance(sub, (ast.Import, ast.ImportFrom)):
                        where = f"{f.relative_to(root)}:{sub.lineno}"
                        deferred.append(where)
                        # the reason on any line of the statement (a formatter may wrap it into parentheses)
                        if not any("# deferred" in ln for ln in lines[sub.lineno - 1 : sub.end_lineno]):
                            unexplained.append(where)
                        if targets(sub, mod, is_pkg, known):
                            deferred_own.append(where)
            if isinstance(node, ast.Import):
                external[mod] |= {a.name.split(".")[0] for a in node.names} - {package}
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                external[mod] |= {node.module.split(".")[0]} - {package}
            if isinstance(node, (ast.Import, ast.ImportFrom)):
                for t in targets(node, mod, is_pkg, known):
                    if t != mod:  # an explicit import of a parent package is an edge too (a real circle if it
                        graph[mod].add(t)  # imports this module back)
        casts += [
            f"{f.relative_to(root)}:{n.lineno}" for n in ast.walk(tree) if is_param_cast(n) or _is_elementwise_cast(n)
        ]
    for f in extra:
        tree = ast.parse(f.read_text(), filename=str(f))
        casts += [
            f"{f.relative_to(root)}:{n.lineno}" for n in ast.walk(tree) if is_param_cast(n) or _is_elementwise_cast(n)
        ]
        for node in ast.walk(tree):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                n = node.end_lineno - node.lineno + 1
                if n > LONG:
                    long_funcs.append((n, f"{f.relative_to(root)}:{node.lineno} {node.name}"))
    # deferred imports are counted once per statement (ast.walk visits nested functions twice)
    deferred, deferred_own = sorted(set(deferred)), sorted(set(deferred_own))
    return {
        "modules": len(mods),
        "circles": scc(graph),
        "function_level_imports": deferred,
        "function_level_own_imports": deferred_own,
        "function_level_imports_without_reason": sorted(set(unexplained)),
        "param_casts": casts,
        "long_functions": sorted(set(long_funcs), reverse=True),
        "graph": graph,
        "external": external,
    }


# The layers of hhscatter, bottom up, and the layers each may import (besides itself). A module's layer is its
# first package component below hhscatter (``hhscatter.scene.grid`` -> ``scene``); inside ``analysis`` it is the
# subpackage (``hhscatter.analysis.survival.fits`` -> ``analysis.survival``), so that the estimators are layered
# too: stats -> survival -> {dissipative, noise} -> geometry. ``errors`` and ``outcomes`` are the bottom.
BASE = {"errors", "outcomes", "_version", "_exports"}  # what every layer shares: the error family, the outcome names,
# the version, the lazy exports of a package
ANALYSIS_ORDER = {  # the subpackages of analysis and the subpackages each may import (besides itself)
    "stats": set(),
    "survival": {"stats"},
    "dissipative": {"stats", "survival"},
    "noise": {"stats", "survival"},
    "geometry": {"stats", "survival", "noise"},
}
ANALYSIS = {"analysis"} | {f"analysis.{sub}" for sub in ANALYSIS_ORDER}  # the package door and its subpackages
LAYERS = {
    "errors": set(),
    "outcomes": set(),
    "_version": set(),
    "_exports": set(),
    "model": BASE,
    "scene": BASE | {"model"},
    "integrate": BASE,  # the engine reads a scene only through its plan, which carries the system: no scene, no model
    "data": BASE | {"model", "scene"},
    "run": BASE | {"model", "scene", "integrate", "data"},
    "analysis": BASE | {"model"},
    **{
        f"analysis.{sub}": BASE | {"model", "analysis"} | {f"analysis.{d}" for d in below}
        for sub, below in ANALYSIS_ORDER.items()
    },
    "reproduction": BASE | {"model"} | ANALYSIS,
    "api": BASE | {"model", "scene", "data", "run"} | ANALYSIS,
    "studies": BASE | {"model", "scene", "integrate", "data", "run", "api", "reproduction"} | ANALYSIS,
    "publish": BASE | {"model", "scene", "data", "api", "studies", "reproduction"} | ANALYSIS,
}
TOP = {"", "__main__", "cli"}  # the package's door and the CLI may import any layer
# outside packages only some layers may import: heyoka only the engine (the model builds its expressions with the
# heyoka module the engine hands it; the data layer reads heyoka's version from its distribution)
CONFINED = {"heyoka": {"integrate"}}


def layer_of(mod: str, package: str = "hhscatter") -> str:
    """The layer of module ``mod``: its first component below ``package``, the subpackage inside analysis."""
    parts = (mod[len(package) + 1 :] if mod.startswith(package + ".") else "").split(".")
    if parts[0] == "analysis" and len(parts) > 1 and parts[1] in ANALYSIS_ORDER:
        return f"analysis.{parts[1]}"
    return parts[0]


def layer_violations(graph: dict[str, set[str]], package: str = "hhscatter") -> list[str]:
    """layer_violations(graph) -> "a -> b (layer x may not import layer y)" for every import against LAYERS."""
    out = []
    for mod, deps in sorted(graph.items()):
        src = layer_of(mod, package)
        if src in TOP:
            continue
        if src not in LAYERS:
            out.append(f"{mod}: not in a declared layer")
            continue
        for dep in sorted(deps):
            dst = layer_of(dep, package)
            if dst != src and dst not in LAYERS[src]:
                out.append(f"{mod} -> {dep} (layer {src} may not import layer {dst or package})")
    return out


def confined_violations(external: dict[str, set[str]], package: str = "hhscatter") -> list[str]:
    """confined_violations(measure(...)["external"]) -> "module -> heyoka (only integrate may import it)" for every
    import of a package of CONFINED outside the layers that may import it."""
    return [
        f"{mod} -> {dep} (only {', '.join(sorted(CONFINED[dep]))} may import it)"
        for mod, deps in sorted(external.items())
        for dep in sorted(deps & set(CONFINED))
        if layer_of(mod, package) not in CONFINED[dep]
    ]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--root", type=Path, default=Path("."))
    ap.add_argument("--package", default="hhscatter")
    ap.add_argument("--details", action="store_true")
    args = ap.parse_args(argv)
    extra = sorted((args.root / "studies").rglob("*.py"))
    m = measure(args.root, args.package, extra)
    print(f"modules: {m['modules']}")
    print(f"import circles: {len(m['circles'])}")
    print(
        f"function-level imports: {len(m['function_level_imports'])} "
        f"({len(m['function_level_own_imports'])} of the package's own modules, "
        f"{len(m['function_level_imports_without_reason'])} without a '# deferred: reason' comment)"
    )
    print(f"casts of study parameters: {len(m['param_casts'])}")
    print(f"functions over {LONG} lines: {len(m['long_functions'])}")
    if args.package == "hhscatter":
        print(f"imports against the layers: {len(layer_violations(m['graph']))}")
        print(f"imports of confined packages outside their layers: {len(confined_violations(m['external']))}")
    if args.details:
        for c in m["circles"]:
            print("circle:", " -> ".join(c))
        if args.package == "hhscatter":
            for v in layer_violations(m["graph"]):
                print("against the layers:", v)
        for n, where in m["long_functions"]:
            print(f"long: {n:4d} {where}")
        for where in m["function_level_own_imports"]:
            print("deferred own import:", where)
        for where in m["function_level_imports_without_reason"]:
            print("deferred import without a reason:", where)
        for where in m["param_casts"]:
            print("cast:", where)
    return 0


if __name__ == "__main__":
    sys.exit(main())

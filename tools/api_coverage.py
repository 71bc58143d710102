"""Measure the API reference: type hints on public parameters and numpy sections in public docstrings.

    python tools/api_coverage.py            # the modules of docs/api (every '::: hhscatter.x' line)
    python tools/api_coverage.py --top      # the top-level public objects of hhscatter (hhscatter.__all__)
    python tools/api_coverage.py --detail   # also list each object that lacks a hint or a section

Public = the module's ``__all__`` when it has one, else the names without a leading underscore defined in the
module (what mkdocstrings shows with ``filters: ["!^_"]``). Counted per public function and class: its
parameters (``self``/``cls`` excluded; a class's are its constructor's) and, for functions and public methods
defined in the class body, the return annotation. Sections are a numpy title line followed by dashes.
"""

from __future__ import annotations

import argparse
import importlib
import inspect
import pathlib
import re
import sys

ROOT = pathlib.Path(__file__).resolve().parents[1]


def doc_modules() -> list[str]:
    names = []
    for md in sorted((ROOT / "docs" / "api").rglob("*.md")):
        names += re.findall(r"^:::\s*(hhscatter[\w.]*)", md.read_text(), flags=re.M)
    return sorted(set(names))


def public(module) -> list[tuple[str, object]]:
    names = getattr(module, "__all__", None)
    if names is None:
        names = [
            n
            for n, o in vars(module).items()
            if not n.startswith("_") and getattr(o, "__module__", None) == module.__name__
        ]
    out = []
    for n in names:
        o = getattr(module, n)
        if inspect.isfunction(o) or inspect.isclass(o):
            out.append((n, o))
    return out


def params(obj) -> list[inspect.Parameter]:
    try:
        sig = inspect.signature(obj)
    except (ValueError, TypeError):
        return []
    return [p for p in sig.parameters.values() if p.name not in ("self", "cls")]


def sections(doc: str) -> set[str]:
    return set(re.findall(r"^(\w[\w ]*)\n-{3,}$", doc, flags=re.M))


def members(name: str, obj, methods: bool = True) -> list[tuple[str, object, bool]]:
    """(qualified name, callable, is a method) of one public object and (``methods``) its public methods."""
    if inspect.isfunction(obj) or not methods:
        return [(name, obj, False)]
    out = [(name, obj, False)]
    for m, v in vars(obj).items():
        if m.startswith("_") or getattr(v, "__qualname__", "").split(".")[0] != obj.__name__:
            continue
        f = v.__func__ if isinstance(v, (staticmethod, classmethod)) else v
        if inspect.isfunction(f):
            out.append((f"{name}.{m}", f, True))
    return out


def measure(objects, detail: bool) -> dict:
    n_par = n_typed = n_ret = n_ret_typed = 0
    n_fn = n_fn_params = n_param_sec = n_ret_sec = n_ex = 0
    for qual, obj, is_method in objects:
        has_return = is_method or inspect.isfunction(obj)
        ps = params(obj)
        untyped = [p.name for p in ps if p.annotation is inspect.Parameter.empty]
        n_par += len(ps)
        n_typed += len(ps) - len(untyped)
        no_ret = False
        if has_return:
            n_ret += 1
            try:
                no_ret = inspect.signature(obj).return_annotation is inspect.Signature.empty
            except (ValueError, TypeError):
                no_ret = False
            n_ret_typed += not no_ret
        if is_method:  # methods: hints only (their docstrings are one line by design)
            if detail and (untyped or no_ret):
                print(f"  {qual}: untyped {untyped}{' no return type' if no_ret else ''}")
            continue
        s = sections(inspect.getdoc(obj) or "")
        n_fn += 1
        n_ex += "Examples" in s
        if ps:
            n_fn_params += 1
            n_param_sec += bool({"Parameters", "Attributes"} & s)
        if inspect.isfunction(obj):
            n_ret_sec += "Returns" in s
        if detail and (
            untyped
            or no_ret
            or (ps and not {"Parameters", "Attributes"} & s)
            or (inspect.isfunction(obj) and "Returns" not in s)
        ):
            print(f"  {qual}: untyped {untyped}{' no return type' if no_ret else ''}; sections {sorted(s)}")
    n_funcs = sum(1 for q, o, is_method in objects if not is_method and inspect.isfunction(o))
    return dict(
        params=n_par,
        typed=n_typed,
        returns=n_ret,
        returns_typed=n_ret_typed,
        objects=n_fn,
        with_params=n_fn_params,
        param_sections=n_param_sec,
        functions=n_funcs,
        returns_sections=n_ret_sec,
        examples=n_ex,
    )


def pct(a: int, b: int) -> str:
    return f"{100 * a / b:.0f} %" if b else "-"


def report(label: str, m: dict) -> None:
    print(
        f"{label}: parameter hints {m['typed']}/{m['params']} ({pct(m['typed'], m['params'])}), "
        f"return hints {m['returns_typed']}/{m['returns']} ({pct(m['returns_typed'], m['returns'])}); "
        f"of {m['objects']} public functions/classes: Parameters {m['param_sections']}/{m['with_params']}, "
        f"Returns {m['returns_sections']}/{m['functions']} (functions), Examples {m['examples']}/{m['objects']}"
    )


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--top", action="store_true", help="the top-level public objects of hhscatter only")
    ap.add_argument("--no-methods", action="store_true", help="count functions and constructors only")
    ap.add_argument("--detail", action="store_true", help="list what each object lacks")
    args = ap.parse_args(argv)
    sys.path.insert(0, str(ROOT))
    if args.top:
        import hhscatter

        objs = [(n, getattr(hhscatter, n)) for n in hhscatter.__all__]
        objs = [(n, o) for n, o in objs if inspect.isfunction(o) or inspect.isclass(o)]
        objs = [x for n, o in objs for x in members(n, o, not args.no_methods)]
        report("hhscatter (top level)", measure(objs, args.detail))
        return 0
    total = []
    for modname in doc_modules():
        mod = importlib.import_module(modname)
        objs = [x for n, o in public(mod) for x in members(f"{modname}.{n}", o, not args.no_methods)]
        if args.detail:
            print(modname)
        m = measure(objs, args.detail)
        if args.detail:
            report(f"  {modname}", m)
        total += objs
    report(f"docs/api ({len(doc_modules())} modules)", measure(total, False))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

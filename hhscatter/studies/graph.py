"""The studies and their dependency graph, read from the study folders (the one place it is declared).

A study is a folder ``studies/<name>/`` with a ``study.toml``. Its header
tables say what it is and which other studies it builds on::

    [about]
    title = "Fig 5: c-measure comparison"      # make help, docs nav, report heading
    paper = "Fig. 5"                           # the paper's figure; "" for a check beyond the paper
    summary = "dissipative section points vs the conservative c-measure; distances"

    [needs]                                    # role = upstream study whose published outputs it reads
    cmeasure = "fig1"
    mu = "fig3"

Everything else that lists studies is derived from these folders: the
Makefile's rules (``python hhscatter/studies/graph.py make``, included by the
Makefile), the report's sections, the docs' navigation and the end-to-end
test's build order.

This module uses the standard library only, so the Makefile can run it with
any Python ≥ 3.11 before a virtual environment exists.
"""

from __future__ import annotations

import os
import sys
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

HEADER_TABLES = ("about", "needs")


class GraphError(ValueError):
    """A study folder's header is unreadable, names an unknown study, or the graph has a cycle."""


@dataclass(frozen=True)
class StudyInfo:
    """StudyInfo(name, title, paper, summary, needs, setup) -> the header of one study folder.

    ``needs`` maps a role (what the study uses the upstream for) to the
    upstream study's name; ``upstream`` is the sorted set of those names.
    """

    name: str
    title: str = ""
    paper: str = ""
    summary: str = ""
    needs: dict = field(default_factory=dict)
    setup: str = ""

    @property
    def upstream(self) -> tuple:
        return tuple(sorted(set(self.needs.values())))

    @property
    def beyond_paper(self) -> bool:
        return not self.paper


#: names a studies folder explicitly (what ``hhscatter study --studies DIR`` sets)
ROOT_ENV = "HHSCATTER_STUDIES"


def default_root() -> Path:
    """The studies folder a command works on: ``$HHSCATTER_STUDIES`` when set, else ``studies/`` of the repository
    the command runs in (the working directory or its nearest parent with a ``studies/<name>/study.toml``).

    Never the folder of the installed code: a second clone using the first clone's virtual environment reads its
    own study files. GraphError when there is none.
    """
    env = os.environ.get(ROOT_ENV)
    if env:
        return Path(env)
    cwd = Path.cwd()
    for d in (cwd, *cwd.parents):
        if any((d / "studies").glob("*/study.toml")):
            return d / "studies"
    raise GraphError(
        f"no studies folder in {cwd} or above it: run from a repository with studies/<name>/study.toml, "
        f"or name the folder (hhscatter study --studies DIR, or {ROOT_ENV}=DIR)"
    )


def _read_toml(path: Path) -> dict:
    try:
        return tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError as exc:
        raise GraphError(f"{path} is not valid TOML: {exc}") from None


def study_info(root: Path, name: str, doc: dict | None = None) -> StudyInfo:
    """study_info(root, name, doc=None) -> StudyInfo from ``<root>/<name>/study.toml`` (or its parsed ``doc``)."""
    path = Path(root) / name / "study.toml"
    if doc is None:
        doc = _read_toml(path)
    about = doc.get("about", {})
    needs = doc.get("needs", {})
    if not isinstance(about, dict) or not isinstance(needs, dict):
        raise GraphError(f"{path}: [about] and [needs] must be tables")
    for role, other in needs.items():
        if not isinstance(other, str):
            raise GraphError(f"{path}: [needs] {role} must be the name of a study (a string), got {other!r}")
    return StudyInfo(
        name=name,
        title=str(about.get("title", name)),
        paper=str(about.get("paper", "")),
        summary=str(about.get("summary", "")),
        needs=dict(needs),
        setup=str(about.get("setup", "")),
    )


def topological(infos: dict) -> list:
    """topological({name: StudyInfo}) -> names, every study after its upstream studies (ties by name)."""
    for info in infos.values():
        for other in info.upstream:
            if other not in infos:
                raise GraphError(
                    f"study {info.name!r} needs {other!r}, which is not a study folder (studies: {sorted(infos)})"
                )
    done, order = set(), []
    pending = sorted(infos)
    while pending:
        ready = [n for n in pending if set(infos[n].upstream) <= done]
        if not ready:
            raise GraphError(f"the studies' [needs] form a cycle among {pending}")
        nxt = ready[0]
        order.append(nxt)
        done.add(nxt)
        pending.remove(nxt)
    return order


def studies(root: Path | None = None) -> list:
    """studies(root=None) -> [StudyInfo] of every folder of ``root`` with a study.toml, in dependency order."""
    root = Path(root) if root is not None else default_root()
    infos = {p.parent.name: study_info(root, p.parent.name) for p in sorted(root.glob("*/study.toml"))}
    return [infos[n] for n in topological(infos)]


def scales(root: Path | None = None, default: str = "quick") -> list:
    """scales(root=None) -> the scales the studies of ``root`` declare: ``default`` and every ``[scale.<name>]``."""
    root = Path(root) if root is not None else default_root()
    found = set()
    for p in sorted(root.glob("*/study.toml")):
        table = _read_toml(p).get("scale", {})
        if isinstance(table, dict):
            found |= set(table)
    return [default, *sorted(found - {default})]


def upstream_closure(name: str, root: Path | None = None) -> list:
    """upstream_closure(name, root=None) -> the study and every study it needs, directly or not, in build order."""
    infos = {s.name: s for s in studies(root)}
    want, todo = set(), [name]
    while todo:
        n = todo.pop()
        if n in want:
            continue
        if n not in infos:
            raise GraphError(f"no study {n!r} (studies: {sorted(infos)})")
        want.add(n)
        todo.extend(infos[n].upstream)
    return [n for n in topological(infos) if n in want]


def makefile(root: Path | None = None) -> str:
    """makefile(root=None) -> the Make rules of every study (what the Makefile includes).

    Each study gets the three stage rules of the Makefile's ``study_rules``
    (its analyze stage also depends on the numbers JSON of every upstream
    study, so ``make <study>`` builds them first) and a phony target with
    its title as ``make help`` text.
    """
    infos = studies(root)
    lines = [
        "# Generated by hhscatter/studies/graph.py from studies/*/study.toml ([about], [needs]): do not edit.",
        f"STUDY_NAMES := {' '.join(s.name for s in infos)}",
        f"STUDIES_MK_TOMLS := {' '.join(sorted(f'studies/{s.name}/study.toml' for s in infos))}",
        f"STUDY_SCALES := {' '.join(scales(root))}",
        "",
    ]
    for s in infos:
        ups = " ".join(s.upstream)
        lines.append(f"$(eval $(call study_rules,{s.name},{ups}))")
        need = f" (needs {', '.join(s.upstream)})" if s.upstream else ""
        lines.append(f"{s.name}: $(call so,{s.name})/{s.name}.png ## {s.title} — {s.summary}{need}")
        lines.append("")
    lines.append(".PHONY: $(STUDY_NAMES)")
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    what = argv[0] if argv else "order"
    root = Path(argv[1]) if len(argv) > 1 else None
    try:
        if what == "make":
            sys.stdout.write(makefile(root))
        elif what == "order":
            print(" ".join(s.name for s in studies(root)))
        else:
            print(f"usage: {Path(__file__).name} [make|order] [STUDIES_ROOT]", file=sys.stderr)
            return 2
    except GraphError as exc:
        print(f"graph.py: error: {exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

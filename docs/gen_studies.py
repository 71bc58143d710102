"""Copy the studies' figures and numbers into docs/ so the site builds without rerunning them.

    python docs/gen_studies.py [--scale quick] [--check]

For each study folder (``studies/<name>/study.toml``) it copies
``studies/<name>/out/<scale>/<name>.png`` (and its further figures ``<name>_*.png``), ``<name>.json`` and the stage
costs ``cost.json`` (as ``<name>.cost.json``) to ``docs/studies/assets/``
(quick scale) or ``docs/studies/assets/<scale>/`` (any other scale, e.g.
``paper``: the committed paper-scale results the docs and
``make report SCALE=paper`` read); for the benchmarks and stress tests, the markdown
summaries, PNG figures and small CSV files of ``benchmarks/out/<bench|stress|engine>/<s>/``
(``<s>`` = ``--bench-scale``, default ``full``, else ``quick``) to
``docs/benchmarks/assets/<bench|stress|engine>/``.
Outputs that do not exist yet are reported and skipped; an asset already in
docs/ is then kept, and the page says which scale made it. The pages render
these assets at build time (docs/_hooks/studies.py) and show a "not yet
generated" note for anything missing, so `make docs` never needs the studies.

``--check`` copies nothing and exits 1 if an asset differs from its source
(e.g. to see whether the committed docs are stale).
"""

from __future__ import annotations

import argparse
import filecmp
import importlib.util
import shutil
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
GRAPH = ROOT / "hhscatter" / "studies" / "graph.py"


def study_names(root: Path) -> list:
    """The study folders of ``root/studies`` (hhscatter/studies/graph.py, loaded by path: stdlib only)."""
    spec = importlib.util.spec_from_file_location("hh_study_graph", GRAPH)
    graph = sys.modules.setdefault(spec.name, importlib.util.module_from_spec(spec))
    spec.loader.exec_module(graph)
    return [s.name for s in graph.studies(root / "studies")]


BENCHES = ("bench", "stress", "engine", "noise")
CSV_MAX_BYTES = 200_000  # larger CSVs stay out of the repository's docs
JSON_WARN_BYTES = 500_000


def _bench_dir(base: Path, bench_scale):
    """The output folder of a benchmark: out/<bench_scale>, else out/full or out/quick, else out/ itself."""
    if not base.is_dir():
        return None
    names = [bench_scale] if bench_scale else ["full", "quick", "paper"]
    for name in names:
        if (base / name).is_dir():
            return base / name
    if not bench_scale and any(p.name.endswith("summary.md") for p in base.iterdir() if p.is_file()):
        return base
    return None


def assets_dir(scale: str) -> Path:
    """assets_dir(scale) -> docs/studies/assets (quick) or docs/studies/assets/<scale>."""
    base = DOCS / "studies" / "assets"
    return base if scale == "quick" else base / scale


def plan(scale: str, bench_scale=None, studies_only: bool = False):
    """plan(scale, bench_scale=None) -> (pairs [(src, dst)], missing [str]) of the files to copy."""
    pairs, missing = [], []
    dst = assets_dir(scale)
    for name in study_names(ROOT):
        out = ROOT / "studies" / name / "out" / scale
        for src, target in (
            (out / f"{name}.png", f"{name}.png"),
            (out / f"{name}.json", f"{name}.json"),
            (out / "cost.json", f"{name}.cost.json"),
        ):
            if src.exists():
                pairs.append((src, dst / target))
            elif src.name != "cost.json":
                missing.append(str(src.relative_to(ROOT)))
        # further figures of a study (<name>_<part>.png: one panel group each, legible at full width)
        pairs += [(src, dst / src.name) for src in sorted(out.glob(f"{name}_*.png"))]
    if studies_only or scale != "quick":  # the benchmarks have scales of their own (full, quick)
        return pairs, missing
    for which in BENCHES:
        base = ROOT / "benchmarks" / "out" / which
        out = _bench_dir(base, bench_scale)
        if out is None:
            missing.append(str(base.relative_to(ROOT)) + f"/{bench_scale or '<full|quick>'}/")
            continue
        dst_dir = DOCS / "benchmarks" / "assets" / which
        for src in sorted(out.iterdir()):
            if not src.is_file():
                continue
            if (
                src.name.endswith("summary.md")
                or src.suffix == ".png"
                or (src.suffix == ".csv" and src.stat().st_size <= CSV_MAX_BYTES)
            ):
                pairs.append((src, dst_dir / src.name))
    return pairs, missing


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scale", default="quick", help="study scale whose outputs to copy (default: quick)")
    ap.add_argument(
        "--bench-scale", help="scale folder of benchmarks/out/<bench|stress|engine> to copy (default: full, else quick)"
    )
    ap.add_argument("--check", action="store_true", help="copy nothing; exit 1 if an asset is stale")
    ap.add_argument("--studies-only", action="store_true", help="copy the studies' outputs, not the benchmarks'")
    a = ap.parse_args(argv)

    pairs, missing = plan(a.scale, a.bench_scale, studies_only=a.studies_only)
    stale = [(s, d) for s, d in pairs if not (d.exists() and filecmp.cmp(s, d, shallow=False))]
    if a.check:
        for s, d in stale:
            print(f"stale: {d.relative_to(ROOT)} (source {s.relative_to(ROOT)})")
        return 1 if stale else 0
    # panels of an earlier layout: a study whose figure is copied keeps only the panels its plot stage wrote now
    copied = {d for _, d in pairs}
    for d in copied:
        if d.suffix == ".png" and "_panel_" not in d.stem:
            for old in d.parent.glob(f"{d.stem}_panel_*.png"):
                if old not in copied:
                    old.unlink()
                    print(f"removed {old.relative_to(ROOT)} (its study's plot stage no longer writes it)")
    for s, d in stale:
        d.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(s, d)
        print(f"copied {s.relative_to(ROOT)} -> {d.relative_to(ROOT)}")
        if d.suffix == ".json" and d.stat().st_size > JSON_WARN_BYTES:
            print(f"  note: {d.name} is {d.stat().st_size // 1000} kB; the docs commit it", file=sys.stderr)
    print(f"{len(pairs) - len(stale)} asset(s) up to date, {len(stale)} copied")
    if missing:
        print("not generated yet (pages show a note): " + ", ".join(missing))
    return 0


if __name__ == "__main__":
    sys.exit(main())

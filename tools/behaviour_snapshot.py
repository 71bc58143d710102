"""Behaviour snapshot for refactors: scene hashes, table contents and study numbers (tiny scale, or another).

A refactor must leave every scene hash, every table byte and every study number unchanged. This tool
records the three in one JSON file, so that the same command before and after a change shows what
moved::

    python tools/behaviour_snapshot.py record before.json            # scenes + tables (~1 min)
    python tools/behaviour_snapshot.py record before.json --numbers  # plus `make studies SCALE=tiny` JSONs
    python tools/behaviour_snapshot.py compare before.json after.json   # exit 1 on any difference
    python tools/behaviour_snapshot.py numbers old.json --checkout DIR   # only the tiny JSONs present in DIR
    python tools/behaviour_snapshot.py numbers q.json --checkout DIR --scale quick   # the quick JSONs there

The code recorded is this checkout's (``ROOT`` first on the import path of the script and of every command it
starts), not the one an editable install of a shared virtual environment points at; ``make`` runs with the
environment's install stamp taken as up to date, so it never reinstalls. ``numbers`` reads another checkout's
outputs (an older commit, its studies run with its own code) with this version of the tool, so that both sides of
a comparison are read alike.

What is recorded:

- ``scenes``: the result hash of every scene that every study's ``simulate`` stage would run, at the
  scales tiny, quick and paper. The stage runs with :meth:`Study.run` replaced by a recorder, so nothing
  is integrated; a stage that reads a run it just "made" stops there, and the hashes recorded until
  then are kept (the stop is recorded too, so it is compared like everything else).
- ``tables``: for a fixed set of small ``hhscatter simulate`` runs (plain, sections + snapshots, a grid,
  drag, an IC table), a SHA-256 of every part's data (Arrow IPC of the table without its metadata) and
  of its metadata without the version and commit keys, and the run's ``scene.json`` without them.
- ``numbers`` (``--numbers``): every numeric leaf of the study JSONs made by ``make studies SCALE=tiny``
  (``--scale`` another scale), without ``provenance`` and ``cost``; floats compared exactly.

The script uses the public CLI for the tables and ``hhscatter.studies`` (``study_names``, ``load_study``,
``stage_module``, ``Study.run``) for the scenes: adapt those four names if the refactor moves them.
"""

from __future__ import annotations

import argparse
import contextlib
import hashlib
import io
import json
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # this checkout's hhscatter, before any editable install of a shared environment
VOLATILE = {
    "git_commit",
    "heyoka",
    "hhscatter",
    "numpy",
    "pyarrow",
    "python",
    "provenance",
    "created",
    "written",
    "host",
    "cost",
    "wall_s",
    "cpu_s",
}
SCALES = ("tiny", "quick", "paper")
RUNS = {  # name -> CLI flags of `hhscatter simulate` (small: the set runs in well under a minute)
    "plain": "--energy 0.3 --gamma 0 -n 300 --seed 11 --chunk-size 100 --t-max 200",
    "drag_sections_snapshots": "--energy 0.3 --gamma 0.01 -n 300 --seed 12 --chunk-size 100 --t-max 200 "
    "--sections --snapshots 0:100:5",
    "grid": "--energy 0.25,0.35 --gamma 0,0.02 -n 100 --seed 13 --chunk-size 50 --t-max 150 --sections",
    "square_resc": "--energy 0.35 --gamma 0.005 -n 200 --seed 14 --region square --r-esc 1.03 --t-max 150",
    "ics": "--gamma 0.01 --t-max 150 --sections --chunk-size 2",
}
ICS_CSV = "x,y,px,py\n0.1,0.05,0.6,0.1\n-0.2,0.1,0.1,-0.65\n0.0,-0.3,0.55,0.2\n0.25,0.25,-0.3,0.5\n0.05,0.0,0.0,0.7\n"


def _strip(obj):
    """obj without the volatile keys (versions, commit, timing), recursively."""
    if isinstance(obj, dict):  # an IC table's path lies in a temporary folder: keep its file name
        return {
            k: Path(v).name if k == "ics" and isinstance(v, str) else _strip(v)
            for k, v in obj.items()
            if k not in VOLATILE
        }
    if isinstance(obj, list):
        return [_strip(v) for v in obj]
    return obj


def _env() -> dict:
    """The environment of a command the script starts: this checkout's code first on its import path."""
    import os

    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(p for p in (str(ROOT), env.get("PYTHONPATH", "")) if p)
    return env


def _sha(b: bytes) -> str:
    return hashlib.sha256(b).hexdigest()[:16]


def part_digest(path: Path) -> dict:
    import pyarrow as pa
    import pyarrow.parquet as pq

    table = pq.read_table(path)
    meta = {k.decode(): v.decode() for k, v in (table.schema.metadata or {}).items()}
    meta = {k: _strip(json.loads(v)) if v[:1] in "{[" else v for k, v in meta.items()}
    sink = io.BytesIO()
    data = table.replace_schema_metadata(None)
    with pa.ipc.new_stream(sink, data.schema) as w:
        w.write_table(data)
    return {
        "rows": table.num_rows,
        "data": _sha(sink.getvalue()),
        "meta": _sha(json.dumps(meta, sort_keys=True).encode()),
    }


def record_tables(hh: Path) -> dict:
    out = {}
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        (tmp / "ics.csv").write_text(ICS_CSV)
        for name, flags in RUNS.items():
            run = tmp / name
            args = [str(hh), "simulate", *flags.split(), "--out", str(run), "--workers", "1", "--no-progress"]
            if name == "ics":
                args += ["--ics", str(tmp / "ics.csv")]
            p = subprocess.run(args, capture_output=True, text=True, env=_env())
            if p.returncode:
                out[name] = {"error": f"exit {p.returncode}: {p.stderr.strip()[-300:]}"}
                continue
            rec = {
                "scene.json": _sha(
                    json.dumps(_strip(json.loads((run / "scene.json").read_text())), sort_keys=True).encode()
                )
            }
            for f in sorted(run.rglob("*.parquet")):
                rec[str(f.relative_to(run))] = part_digest(f)
            out[name] = rec
            print(f"  tables/{name}: {len(rec) - 1} part(s)", file=sys.stderr)
    return out


def record_scenes() -> dict:
    import os

    os.environ.setdefault("HHSCATTER_STUDIES", str(ROOT / "studies"))  # this checkout's studies, wherever it runs
    from hhscatter import studies as st

    out = {}
    real_run = st.Study.run

    def recorder(self, key, scene, *, workers=None, progress=True):
        self._recorded[f"{key}"] = scene.result_hash()
        return self.raw(key)

    st.Study.run = recorder
    try:
        for name in st.study_names():
            for scale in SCALES:
                try:
                    study = st.load_study(name, scale)
                except Exception as e:  # a study without that scale
                    out[f"{name}@{scale}"] = {"load": f"{type(e).__name__}: {e}"[:200]}
                    continue
                study._recorded = {}
                stop = None
                with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
                    try:
                        st.stage_module(name).simulate(study)
                    except BaseException as e:  # noqa: BLE001 - any stop is recorded and compared
                        stop = type(e).__name__
                out[f"{name}@{scale}"] = {"hashes": study._recorded, "stopped_by": stop}
                print(
                    f"  scenes/{name}@{scale}: {len(study._recorded)} scene(s)"
                    + (f", stopped by {stop}" if stop else ""),
                    file=sys.stderr,
                )
    finally:
        st.Study.run = real_run
    return out


def numeric_leaves(obj, prefix=""):
    if isinstance(obj, dict):
        for k, v in obj.items():
            if k not in VOLATILE:
                yield from numeric_leaves(v, f"{prefix}.{k}" if prefix else str(k))
    elif isinstance(obj, list):
        for i, v in enumerate(obj):
            yield from numeric_leaves(v, f"{prefix}[{i}]")
    elif isinstance(obj, (bool, int, float, str)) or obj is None:
        yield prefix, obj


def record_numbers(make: bool, checkout: Path = ROOT, scale: str = "tiny") -> dict:
    """Every leaf of the numbers JSON at ``scale`` of each study of ``checkout`` (its ``studies/<name>/out/<scale>/``)."""
    if make:  # the install stamp taken as up to date: never a reinstall into the (perhaps shared) environment
        cmd = ["make", "-o", ".venv/.installed-stamp", "studies", f"SCALE={scale}"]
        subprocess.run(cmd, cwd=ROOT, check=True, stdout=subprocess.DEVNULL, env=_env())
    out = {}
    for f in sorted((Path(checkout) / "studies").glob(f"*/out/{scale}/*.json")):
        if f.name.endswith(".cost.json") or f.parent.parent.parent.name != f.stem:
            continue
        out[f.stem] = dict(numeric_leaves(json.loads(f.read_text())))
        print(f"  numbers/{f.stem}: {len(out[f.stem])} leaves", file=sys.stderr)
    return out


def compare(a: dict, b: dict, path="") -> list[str]:
    diffs = []
    for k in sorted(set(a) | set(b), key=str):
        p = f"{path}/{k}"
        if k not in a or k not in b:
            diffs.append(f"{p}: only in {'after' if k not in a else 'before'}")
        elif isinstance(a[k], dict) and isinstance(b[k], dict):
            diffs += compare(a[k], b[k], p)
        elif not _same(a[k], b[k]):
            diffs.append(f"{p}: {a[k]!r} -> {b[k]!r}")
    return diffs


def _same(x, y) -> bool:
    """Leaves equal exactly: the same type, and a float bit for bit (NaN equals NaN, -0.0 differs from 0.0)."""
    if type(x) is not type(y):
        return False
    return repr(x) == repr(y) if isinstance(x, float) else x == y


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("record")
    r.add_argument("out", type=Path)
    r.add_argument("--numbers", action="store_true", help="also run `make studies SCALE=tiny` and record its JSONs")
    r.add_argument(
        "--numbers-only-existing", action="store_true", help="record the tiny JSONs already present (no make)"
    )
    n = sub.add_parser("numbers", help="record only the tiny-scale numbers already present (no make, no scenes)")
    n.add_argument("out", type=Path)
    n.add_argument("--checkout", type=Path, default=ROOT, help="the checkout whose outputs to read (default: this)")
    for p in (r, n):
        p.add_argument("--scale", default="tiny", choices=SCALES, help="the studies' scale whose JSONs to record")
    c = sub.add_parser("compare")
    c.add_argument("before", type=Path)
    c.add_argument("after", type=Path)
    a = ap.parse_args(argv)
    if a.cmd == "record":
        snap = {"scenes": record_scenes(), "tables": record_tables(ROOT / ".venv" / "bin" / "hhscatter")}
        if a.numbers or a.numbers_only_existing:
            snap["numbers"] = record_numbers(make=a.numbers, scale=a.scale)
        a.out.write_text(json.dumps(snap, indent=1, sort_keys=True))
        n = sum(len(v.get("hashes", {})) for v in snap["scenes"].values())
        print(
            f"wrote {a.out}: {n} scene hashes, {len(snap['tables'])} table runs, "
            f"{sum(len(v) for v in snap.get('numbers', {}).values())} numbers"
        )
        return 0
    if a.cmd == "numbers":
        if not (a.checkout / "studies").is_dir():
            ap.error(f"--checkout {a.checkout}: no studies/ folder there")
        snap = {"numbers": record_numbers(make=False, checkout=a.checkout, scale=a.scale)}
        a.out.write_text(json.dumps(snap, indent=1, sort_keys=True))
        print(
            f"wrote {a.out}: {sum(len(v) for v in snap['numbers'].values())} numbers of {len(snap['numbers'])} studies"
        )
        return 0
    before, after = (json.loads(p.read_text()) for p in (a.before, a.after))
    diffs = compare(before, after)
    for d in diffs[:200]:
        print(d)
    print(f"{len(diffs)} difference(s)" + (" (first 200 shown)" if len(diffs) > 200 else ""))
    return 1 if diffs else 0


if __name__ == "__main__":
    sys.exit(main())

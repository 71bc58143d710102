"""tools/behaviour_snapshot.py: its digests see data changes and ignore versions; compare finds every change."""

import importlib.util
import json
from pathlib import Path

import pyarrow as pa
import pyarrow.parquet as pq

spec = importlib.util.spec_from_file_location(
    "behaviour_snapshot", Path(__file__).resolve().parents[2] / "tools" / "behaviour_snapshot.py"
)
bs = importlib.util.module_from_spec(spec)
spec.loader.exec_module(bs)


def _part(path, values, version):
    meta = {
        "hhscatter": json.dumps(
            {
                "hhscatter": version,
                "git_commit": version * 3,
                "rows": len(values),
                "scene": {"ics": f"/tmp/{version}/ics.csv", "seed": 1},
            }
        )
    }
    pq.write_table(pa.table({"t": values}).replace_schema_metadata(meta), path)
    return bs.part_digest(path)


def test_part_digest_sees_data_and_ignores_versions_and_temporary_paths(tmp_path):
    a = _part(tmp_path / "a.parquet", [1.0, 2.0], "0.1")
    b = _part(tmp_path / "b.parquet", [1.0, 2.0], "0.2")  # other version, commit, tmp folder
    c = _part(tmp_path / "c.parquet", [1.0, 2.0 + 2**-51], "0.1")  # one ulp-scale change in the data
    assert a == b
    assert a["data"] != c["data"] and a["meta"] == c["meta"]


def test_compare_lists_every_change_and_nothing_else():
    before = {"scenes": {"fig1@tiny": {"hashes": {"E0.30": "aa"}, "stopped_by": None}}, "numbers": {"x": 1.0}}
    same = json.loads(json.dumps(before))
    after = {"scenes": {"fig1@tiny": {"hashes": {"E0.30": "ab"}, "stopped_by": None}}, "numbers": {"y": 1.0}}
    assert bs.compare(before, same) == []
    assert bs.compare(before, after) == [
        "/numbers/x: only in before",
        "/numbers/y: only in after",
        "/scenes/fig1@tiny/hashes/E0.30: 'aa' -> 'ab'",
    ]


def test_numeric_leaves_skip_provenance_and_cost():
    doc = {"kappa": [0.1, {"err": 0.01}], "provenance": {"git_commit": "x"}, "cost": 3, "ok": True}
    assert dict(bs.numeric_leaves(doc)) == {"kappa[0]": 0.1, "kappa[1].err": 0.01, "ok": True}


def test_compare_takes_floats_bit_for_bit_and_types_exactly():
    nan = float("nan")
    assert bs.compare({"x": nan}, {"x": nan}) == []  # the same leaf, though nan != nan
    assert bs.compare({"x": 0.0}, {"x": -0.0}) == ["/x: 0.0 -> -0.0"]
    assert bs.compare({"x": 3.0}, {"x": 3}) == ["/x: 3.0 -> 3"]
    assert bs.compare({"x": True}, {"x": 1}) == ["/x: True -> 1"]
    assert bs.compare({"x": 0.1 + 0.2}, {"x": 0.3}) == [f"/x: {0.1 + 0.2!r} -> 0.3"]


def test_numbers_reads_another_checkouts_tiny_outputs_only(tmp_path):
    out = tmp_path / "old" / "studies" / "fig9" / "out"
    (out / "tiny").mkdir(parents=True)
    (out / "quick").mkdir()
    (out / "tiny" / "fig9.json").write_text(json.dumps({"kappa": {"value": 0.5, "err": 0.25}, "cost": {"s": 1}}))
    (out / "tiny" / "fig9.cost.json").write_text(json.dumps({"s": 2.0}))
    (out / "tiny" / "other.json").write_text(json.dumps({"a": 1}))
    (out / "quick" / "fig9.json").write_text(json.dumps({"b": 1}))
    snap = tmp_path / "n.json"
    assert bs.main(["numbers", str(snap), "--checkout", str(tmp_path / "old")]) == 0
    assert json.loads(snap.read_text()) == {"numbers": {"fig9": {"kappa.value": 0.5, "kappa.err": 0.25}}}
    # another scale: its folder alone
    assert bs.main(["numbers", str(snap), "--checkout", str(tmp_path / "old"), "--scale", "quick"]) == 0
    assert json.loads(snap.read_text()) == {"numbers": {"fig9": {"b": 1}}}


def test_commands_started_import_this_checkouts_code_first():
    first = bs._env()["PYTHONPATH"].split(__import__("os").pathsep)[0]
    assert Path(first) == Path(__file__).resolve().parents[2]

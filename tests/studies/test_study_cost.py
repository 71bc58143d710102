"""The cost record of a study stage (hhscatter.studies.cost): CPU of children counted, invocations added."""

import json
import multiprocessing as mp

from hhscatter.studies.cost import StageCost, meter, record, totals


def _burn(n):
    s = 0
    for i in range(n):
        s += i * i
    return s


def test_meter_counts_the_cpu_of_waited_children(tmp_path):
    ctx = mp.get_context("spawn")
    with meter("simulate") as cost:
        p = ctx.Process(target=_burn, args=(3_000_000,))
        p.start()
        p.join()
    # the child's loop alone takes ≥ 0.05 s of CPU on any machine; a meter of this process only would miss it
    with meter("simulate") as self_only:
        pass
    assert cost.cpu_s > 0.05 > self_only.cpu_s
    assert cost.wall_s >= cost.cpu_s * 0.5
    assert cost.rss_self_mb > 1 and cost.rss_children_mb > 1


def test_record_adds_resumed_invocations_and_a_fresh_run_replaces_them(tmp_path):
    a = StageCost("simulate", wall_s=10, cpu_s=18, orbits=100, rss_self_mb=200, rss_children_mb=300)
    b = StageCost("simulate", wall_s=5, cpu_s=9, orbits=50, chunks_resumed=2, rss_self_mb=250, rss_children_mb=100)
    record(tmp_path, a)
    record(tmp_path, b)
    record(tmp_path, StageCost("analyze", wall_s=4, cpu_s=4))
    record(tmp_path, StageCost("analyze", wall_s=3, cpu_s=3))  # analyze starts over: the last one counts
    t = totals(json.loads((tmp_path / "cost.json").read_text()))
    assert t["simulate"] == {
        "wall_s": 15,
        "cpu_s": 27,
        "orbits": 150,
        "rss_self_mb": 250,
        "rss_children_mb": 300,
        "invocations": 2,
    }
    assert t["analyze"]["invocations"] == 1 and t["analyze"]["cpu_s"] == 3
    record(tmp_path, StageCost("simulate", wall_s=1, cpu_s=2, orbits=7))  # a fresh run: nothing resumed
    t = totals(json.loads((tmp_path / "cost.json").read_text()))
    assert t["simulate"]["orbits"] == 7 and t["simulate"]["invocations"] == 1


def test_streamed_table_is_one_file_with_a_row_group_per_part(tmp_path):
    """write_parts_streamed: the parts in order, their dictionaries may differ, the metadata is the study's."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    from hhscatter.data.read import read_meta
    from hhscatter.data.write import write_parts_streamed

    dic = pa.dictionary(pa.int8(), pa.string())
    parts = [
        pa.table({"g": pa.array([0.0, 0.0]), "o": pa.array(["escaped", "censored"]).cast(dic)}),
        pa.table({"g": pa.array([1.0]), "o": pa.array(["settled"]).cast(dic)}),
    ]
    path = tmp_path / "t.parquet"
    assert write_parts_streamed(path, iter(parts), {"study": "x"}) == 3
    f = pq.ParquetFile(path)
    assert f.num_row_groups == 2 and read_meta(path) == {"study": "x"}
    back = pq.read_table(path).to_pandas()
    assert list(back["o"].astype(str)) == ["escaped", "censored", "settled"] and list(back["g"]) == [0, 0, 1]
    assert str(back["o"].dtype) == "category"
    import pytest

    with pytest.raises(ValueError, match="no table"):
        write_parts_streamed(tmp_path / "empty.parquet", iter([]), {})
    assert not (tmp_path / "empty.parquet").exists()

"""The lighter paths of writing and describing a run give what the general ones give: ``to_arrow``
builds its arrays from the numpy buffers (the same Arrow data as ``pa.array``, byte for byte in Arrow IPC),
``describe_run`` counts a manifest run from its part files (the same dict as the ``pyarrow.dataset`` scan)."""

from __future__ import annotations

import io

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

import hhscatter
from hhscatter.data import schema, verify
from hhscatter.data.write import dictionary_columns
from hhscatter.integrate.engine import run_chunk
from hhscatter.scene.ics import region_ics
from hhscatter.scene.scene import Follow, Scene, SectionWindow


def _ipc(table):
    sink = io.BytesIO()
    with pa.ipc.new_stream(sink, table.schema) as w:
        w.write_table(table)
    return sink.getvalue()


def _to_arrow_with_pa_array(name, columns):  # the reference: pa.array on every column
    arrays = []
    for field in schema._schemas()[name]:
        col = np.asarray(columns[field.name])
        if name == "lifetimes" and field.name == "outcome":
            arrays.append(pa.DictionaryArray.from_arrays(pa.array(col.astype(np.int8)), pa.array(schema.OUTCOMES)))
        elif name == "lifetimes" and field.name == "exit_channel":
            arrays.append(pa.array(col.astype(np.int8), pa.int8(), mask=col < 0))
        else:
            arrays.append(pa.array(col, field.type))
    return pa.Table.from_arrays(arrays, schema=schema._schemas()[name])


@pytest.mark.parametrize(
    "kw",
    [
        {"gamma": 0.01, "t_max": 30.0, "snapshots": (0.0, 1.0, 5.0), "sections": SectionWindow()},
        {"gamma": 0.0, "follow": Follow((1.2,))},
    ],
    ids=["censored+sections+snapshots", "follow crossings"],
)
def test_to_arrow_equals_pa_array_in_arrow_ipc_bytes(kw, tmp_path):
    sc = Scene(energy=0.3, n=200, seed=5, r_esc=1.03, **kw)
    res = run_chunk(sc, region_ics(sc, 0, sc.n), np.arange(sc.n))
    for name, cols in res.tables().items():
        ours, ref = schema.to_arrow(name, cols), _to_arrow_with_pa_array(name, cols)
        assert _ipc(ours) == _ipc(ref), name
        path = tmp_path / f"{name}.parquet"  # and the Parquet written with our encodings reads back the same
        pq.write_table(ours, path, use_dictionary=dictionary_columns(ours.schema), compression="zstd")
        back = pq.read_table(path)
        assert back.cast(ref.schema).equals(ref), name
        # the types too, but for the width of a dictionary's indices: int8 as written, kept by pyarrow ≥ 17 and
        # read back as int32 by older ones
        for b, r in zip(back.schema, ref.schema):
            assert b.type == r.type or (pa.types.is_dictionary(r.type) and b.type.value_type == r.type.value_type)
    if sc.gamma > 0:
        assert (res.lifetimes["exit_channel"] < 0).any()  # the masked (null) channel is exercised


@pytest.mark.parametrize(
    "args",
    [
        {"run": Scene(energy=0.3, gamma=0.02, n=120, seed=3, chunk_size=50, t_max=100.0, sections=SectionWindow())},
        {
            "run": hhscatter.Grid(
                Scene(energy=0.3, n=60, seed=4, chunk_size=25, t_max=100.0), energies=(0.25, 0.35), gammas=(0.0, 0.02)
            )
        },
    ],
    ids=["plain", "grid"],
)
def test_describe_run_from_parts_equals_the_dataset_scan(args, tmp_path, monkeypatch):
    hhscatter.simulate(args["run"], tmp_path, workers=1, progress=False, overwrite=True)
    light = verify.describe_run(tmp_path)
    monkeypatch.setattr(verify, "_describe_parts", lambda *a: None)
    assert light == verify.describe_run(tmp_path)
    assert sum(p["escaped"] + p["settled"] + p["censored"] for p in light["points"]) == light["rows"]["lifetimes"]

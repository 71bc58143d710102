"""read_ics_table: Parquet and CSV read with pyarrow (no pandas on the simulate path), the values
exactly those written, and the file's mistakes refused with the key named."""

import math
import subprocess
import sys

import numpy as np
import pyarrow as pa
import pyarrow.csv as pcsv
import pyarrow.parquet as pq
import pytest

from hhscatter.errors import ConfigError
from hhscatter.scene.ics import read_ics_table


def _write(tmp_path, name, columns):
    t = pa.table(columns)
    pq.write_table(t, tmp_path / f"{name}.parquet")
    pcsv.write_csv(t, tmp_path / f"{name}.csv")
    return [tmp_path / f"{name}.parquet", tmp_path / f"{name}.csv"]


@pytest.mark.parametrize("fmt", [0, 1], ids=["parquet", "csv"])
def test_values_are_those_written(tmp_path, fmt):
    rng = np.random.default_rng(5)
    v = rng.standard_normal((500, 4)) * 0.3
    ids = rng.permutation(10_000)[:500]
    p = _write(
        tmp_path, "a", {"x": v[:, 0], "y": v[:, 1], "px": v[:, 2], "py": v[:, 3], "traj_id": ids, "note": ["n"] * 500}
    )[fmt]
    states, got = read_ics_table(p)
    assert states.dtype == np.float64 and states.tobytes() == np.ascontiguousarray(v).tobytes()
    assert got.dtype == np.int64 and np.array_equal(got, ids)
    p = _write(tmp_path, "b", {"x": [0, 1], "y": [0.5, 0.25], "px": [0.0, 0.1], "py": [0.2, 0.3]})[fmt]
    states, got = read_ics_table(p)  # integer positions are numbers too; ids default to the row numbers
    assert states[:, 0].tolist() == [0.0, 1.0] and got.tolist() == [0, 1]


@pytest.mark.parametrize(
    "columns, message",
    [
        ({"x": [0.1], "y": [0.2], "px": [0.3]}, r"lacks column\(s\) \['py'\]"),
        ({"x": [0.1, None], "y": [0.2, 0.2], "px": [0.3, 0.3], "py": [0.1, 0.1]}, "1 row\\(s\\) have non-finite"),
        ({"x": [0.1], "y": [0.2], "px": [0.3], "py": [math.inf]}, "non-finite"),
        ({"x": ["a"], "y": [0.2], "px": [0.3], "py": [0.1]}, "must be numeric"),
        ({"x": [0.1, 0.1], "y": [0.2, 0.2], "px": [0.3, 0.3], "py": [0.1, 0.1], "traj_id": [1, 1]}, "must be unique"),
        (
            {"x": [0.1, 0.1], "y": [0.2, 0.2], "px": [0.3, 0.3], "py": [0.1, 0.1], "traj_id": [1.5, 2.0]},
            "must be integers",
        ),
        (
            {"x": [0.1, 0.1], "y": [0.2, 0.2], "px": [0.3, 0.3], "py": [0.1, 0.1], "traj_id": [1, None]},
            "must be integers",
        ),
    ],
)
def test_mistakes_are_refused(tmp_path, columns, message):
    for p in _write(tmp_path, "m", columns):
        with pytest.raises(ConfigError, match=message):
            read_ics_table(p)


def test_no_rows_missing_file_and_unreadable(tmp_path):
    for p in _write(
        tmp_path,
        "e",
        {
            "x": pa.array([], pa.float64()),
            "y": pa.array([], pa.float64()),
            "px": pa.array([], pa.float64()),
            "py": pa.array([], pa.float64()),
        },
    ):
        with pytest.raises(ConfigError, match="has no rows"):
            read_ics_table(p)
    with pytest.raises(ConfigError, match="file not found"):
        read_ics_table(tmp_path / "none.parquet")
    (tmp_path / "bad.parquet").write_bytes(b"not parquet")
    with pytest.raises(ConfigError, match="cannot read"):
        read_ics_table(tmp_path / "bad.parquet")


def test_reading_imports_no_pandas(tmp_path):
    paths = _write(tmp_path, "c", {"x": [0.1], "y": [0.2], "px": [0.3], "py": [0.1], "traj_id": [7]})
    code = (
        "import sys; from hhscatter.scene.ics import read_ics_table; "
        f"[read_ics_table(p) for p in {[str(p) for p in paths]!r}]; print('pandas' in sys.modules)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "False"


@pytest.mark.parametrize("header", ["x,y,px,py,x", "x,y,px,py,traj_id,traj_id"])
def test_a_duplicated_column_is_refused(tmp_path, header):
    f = tmp_path / "dup.csv"
    f.write_text(header + "\n" + ",".join(["0.1"] * 4 + ["1"] * (len(header.split(",")) - 4)) + "\n")
    with pytest.raises(
        ConfigError,
        match=r"ics: table .*dup.csv has column\(s\) \['(x|traj_id)'\] more than once: "
        "which one holds the initial states is ambiguous",
    ):
        read_ics_table(f)

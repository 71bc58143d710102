"""κ from P(t) of every built-in at E = 1.5 E_c (N = 2e4, t_max = 2000): a check of every built-in.

.venv/bin/python tools/kappa_builtins.py      # ~4 CPU-min; prints one JSON line per system
"""

import json
import sys
import tempfile
import time
import warnings

import hhscatter

rows = []
for spec in (
    {"name": "henon_heiles"},
    {"name": "n_exit", "params": {"n": 4}},
    {"name": "contopoulos"},
    {"name": "barbanis"},
    {"potential": "0.5*(x**2 + y**2) - eps*x**2*y**2", "params": {"eps": 0.25}},
):
    m = hhscatter.make_system(**spec)
    E = 1.5 * m.critical_energy
    sc = hhscatter.Scene(energy=E, n=20000, seed=1, system=spec, t_max=2000.0)
    with tempfile.TemporaryDirectory() as d:
        t0 = time.time()
        hhscatter.simulate(sc, d, workers=1, progress=False)
        wall = time.time() - t0
        lt = hhscatter.read_lifetimes(d)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        f = hhscatter.escape_rates(lt).to_frame().iloc[0]
    rows.append(
        {
            "system": spec.get("name", "declared"),
            "params": m.spec()["params"],
            "E_c": m.critical_energy,
            "exits": [[round(e.x, 6), round(e.y, 6)] for e in m.exits],
            "omega_radius": m.omega_radius,
            "E": E,
            "r_esc": sc.r_esc,
            "kappa": f["kappa"],
            "kappa_err": f["kappa_err"],
            "tau0": f["tau0"],
            "note": f.get("note"),
            "wall_s": round(wall, 1),
            "censored": int((lt["outcome"] == "censored").sum()),
        }
    )
    print(json.dumps(rows[-1]), flush=True)
json.dump(rows, sys.stdout, indent=1)

"""Paper-scale verdict rows of fig5 from the authors' four runs only (issue 28), while the γ runs are not done.

Runs (through the study's runner: resumable, the same scenes and hashes `make fig5 SCALE=paper` uses) the keys
5a_authors, 5b_authors, 5a_authors_random, 5b_authors_random at paper scale with one worker, then computes the
like-for-like rows of verdict_5b and the authors' rows of refs_paired with the study's own functions.
Usage (in a worktree with fig1 at paper scale): .venv/bin/python .dev/fig5_verdict_paper.py run|analyze
"""
import json
import sys

from hhscatter.analysis.geometry import distance as dist
from hhscatter.studies import load_study
from hhscatter.studies.fig5 import study as s5

study = load_study("fig5", "paper")
keys = (*s5.AUTHORS, *s5.SENSITIVITY)
if sys.argv[1] == "run":
    for key in keys:
        study.run(key, s5._authors_scene(study, key), workers=1, progress=False)
        print("done", key, flush=True)
    sys.exit(0)

p = study.params
inputs = {}
cm_full, _ = s5._cmeasure_points(study, inputs, p.E1, float(study.config["scene"]["energy"]))
ref_all = s5._cap(cm_full["E1"], p.n_cap, p.seed)
ref_cut = s5._cap(s5._r_cut(cm_full["E1"], p.r_cut), p.n_cap, p.seed)
auth = s5._authors_sets(study, keys)
a, b = auth[("authors", "5a_authors")], auth[("authors", "5b_authors")]
ar, br = auth[("authors", "5a_authors_random")], auth[("authors", "5b_authors_random")]
out = {"n_E1_cm_full": len(cm_full["E1"]), "rows": []}
for key, (A, B, R), offs in (("old", (a, b, ref_all), 1), ("cut", (a, b, ref_cut), 1),
                             ("cut_offsets", (a, b, ref_cut), p.verdict_offsets),
                             ("cut_offsets_random", (ar, br, ref_cut), p.verdict_offsets)):
    r = dist.paired_hellinger_difference(
        dist.points(A), dist.points(B), dist.points(R), p.box_headline, tuple(p.extent),
        units_a=A["traj_id"].to_numpy(), units_b=B["traj_id"].to_numpy(), units_r=R["traj_id"].to_numpy(),
        offsets=offs, n_boot=p.verdict_boot, level=p.verdict_level, seed=p.seed)
    row = {"construction": key, "n_5a": len(A), "n_5b": len(B), "n_ref": len(R), "d_5a": r.d_a, "d_5b": r.d_b,
           "delta": r.delta, "delta_interval": [r.lo, r.hi], "offset_spread_of_delta": r.offset_spread}
    out["rows"].append(row)
    print(json.dumps(row), flush=True)
# the authors' rows of refs_paired (5a, 5b against μ_c^0.30 and μ_c^0.35, all cut at r < 1), as _refs_paired
refs = {k: s5._cap(s5._r_cut(v, p.r_cut), p.n_cap, p.seed) for k, v in cm_full.items()}
sets = {s: dist.UnitSet(dist.points(df), df["traj_id"].to_numpy(), "run") for s, df in (("5a", a), ("5b", b))}
sets.update({r: dist.UnitSet(dist.points(df), df["traj_id"].to_numpy(), "cm") for r, df in refs.items()})
pairs = [(x, r) for x in ("5a", "5b") for r in ("E1", "E2")]
boxes = sorted(map(float, p.boxes), reverse=True)
reps = dist.paired_hellinger_replicates(sets, pairs, boxes, tuple(p.extent), offsets=p.verdict_offsets,
                                        n_boot=p.verdict_boot, seed=p.seed)
jh = boxes.index(p.box_headline)
for x in ("5a", "5b"):
    i1, i2 = pairs.index((x, "E1")), pairs.index((x, "E2"))
    row = {"refs_paired_authors": x, "d_E1": dist.percentile_interval(reps[:, i1, jh], p.verdict_level),
           "d_E2": dist.percentile_interval(reps[:, i2, jh], p.verdict_level),
           "delta": dist.percentile_interval(reps[:, i2, jh] - reps[:, i1, jh], p.verdict_level)}
    out["rows"].append(row)
    print(json.dumps(row), flush=True)
print(json.dumps(out))

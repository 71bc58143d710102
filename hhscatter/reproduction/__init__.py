"""What reproduces the paper: the numbers, tables and comparisons a figure, a study or a claim assembles.

Above :mod:`hhscatter.analysis` (whose general estimators these modules call) and below the studies and the
report; imports ``model`` and ``analysis`` only.

* ``fig1`` — the paper's Fig. 1 in tables: the record of one energy's c-measure run and its points;
* ``fig2`` — the paper's Fig. 2 values and ours beside them (κ of P(t), τ*, the κ(E) law, κ from the c-measure);
* ``convention_tables`` — κ of each run under the two window rules, the energies where the conventions agree,
  the κ(E) law per convention and its spread across them (Fig. 2b);
* ``kappa_references`` — the κ references a study reads from the escape-rate study's numbers (κ0(E), κ_c);
* ``escape_summaries`` — escape-rate results as numbers and plot tables (P(t), κ, the sticky tail, the κ(E) law);
* ``escape_criterion`` — κ under several r_esc on the same orbits, returns, exit channels, the recommended r_esc;
* ``fig3`` — μ on the paper's and other windows, the inset's histograms, μ in the authors' conventions;
* ``transition_tables``, ``model_tables``, ``model_verdicts`` — τ1, τ2 and the survival models' tables and verdicts;
* ``hazard_fits`` — the fitting rule of the survival models (fitted points, starts, every hazard; Fig. 6);
* ``basin_summary`` — the records of a basin study: outcome codes, per-point records, trends, cut-off records;
* ``saddle_records`` — the records of a chaotic-saddle study: d₁'s error parts and range, d₀ beside d₁, the rows
  and summaries of the Kantz–Grassberger relation and of the dimensions;
* ``cmeasure_comparison``, ``cmeasure_verdicts`` — section points against the conservative c-measure (Fig. 5);
* ``operator_cmeasure``, ``operator_records`` — the transfer operator's measures against sprinkler points of the
  c-measure, its κ beside the escape rate of P(t) and its dissipative survival beside a simulated one;
* ``noise_records`` — thermal and noisy escape rates against Kramers–Langer and the turnover theory, and their
  checks (finite barrier, absorbing radius, two saddles, no drag, re-activation);
* ``claims`` — the paper's claims tested on a system, and the evidence behind their readings;
* ``verdicts`` — the rule of every comparison with the paper, the kinds of reference, the smoke scale that states
  none.

Every module and subpackage of the package is in this list (a test checks it).
"""

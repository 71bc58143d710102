"""Pure analysis functions on arrays and DataFrames (numpy, scipy, pandas; no files, no integration).

* ``stats`` — least squares, intervals, verdict wording;
* ``survival`` — P(t) (Kaplan–Meier), κ from P(t) and from the c-measure, the κ(E) law, fit windows;
* ``dissipative`` — energy decay, transition times τ0, τ1, τ2, the survival model and its mixture;
* ``geometry`` — section-point distances, exit basins and their fractality, the transfer operator, exit channels.
"""

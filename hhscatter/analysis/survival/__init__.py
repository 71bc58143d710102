"""Escape from P(t): Kaplan–Meier curves, exponential and power-law fits, κ and its windows, κ from the c-measure, the κ(E) law."""

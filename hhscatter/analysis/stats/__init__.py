"""Statistics shared by the analyses: weighted least squares, binomial intervals, verdict wording."""

"""Phase-space geometry: distances of section-point sets, exit basins (fractality, Wada), the transfer operator, exit channels."""

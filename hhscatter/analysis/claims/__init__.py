"""The paper's claims tested on a system, and the evidence behind their readings (regular orbits, long-time escape)."""

"""Analysis of the engine's tables (lifetimes, snapshots, sections): pure functions, no I/O."""

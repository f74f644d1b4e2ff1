"""Measuring: the metrics computed from a run, their catalogue (names, units, how each is
gated), the error model every verdict reads, and how a measured number is written."""

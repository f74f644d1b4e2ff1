"""The units at pbcm's edges: SI inside every computation, millimetres where a user reads or
writes (case settings, reports)."""

MM = 1e-3    # metres per millimetre

"""Running: the shared runner of a case's models and references, the worker pool, the run
store, the progress display, the stop on a signal, atomic output and the gate over the runs'
metrics against the gold values."""

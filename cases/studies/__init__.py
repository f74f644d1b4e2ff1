"""Studies: work of its own shape built on the cases (several cases, mesh sizes, derived
fits), each a ``cases.framework.Study`` named in ``cases.registry`` (convergence, extensions),
or a command of its own (``fit``: parameter identification; ``sweeps``: parameter sweeps).
A study uses the harness and the cases; it reaches another study only through the registry."""

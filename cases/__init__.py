"""Experiments, metrics and the ``pbcm`` command."""

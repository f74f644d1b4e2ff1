"""``python -m cases.cli``: the pbcm command."""
import sys

from . import console

sys.exit(console())

"""``python -m cases.cli``: the pbcm command."""
import sys

from . import main

sys.exit(main())

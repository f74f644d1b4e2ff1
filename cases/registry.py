"""Cases by name: each is a module with Config, run, MESHES, BCS and MODELS."""
from . import paper_cube

CASES = {"paper-cube": paper_cube}

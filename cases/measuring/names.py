"""The run keys derived from a quantity's name: its FEM value, its relative error, its value at
the case's load. Kept apart from the catalogue so that the error model can name keys without
importing the reports' formatting."""

# a run key's unit suffix and the unit it names (the longest suffix a name ends with counts)
UNIT_OF_SUFFIX = {"_1_s": "1/s", "_mm": "mm", "_nm": "N m", "_n": "N", "_hz": "Hz", "_s": "s",
                  "_pa": "Pa"}
UNIT_SUFFIXES = tuple(UNIT_OF_SUFFIX)


def unit_suffix(name):
    """The unit suffix ``name`` ends with (the longest of UNIT_SUFFIXES), or None."""
    return max((x for x in UNIT_SUFFIXES if name.endswith(x)), key=len, default=None)


def _split(name):
    """(stem, unit suffix or '') of ``name``."""
    unit = unit_suffix(name) or ""
    return name[:len(name) - len(unit)], unit


def ref_name(name):
    """The run key of the FEM value of quantity ``name``: '_fem' before a unit suffix
    (bulge_profile_mm -> bulge_profile_fem_mm, paper_pattern -> paper_pattern_fem)."""
    stem, unit = _split(name)
    return stem + "_fem" + unit


def load_name(name):
    """The run key of quantity ``name`` at the case's load (the finite-strain solve):
    '_at_load' before a unit suffix (tip_deflection_mm -> tip_deflection_at_load_mm); its
    continuum value is ``ref_name`` of it."""
    stem, unit = _split(name)
    return stem + "_at_load" + unit


def err_name(name):
    """The run key of the relative error of quantity ``name`` (tip_deflection_mm ->
    tip_deflection_rel_err)."""
    return _split(name)[0] + "_rel_err"

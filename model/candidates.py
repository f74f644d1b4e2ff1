"""The normal-stress candidates: the paper's model with one deviatoric normal form added
each (docs/model.md, "Normal-stress extensions"). The extensions study ranks them and the
bench times them by default, so they are named here, with the models, once."""
from .compose import label

BASE = "pbcm-variational"    # the paper's model: its best reading (variational, c fitted)
# the normal-stress forms added to the paper's model, one candidate each
NORMAL_FORMS = ("normal_edge", "normal_tet", "normal_corotated", "normal_sbd")
CANDIDATES = tuple(label(f"{BASE} + {form}(c=auto)") for form in NORMAL_FORMS)


def short(model):
    """The name the report's tables use: the added term of a candidate, else the model."""
    for form in NORMAL_FORMS:
        if model == label(f"{BASE} + {form}(c=auto)"):
            return f"+{form}"
    return model


__all__ = ["BASE", "NORMAL_FORMS", "CANDIDATES", "short"]

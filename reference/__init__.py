"""FEM references (scikit-fem) and closed forms the particle model is measured against."""

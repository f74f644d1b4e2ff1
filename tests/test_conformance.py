"""The conformance gate (model.conformance): every built-in term passes it with every option,
and a user term with a bug is refused when it is first made, from Python and from `--term`,
with the name of the check it fails and the numbers."""
import textwrap

import numpy as np
import pytest

import model.terms
from model import Material
from model.conformance import EXACT, GRADIENT, checks, conform, probe
from model.errors import ModelError
from model.mesh import cube
from model.terms import make_term, registered

# a user term from scratch: springs on the mesh edges, W = F/2 k sum (L - L0)^2, with one bug
# switched on by name
TEMPLATE = '''
import numpy as np
from numba import njit
from model.terms import Term, register

SIGN, FACTOR, NUMPY_K, PUSH, REST = {sign}, {factor}, {numpy_k}, {push}, {rest}


@njit(cache=False)
def edge_forces(x, edges, rest, k, out):
    for e in range(edges.shape[0]):
        i, j = edges[e, 0], edges[e, 1]
        d = x[j] - x[i]
        length = np.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
        for a in range(3):
            f = SIGN * k * (length - rest[e]) / length * d[a]
            out[i, a] += f
            out[j, a] -= f
    out[0, 0] += PUSH * k * rest[0]
    return -1


@register
class EdgeSprings(Term):
    name = "edge_springs_{bug}"
    conservative = True

    def __init__(self, mesh, material, scale=1.0, **params):
        super().__init__(mesh, material, scale, **params)
        e = mesh.edges
        self.rest = REST * np.linalg.norm(mesh.points[e[:, 1]] - mesh.points[e[:, 0]], axis=1)
        self.k = self.scale * material.E * self.rest.mean()

    def kernel(self):
        return edge_forces, (self.mesh.edges, self.rest, self.k)

    def forces_numpy(self, x):
        e = self.mesh.edges
        d = x[e[:, 1]] - x[e[:, 0]]
        length = np.linalg.norm(d, axis=1)
        f = SIGN * NUMPY_K * self.k * ((length - self.rest) / length)[:, None] * d
        out = np.zeros_like(x)
        np.add.at(out, e[:, 0], f)
        np.add.at(out, e[:, 1], -f)
        out[0, 0] += PUSH * self.k * self.rest[0]
        return out

    def energy(self, x):
        e = self.mesh.edges
        length = np.linalg.norm(x[e[:, 1]] - x[e[:, 0]], axis=1)
        return FACTOR * 0.5 * self.k * float(np.sum((length - self.rest) ** 2))
'''
SOUND = {"sign": 1.0, "factor": 1.0, "numpy_k": 1.0, "push": 0.0, "rest": 1.0}
BUGS = {  # bug: (what is changed, the check that must catch it)
    "sign": ({"sign": -1.0}, "forces equal minus the energy gradient"),
    "factor": ({"factor": 0.5}, "forces equal minus the energy gradient"),
    "numpy": ({"numpy_k": 0.5}, "kernel equals forces_numpy"),
    "net": ({"push": 1e-3}, "zero net force"),
    "rest": ({"rest": 0.9}, "zero force at rest"),
}


@pytest.fixture(scope="module")
def term_file(tmp_path_factory):
    """The file of the edge-spring term with ``bug`` (one file per bug in the session: a
    term is registered once per process)."""
    folder = tmp_path_factory.mktemp("terms")

    def write(bug):
        path = folder / f"edge_springs_{bug}.py"
        if not path.exists():
            values = {**SOUND, **(BUGS[bug][0] if bug in BUGS else {})}
            path.write_text(textwrap.dedent(TEMPLATE.format(bug=bug, **values)))
        return path
    return write


def _options(name):
    return [{"reading": r} for r in ("corner", "balanced", "variational")] \
        if name == "shear" else [{}]


@pytest.mark.parametrize("name", sorted(registered()))
def test_every_built_in_term_passes_with_a_margin(name):
    """Each check passes by a factor 100 at least: the bounds are not tuned to the terms."""
    cls = registered()[name]
    for opts in _options(name):
        mesh, mat, x = probe()
        p = {**cls.params, **opts}
        if p.get("c") == "auto":
            p["c"] = 0.5
        for check, value, bound in checks(cls(mesh, mat, **p), mesh, x):
            assert value <= bound / 100, (name, opts, check, value)


def test_the_claims_are_declared_where_a_term_does_not_make_them():
    """The corner shear reading claims neither momentum nor angular momentum, the balanced one
    momentum only, and fem_linear neither rotation invariance nor angular momentum; the corner
    reading is not checked for zero net force or torque, and its net force is indeed far from
    zero."""
    mesh, mat, x = probe()
    corner = make_term("shear", mesh, mat, reading="corner", c=0.5)
    balanced = make_term("shear", mesh, mat, reading="balanced", c=0.5)
    assert not corner.momentum and not corner.angular_momentum
    assert balanced.momentum and not balanced.angular_momentum
    linear = registered()["fem_linear"]
    assert not linear.rotation_invariant and not linear.angular_momentum
    # and what a term does not claim it indeed does not do (else the claim should be made)
    names = {c for c, _, _ in checks(corner, mesh, x)}
    assert "zero net force" not in names and "zero net torque" not in names
    f = corner.forces(x)
    assert np.linalg.norm(f.sum(axis=0)) > 1e3 * EXACT * np.abs(f).sum()


def test_a_sound_user_term_passes(term_file):
    """A user edge-spring term with no bug is made without being refused by the conformance gate and
    keeps its claim to be conservative."""
    model.terms.load_file(term_file("sound"))
    t = make_term("edge_springs_sound", cube(3, 0.02, "six"),
                  Material(E=10e3, nu=0.3, rho=1000.0))
    assert t.conservative


@pytest.mark.parametrize("bug", BUGS)
def test_a_broken_user_term_is_refused_with_the_check_and_the_numbers(term_file, bug):
    """A user term with one bug (a flipped force sign, a wrong energy factor, a NumPy path unlike
    the kernel, a net force, a force at rest) is refused when made with a ModelError naming the
    term, the check it fails and its value against the bound, and a later conformance call
    refuses it again."""
    model.terms.load_file(term_file(bug))
    check = BUGS[bug][1]
    with pytest.raises(ModelError, match=f"edge_springs_{bug}.*refused.*'{check}': [0-9.e+-]+ "
                                         f"> [0-9.e+-]+"):
        make_term(f"edge_springs_{bug}", cube(3, 0.02, "six"),
                  Material(E=10e3, nu=0.3, rho=1000.0))
    # refused again: a failed term is never marked as passed
    with pytest.raises(ModelError, match=check):
        conform(registered()[f"edge_springs_{bug}"])


def test_the_gradient_bound_separates_truncation_from_a_missing_factor(term_file):
    """The sound term's gradient error is the difference's truncation, far below the bound;
    a factor 2 is of order one."""
    model.terms.load_file(term_file("sound"))
    mesh, mat, x = probe()
    value = dict((c, v) for c, v, _ in checks(registered()["edge_springs_sound"](mesh, mat),
                                               mesh, x))["forces equal minus the energy gradient"]
    assert value < GRADIENT / 100


def test_a_broken_term_file_is_refused_by_the_command_before_computing(term_file, tmp_path,
                                                                     capsys):
    """`pbcm run --term` with a term whose forces have the wrong sign exits 2 with an error naming
    the refused energy-gradient check, and writes no metrics.json."""
    from cases.cli import main
    path = term_file("sign")
    out = tmp_path / "out"
    status = main(["run", "paper-cube", "--quick", "--term", str(path), "--models",
                   "edge_springs_sign", "--out", str(out)])
    err = capsys.readouterr().err
    assert status == 2
    assert "'forces equal minus the energy gradient'" in err and "refused" in err
    assert not (out / "metrics.json").exists()


def test_a_term_with_non_finite_forces_is_refused_saying_so(tmp_path):
    """A term whose forces hold a NaN is refused with the count of non-finite components,
    never with a NaN printed as a number ('0')."""
    path = tmp_path / "edge_springs_nan.py"
    path.write_text(textwrap.dedent(TEMPLATE.format(bug="nan", **{**SOUND,
                                                                  "push": "float('nan')"})))
    model.terms.load_file(path)
    with pytest.raises(ModelError, match=r"'finite forces at a deformed state': not finite "
                                         r"\(nan\), expected finite \(\d+ of \d+ components "
                                         r"are not\)"):
        make_term("edge_springs_nan", cube(3, 0.02, "six"), Material(E=10e3, nu=0.3, rho=1000.0))


def test_a_term_that_raises_is_refused_in_one_line(tmp_path):
    """A user term whose constructor raises its own error (not pbcm's) is refused with a
    ModelError naming the term and the error, which the command line prints as one line."""
    path = tmp_path / "raising_term.py"
    path.write_text(textwrap.dedent('''
        from model.terms import Term, register

        @register
        class Raising(Term):
            name = "raising"

            def __init__(self, mesh, material, scale=1.0, **params):
                raise ValueError("my table is missing")
    '''))
    model.terms.load_file(path)
    with pytest.raises(ModelError, match="'raising' raised ValueError.*my table is missing"):
        make_term("raising", cube(3, 0.02, "six"), Material(E=10e3, nu=0.3, rho=1000.0))

"""The TOML of a user's problem, read and checked whole before anything is computed.

:func:`load` returns a :class:`Spec`: the mesh (read by meshio, in metres), the material, the
selections of nodes, the prescribed displacements, tractions and gravity, the measured
quantities, the models and the references. Every mistake is a :class:`ProblemError` of one
line naming the file, the key and what to do. Lengths in the TOML are in the mesh's unit
(``[mesh] unit``), forces in newtons and stresses in pascals; inside, everything is SI.
"""
import hashlib
import json
import re
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from model import PRESETS, Material
from model.bc import merge
from model.errors import MeshError, ModelError
from model.loads import boundary_facets
from model.material import poisson_problem
from model.mesh import read_with_sets
from model.units import MM

LENGTH_UNITS = {"m": 1.0, "cm": 1e-2, "mm": MM, "um": 1e-6, "in": 0.0254}
AXES = ("x", "y", "z")
# a case name: the folder reports/problems/NAME and the name metrics.json gates under
NAME = re.compile(r"[a-z0-9][a-z0-9_-]{0,63}")
MEASURE_NAME = re.compile(r"[a-z][a-z0-9_]{0,47}")
MEASURE_KINDS = ("reaction", "displacement", "profile")
SCALAR_KINDS = ("reaction", "displacement")
HINT = "`pbcm problem new NAME` writes a commented template"
# the keys of each kind of selection (a selection gives the keys of one kind)
SELECTION_KEYS = {"plane": ("axis", "at", "tolerance"), "box": ("min", "max"),
                  "set": ("set",), "nearest": ("nearest",)}
# every key of every table (the template explains each)
KEYS = {"": ("name", "title", "models", "gravity", "mesh", "material", "select",
             "displacement", "traction", "measure", "references"),
        "mesh": ("file", "unit", "up"), "material": ("E", "nu", "rho"),
        "select": tuple(k for keys in SELECTION_KEYS.values() for k in keys),
        "displacement": ("on", "value", "components", "fixed"), "traction": ("on", "value"),
        "measure": ("name", "kind", "on", "axis", "at", "component", "along", "through",
                    "from", "to", "samples"),
        "references": ("neohookean", "p2_levels", "nh_levels")}
# the rigid motions the prescribed displacements must hold (a singular problem otherwise)
RIGID = ("translation along x", "translation along y", "translation along z",
         "rotation about x", "rotation about y", "rotation about z")
RIGID_TOL = 1e-9          # relative singular value below which a rigid motion is free


class ProblemError(ModelError):
    """The TOML of a problem is wrong: the message names the file, the key and what to do."""


_REQUIRED = object()


class Table:
    """One TOML table being read: each key checked as it is taken, and ``done()`` refuses
    the keys nobody took (a misspelt key would otherwise be ignored silently)."""

    def __init__(self, source, where, data):
        self.source, self.where = source, where
        if not isinstance(data, dict):
            raise ProblemError(f"{source}: {where or 'the file'} must be a table, got "
                               f"{_shown(data)}; {HINT}")
        self.data, self.taken = data, []

    def path(self, key):
        return ".".join(k for k in (self.where, key) if k)

    def error(self, key, what):
        return ProblemError(f"{self.source}: {self.path(key)}: {what}")

    def raw(self, key, what, default=_REQUIRED):
        """The value of ``key`` as written, or ``default``; absent without one: an error."""
        if self.absent(key, what, default):
            return default
        return self.data[key]

    def absent(self, key, what, default):
        """True where ``key`` is not given and has a ``default`` (the key counts as taken
        either way); not given without one: an error saying what it is."""
        self.taken.append(key)
        if key in self.data:
            return False
        if default is _REQUIRED:
            raise ProblemError(f"{self.source}: missing key {self.path(key)} ({what}); add "
                               f"it ({HINT})")
        return True

    def number(self, key, what, default=_REQUIRED, low=None, integer=False):
        if self.absent(key, what, default):
            return default
        v = self.data[key]
        kind = int if integer else (int, float)
        if isinstance(v, bool) or not isinstance(v, kind) or not np.isfinite(v) \
                or (low is not None and v < low):
            bound = "" if low is None else f" >= {low:g}"
            raise self.error(key, f"must be {'an integer' if integer else 'a number'}{bound} "
                                  f"({what}), got {_shown(v)}")
        return v

    def string(self, key, what, default=_REQUIRED, choices=None):
        if self.absent(key, what, default):
            return default
        v = self.data[key]
        if not isinstance(v, str) or (choices and v not in choices):
            valid = f"one of {', '.join(choices)}" if choices else "a string"
            raise self.error(key, f"must be {valid} ({what}), got {_shown(v)}")
        return v

    def axis(self, key, what, default=_REQUIRED):
        if self.absent(key, what, default):
            return default
        return AXES.index(self.string(key, what, choices=AXES))

    def axes(self, key, what, default=_REQUIRED):
        if self.absent(key, what, default):
            return default
        v = self.data[key]
        if not isinstance(v, list) or not v or any(a not in AXES for a in v) \
                or len(set(v)) != len(v):
            raise self.error(key, f"must be a list of distinct axes among \"x\", \"y\", \"z\" "
                                  f"({what}), got {_shown(v)}")
        return tuple(AXES.index(a) for a in v)

    def vector(self, key, what, default=_REQUIRED):
        if self.absent(key, what, default):
            return default
        v = self.data[key]
        if not isinstance(v, list) or len(v) != 3 or any(
                isinstance(x, bool) or not isinstance(x, (int, float)) or not np.isfinite(x)
                for x in v):
            raise self.error(key, f"must be three numbers [x, y, z] ({what}), got {_shown(v)}")
        return np.array(v, dtype=float)

    def table(self, key, what, default=_REQUIRED):
        if self.absent(key, what, default):
            return default
        v = self.data[key]
        if not isinstance(v, dict):
            raise self.error(key, f"must be a table ({what}), got {_shown(v)}")
        return Table(self.source, self.path(key), v)

    def tables(self, key, what):
        """The tables of the array ``[[key]]`` (none when absent), named key[1], key[2]..."""
        v = self.raw(key, what, [])
        if not isinstance(v, list) or not all(isinstance(t, dict) for t in v):
            raise self.error(key, f"must be an array of tables, each written [[{key}]] "
                                  f"({what})")
        return [Table(self.source, f"{self.path(key)}[{i}]", t) for i, t in enumerate(v, 1)]

    def only(self, *keys):
        """Refuse at once a key not among ``keys`` (a misspelt table would otherwise be
        reported as the one missing)."""
        self._refuse([k for k in self.data if k not in keys], keys)

    def done(self):
        """Refuse the keys nobody took."""
        self._refuse([k for k in self.data if k not in self.taken], self.taken)

    def _refuse(self, unknown, valid):
        if unknown:
            where = f" of [{self.where}]" if self.where else ""
            raise ProblemError(f"{self.source}: unknown key {self.path(unknown[0])} (valid "
                               f"keys{where}: {', '.join(dict.fromkeys(valid)) or 'none'}); "
                               "correct or remove it")


def nodes_said(n):
    """'1 node', '19 nodes'."""
    return f"{n} node" + ("" if n == 1 else "s")


def _shown(v):
    text = json.dumps(v) if isinstance(v, (str, list, dict, bool)) else repr(v)
    return text if len(text) < 60 else text[:57] + "..."


@dataclass
class Selection:
    """A named set of nodes as the TOML declares it: ``text`` says how, in the TOML's
    words; ``nodes`` the mesh's node indices."""

    name: str
    kind: str
    text: str
    nodes: np.ndarray


@dataclass
class Surface:
    """A uniform traction ``value`` [Pa] (3,) on the boundary triangles ``faces`` (k, 3)
    whose three nodes are in the selection ``on``."""

    on: str
    value: tuple
    faces: np.ndarray


@dataclass
class Measure:
    """A measured quantity: ``key`` its run key (``NAME_n`` for a reaction, ``NAME_mm`` for
    a displacement or a profile), ``text`` what it is, in the TOML's words; a reaction's
    ``nodes`` and ``axis``; a displacement's ``node`` and ``component``; a profile's
    ``located`` points (``TetMesh.locate``) at ``positions`` [m] along ``axis``."""

    name: str
    kind: str
    key: str
    text: str
    component: int = None
    axis: int = None
    nodes: np.ndarray = None
    node: int = None
    located: tuple = None
    positions: np.ndarray = None

    @property
    def scalar(self):
        return self.kind in SCALAR_KINDS


@dataclass
class Spec:
    """A problem as its TOML declares it, checked; lengths in metres."""

    path: Path
    source: bytes           # the TOML as read: what a run copies into its folder
    name: str
    title: str
    mesh_file: Path
    unit: str
    up: int
    mesh: object
    material: Material
    selections: dict
    dirichlet: dict
    held: list              # what each [[displacement]] prescribes, in the TOML's words
    surfaces: list
    gravity: float
    measures: list
    models: tuple
    neohookean: bool
    p2_levels: int
    nh_levels: int
    digests: dict = field(default_factory=dict)


# ---------------------------------------------------------------- reading


def load(path):
    """The checked :class:`Spec` of the TOML file ``path``; a ProblemError otherwise."""
    path = Path(path)
    if not path.is_file():
        raise ProblemError(f"problem file {path} does not exist (or is not a file); give the "
                           f"path of a problem's TOML ({HINT})")
    source = path.read_bytes()
    try:
        data = tomllib.loads(source.decode("utf-8"))
    except (UnicodeDecodeError, tomllib.TOMLDecodeError) as exc:
        raise ProblemError(f"{path}: not a valid TOML file ({exc}); correct it") from None
    return parse(data, path, source)


def parse(data, path, source=b""):
    """The checked :class:`Spec` of the parsed TOML ``data`` read from ``path`` (relative
    mesh paths are relative to its folder)."""
    path = Path(path)
    top = Table(path.name, "", data)
    top.only(*KEYS[""])
    name = _name(top)
    title = top.string("title", "one line for the report", "")
    models = _models(top)
    gravity = top.number("gravity", "m/s^2 along -up; 0 for none", 0.0)
    mesh_t = top.table("mesh", "the mesh file, its unit and up axis")
    mesh_file, unit, up, mesh, sets = _mesh(mesh_t, path)
    material = _material(top.table("material", "E [Pa], nu, rho [kg/m^3]"))
    scale = LENGTH_UNITS[unit]
    selections = _selections(top.table("select", "named selections of nodes"), mesh, sets,
                             scale, unit)
    dirichlet, held = _dirichlet(top, selections, scale, unit)
    surfaces = _surfaces(top, mesh, selections)
    measures = _measures(top, mesh, selections, dirichlet, scale, unit)
    neohookean, p2_levels, nh_levels = _references(top)
    top.done()
    _holds_rigid_motions(top, mesh, dirichlet)
    _loaded(top, dirichlet, surfaces, gravity)
    return Spec(path=path, source=source, name=name, title=title, mesh_file=mesh_file,
                unit=unit, up=up, mesh=mesh, material=material, selections=selections,
                dirichlet=dirichlet, held=held, surfaces=surfaces, gravity=float(gravity),
                measures=measures, models=models, neohookean=neohookean,
                p2_levels=p2_levels, nh_levels=nh_levels, digests=_digests(data, mesh_file))


def _references(top):
    """(neohookean, p2_levels, nh_levels) of the optional table [references]."""
    refs = top.table("references", "neohookean, p2_levels, nh_levels", None) \
        or Table(top.source, "references", {})
    refs.only(*KEYS["references"])
    neohookean = refs.raw("neohookean", "true: the neo-Hookean reference at the load", False)
    if not isinstance(neohookean, bool):
        raise refs.error("neohookean", f"must be true or false, got {_shown(neohookean)}")
    p2_levels = refs.number("p2_levels", "refinements of the P2 reference", 2, low=1,
                            integer=True)
    nh_levels = refs.number("nh_levels", "refinements of the neo-Hookean reference", 1,
                            low=1, integer=True)
    refs.done()
    return neohookean, int(p2_levels), int(nh_levels)


def _digests(data, mesh_file):
    """The sha256 of what defines the problem's physics in the TOML (as parsed: neither its
    comments nor its name, title and models) and of the mesh file's bytes."""
    physics = {k: v for k, v in data.items() if k not in ("name", "title", "models")}
    text = json.dumps(physics, sort_keys=True, default=str).encode()
    return {"spec_sha256": hashlib.sha256(text).hexdigest(),
            "mesh_sha256": hashlib.sha256(mesh_file.read_bytes()).hexdigest()}


def check_name(name, error):
    """``name`` if it can name a problem (a safe folder name, no library case's or study's);
    else ``error(what)``, an exception to raise."""
    from ...registry import CASES, STUDY_MODULES
    if not isinstance(name, str) or not NAME.fullmatch(name):
        raise error(f"must be lower-case letters, digits, '-' and '_' (a folder name, at most "
                    f"64, starting with a letter or digit), got {_shown(name)}")
    if name in CASES or name in STUDY_MODULES:
        raise error(f"{name!r} is the name of the library's {name} "
                    f"{'case' if name in CASES else 'study'}; choose another")
    return name


def _name(top):
    return check_name(top.raw("name", "the problem's name, its output folder"),
                      lambda what: top.error("name", what))


def _models(top):
    """The models (canonical labels; default every preset), each checked by building it."""
    from model.compose import checked
    given = top.raw("models", "presets, or terms composed with '+'", None)
    if given is None:
        return tuple(PRESETS)
    if not isinstance(given, list) or not given or not all(isinstance(m, str) for m in given):
        raise top.error("models", f"must be a list of model names, got {_shown(given)}; "
                                  "leave it out for every preset")
    out = []
    for m in given:
        try:
            out.append(checked(m))
        except ModelError as exc:
            raise top.error("models", f"{exc}") from None
    return tuple(dict.fromkeys(out))


def _mesh(t, path):
    """(file, unit, up axis, TetMesh in metres, named node sets) of ``[mesh]``."""
    t.only(*KEYS["mesh"])
    file = t.string("file", "a mesh file meshio reads, relative to this TOML")
    unit = t.raw("unit", "the length unit of the mesh: " + ", ".join(LENGTH_UNITS))
    if unit not in LENGTH_UNITS:
        raise t.error("unit", f"{_shown(unit)} is not a length unit; give one of "
                              f"{', '.join(LENGTH_UNITS)}")
    up = t.axis("up", "the vertical axis: gravity acts along -up")
    t.done()
    where = (path.parent / file)
    if not where.is_file():
        raise t.error("file", f"mesh file {where} does not exist (a path relative to "
                              f"{path.name}'s folder); give an existing mesh file")
    try:
        mesh, sets = read_with_sets(where)
    except MeshError as exc:
        raise t.error("file", f"{exc}") from None
    from model.mesh import TetMesh
    return where, unit, up, TetMesh(mesh.points * LENGTH_UNITS[unit], mesh.tets), sets


def _material(t):
    t.only(*KEYS["material"])
    E = t.number("E", "Young's modulus [Pa]")
    nu = t.number("nu", "Poisson's ratio")
    rho = t.number("rho", "density [kg/m^3]")
    t.done()
    for key, v, ok in (("E", E, E > 0), ("nu", nu, not poisson_problem(nu)),
                       ("rho", rho, rho > 0)):
        if not ok:
            raise t.error(key, poisson_problem(nu) if key == "nu" else
                          f"must be > 0, got {v:g}; give a positive {key}")
    return Material(E=float(E), nu=float(nu), rho=float(rho))


# ---------------------------------------------------------------- selections


def _selections(t, mesh, sets, scale, unit):
    out = {}
    for name in list(t.data):
        sel = t.table(name, "a selection")
        out[name] = _selection(sel, name, mesh, sets, scale, unit)
    t.done()
    if not out:
        raise t.error("", "declares no selection; name at least the nodes the displacements "
                          "hold")
    return out


def _selection(t, name, mesh, sets, scale, unit):
    """The nodes of one selection: a plane, a box, a named set of the file or a node."""
    kinds = [k for k, keys in SELECTION_KEYS.items() if any(key in t.data for key in keys)]
    if len(kinds) != 1:
        raise t.error("", "give one kind of selection: a plane (axis, at, optional "
                          "tolerance), a box (min, max), a named set of the mesh file (set) "
                          "or the node nearest a point (nearest)"
                      + (f"; it mixes {' and '.join(kinds)}" if kinds else ""))
    kind = kinds[0]
    nodes, text = SELECTORS[kind](t, mesh, sets, scale, unit)
    t.done()
    if not len(nodes):
        raise t.error("", f"selects no node ({text}; the mesh spans "
                          f"{_extent(mesh, scale)}); correct it")
    return Selection(name, kind, text, np.asarray(nodes, dtype=np.int64))


def _extent(mesh, scale):
    lo, hi = mesh.points.min(axis=0) / scale, mesh.points.max(axis=0) / scale
    return ", ".join(f"{a} {a0:.4g}..{a1:.4g}" for a, a0, a1 in zip(AXES, lo, hi))


def _plane(t, mesh, sets, scale, unit):
    axis = t.axis("axis", "the plane's normal axis")
    at = t.number("at", "the plane's coordinate")
    tol = t.number("tolerance", "how far from the plane a node may be", None, low=0)
    tol = 1e-6 * mesh.size if tol is None else tol * scale
    nodes = mesh.nodes_on_plane(axis, at * scale, tol)
    return nodes, f"plane {AXES[axis]} = {at:g} {unit}, tolerance {tol / scale:.3g} {unit}"


def _box(t, mesh, sets, scale, unit):
    lo, hi = t.vector("min", "the box's lowest corner"), t.vector("max", "its highest corner")
    if np.any(lo > hi):
        raise t.error("max", f"must be at least min in every coordinate, got min {lo.tolist()}"
                             f" and max {hi.tolist()}")
    nodes = mesh.nodes_where(lambda p: np.all((p >= lo * scale) & (p <= hi * scale), axis=1))
    return nodes, f"box {_at(lo, 1)} to {_at(hi, 1)} {unit}"


def _set(t, mesh, sets, scale, unit):
    name = t.string("set", "a point set, cell set or physical group of the mesh file")
    if name not in sets:
        raise t.error("set", f"the mesh file has no set named {name!r} (its sets: "
                             f"{', '.join(sets) or 'none'}); give one of them")
    return sets[name], f"the mesh file's set {name!r}"


def _nearest(t, mesh, sets, scale, unit):
    p = t.vector("nearest", "a point: its nearest node is selected")
    node = int(np.argmin(np.linalg.norm(mesh.points - p * scale, axis=1)))
    away = np.linalg.norm(mesh.points[node] - p * scale)
    return [node], (f"node {node} at {_at(mesh.points[node], scale)} {unit}, the nearest to "
                    f"{_at(p, 1)} ({away / scale:.3g} {unit} away)")


def _at(x, scale):
    return "(" + ", ".join(f"{v / scale:.4g}" for v in x) + ")"


SELECTORS = {"plane": _plane, "box": _box, "set": _set, "nearest": _nearest}


def _selected(t, key, selections, what):
    name = t.string(key, what)
    if name not in selections:
        raise t.error(key, f"names no selection of [select] (declared: "
                           f"{', '.join(selections) or 'none'}); declare {name!r} there")
    return selections[name]


# ---------------------------------------------------------------- boundary conditions


def _dirichlet(top, selections, scale, unit):
    """({node: (ux, uy, uz)} [m] of every [[displacement]], what each prescribes in the
    TOML's words); a component given twice with two values is an error naming the second."""
    out, held = {}, []
    for t in top.tables("displacement", "prescribed displacements"):
        t.only(*KEYS["displacement"])
        sel = _selected(t, "on", selections, "the selection whose nodes are held")
        if "fixed" in t.data and ("value" in t.data or "components" in t.data):
            raise t.error("fixed", "give either fixed (components held at zero) or value with "
                                   "optional components, not both")
        if "fixed" in t.data:
            comps, value = t.axes("fixed", "the components held at zero"), np.zeros(3)
        else:
            value = t.vector("value", "the displacement [ux, uy, uz] in the mesh's unit")
            comps = t.axes("components", "the components of value prescribed", (0, 1, 2))
        t.done()
        u = tuple(float(value[k] * scale) if k in comps else None for k in range(3))
        held.append(f"{sel.name} ({nodes_said(len(sel.nodes))}): " + ", ".join(
            f"u_{AXES[k]} = {value[k]:g} {unit}" for k in sorted(comps)))
        try:
            out = merge(list(out.items()) + [(int(i), u) for i in sel.nodes])
        except ModelError as exc:
            raise t.error("on", f"{exc} (values in m: an earlier [[displacement]] gives it "
                                "another value)") from None
    return out, held


def _surfaces(top, mesh, selections):
    out = []
    tri = boundary_facets(mesh.tets)
    for t in top.tables("traction", "tractions on boundary faces"):
        t.only(*KEYS["traction"])
        sel = _selected(t, "on", selections, "the selection whose boundary faces are loaded")
        value = t.vector("value", "the traction [tx, ty, tz] in Pa (force per area)")
        t.done()
        inside = np.isin(tri, sel.nodes).all(axis=1)
        if not inside.any():
            raise t.error("on", f"selection {sel.name!r} holds no boundary face (a traction "
                                "loads the boundary triangles whose three nodes are "
                                "selected); select a surface")
        out.append(Surface(sel.name, tuple(map(float, value)), tri[inside]))
    return out


def _holds_rigid_motions(top, mesh, dirichlet):
    """Refuse prescribed displacements that leave a rigid motion free (the problem would be
    singular): the six rigid motions restricted to the prescribed components must have
    rank six."""
    if not dirichlet:
        raise top.error("displacement", "no [[displacement]]: without prescribed "
                                        "displacements every rigid motion is free; hold some "
                                        "nodes")
    nodes = np.array(list(dirichlet), dtype=np.int64)
    given = np.array([[v is not None for v in dirichlet[i]] for i in nodes])
    x = (mesh.points[nodes] - mesh.points.mean(axis=0)) / mesh.size   # rotations ~ translations
    motions = np.zeros((len(nodes), 3, 6))
    motions[:, [0, 1, 2], [0, 1, 2]] = 1.0
    for k, (a, b) in enumerate(((1, 2), (2, 0), (0, 1))):          # about x, y, z
        motions[:, a, 3 + k], motions[:, b, 3 + k] = -x[:, b], x[:, a]
    _, sv, vt = np.linalg.svd(motions[given], full_matrices=True)
    sv = np.r_[sv, np.zeros(6 - len(sv))]
    free = vt[sv <= RIGID_TOL * sv.max()]
    if len(free):
        names = sorted({RIGID[int(np.argmax(np.abs(v)))] for v in free})
        raise top.error("displacement", f"the prescribed displacements leave rigid motions "
                                        f"free ({', '.join(names)}): the problem is singular; "
                                        "hold more components (a node on the axis of a free "
                                        "rotation held sideways, another held around it)")


def _loaded(top, dirichlet, surfaces, gravity):
    moved = any(v not in (None, 0.0) for u in dirichlet.values() for v in u)
    pulled = any(any(s.value) for s in surfaces)
    if not (moved or pulled or gravity):
        raise top.error("displacement", "nothing loads the problem (every prescribed "
                                        "displacement is zero, no traction, no gravity); "
                                        "prescribe a displacement, a traction or gravity")


# ---------------------------------------------------------------- measures


def _measures(top, mesh, selections, dirichlet, scale, unit):
    out = []
    for t in top.tables("measure", "the quantities compared"):
        t.only(*KEYS["measure"])
        name = t.string("name", "the quantity's name: lower-case letters, digits and '_'")
        if not MEASURE_NAME.fullmatch(name):
            raise t.error("name", f"must start with a lower-case letter and hold only "
                                  f"lower-case letters, digits and '_', got {_shown(name)}")
        if any(m.name == name for m in out):
            raise t.error("name", f"{name!r} names an earlier [[measure]] too; give each "
                                  "its own")
        kind = t.string("kind", "what is measured", choices=MEASURE_KINDS)
        m = MEASURES[kind](t, name, mesh, selections, dirichlet, scale, unit)
        t.done()
        out.append(m)
    if not out:
        raise top.error("measure", "no [[measure]]: declare at least one quantity (the first "
                                   "is what the error model decomposes)")
    if not out[0].scalar:
        raise top.error("measure", f"the first [[measure]] ({out[0].name}) is a profile; the "
                                   "first is what the error model decomposes, a single "
                                   "number: put a reaction or a displacement first")
    return out


def _reaction(t, name, mesh, selections, dirichlet, scale, unit):
    sel = _selected(t, "on", selections, "the selection whose reaction is summed")
    axis = t.axis("axis", "the direction of the force")
    if not any(dirichlet.get(int(i), (None,) * 3)[axis] is not None for i in sel.nodes):
        raise t.error("on", f"no node of selection {sel.name!r} has its {AXES[axis]} "
                            "displacement prescribed, so it has no reaction along "
                            f"{AXES[axis]}; measure where a [[displacement]] holds that "
                            "component")
    return Measure(name, "reaction", f"{name}_n", f"the reaction on {sel.name} ({sel.text}, "
                   f"{nodes_said(len(sel.nodes))}) along {AXES[axis]} [N]", axis=axis,
                   nodes=sel.nodes)


def _displacement(t, name, mesh, selections, dirichlet, scale, unit):
    p = t.vector("at", "a point: the node nearest it is measured")
    comp = t.axis("component", "the displacement component measured")
    node = int(np.argmin(np.linalg.norm(mesh.points - p * scale, axis=1)))
    away = np.linalg.norm(mesh.points[node] - p * scale)
    return Measure(name, "displacement", f"{name}_mm", f"u_{AXES[comp]} [mm] at node {node}, "
                   f"{_at(mesh.points[node], scale)} {unit}, the node nearest "
                   f"{_at(p, 1)} {unit} ({away / scale:.3g} {unit} away)",
                   component=comp, node=node)


def _profile(t, name, mesh, selections, dirichlet, scale, unit):
    axis = t.axis("along", "the axis the profile runs along")
    through = t.vector("through", "a point of the line")
    lo, hi = mesh.points[:, axis].min() / scale, mesh.points[:, axis].max() / scale
    start = t.number("from", "where the line starts, along its axis", lo)
    end = t.number("to", "where it ends", hi)
    samples = t.number("samples", "how many points along the line", 11, low=2, integer=True)
    comp = t.axis("component", "the displacement component measured")
    if not start < end:
        raise t.error("to", f"must exceed from ({start:g}), got {end:g}")
    positions = np.linspace(start, end, int(samples)) * scale
    points = np.repeat(through[None] * scale, len(positions), axis=0)
    points[:, axis] = positions
    try:
        located = mesh.locate(points)
    except MeshError:
        raise t.error("through", f"the line leaves the mesh (which spans "
                                 f"{_extent(mesh, scale)}); move it inside: through, from and "
                                 "to place it") from None
    return Measure(name, "profile", f"{name}_mm", f"u_{AXES[comp]} [mm] at {int(samples)} "
                   f"points along {AXES[axis]} from {start:g} to {end:g} {unit} through "
                   f"{_at(through * scale, scale)} {unit} (interpolated in the tetrahedra)",
                   component=comp, axis=axis, located=located, positions=positions)


MEASURES = {"reaction": _reaction, "displacement": _displacement, "profile": _profile}

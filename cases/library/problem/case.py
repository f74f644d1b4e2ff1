"""A user's problem as a :class:`~cases.framework.Case`: :func:`case_of` builds the case of a
checked :class:`~.spec.Spec`, so that the shared runner, the error model, the report and the
gate treat it as they treat the library's cases.

Each problem is a subclass of :class:`ProblemCase` made for its spec (the class attributes a
case declares, its headline and decomposed quantity among them, come from the TOML); its
measured quantities are declared in the metric catalogue under the names the TOML gives. A
problem has one mesh (its file) and one boundary condition (``declared``: everything the TOML
prescribes).
"""
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from scipy.spatial import cKDTree

from model.loads import body_forces
from ...measuring import catalogue
from ...measuring import metrics as M
from ...measuring.catalogue import err_name, ref_name
from ...measuring.error_model import Scalar
from ...framework import AT_LOAD, MM, Case, Loads, Settings
from ...running.runner import reaction_along, reference
from .spec import AXES, ProblemError, load

BC = "declared"
# how many triangles' centroids, nearest first, are tried for a point of a loaded surface
CANDIDATES = 16
CHUNK = 20000            # points tested at once (the candidates' arrays grow with it)


@dataclass
class ProblemSettings(Settings):
    """A problem's settings: what every case has, and the digests of its TOML (as parsed)
    and its mesh file, which define the problem (a gold value was measured at them; the run
    store keys on them)."""

    spec_sha256: str = ""
    mesh_sha256: str = ""

    def problem(self):
        return {**super().problem(), "spec_sha256": self.spec_sha256,
                "mesh_sha256": self.mesh_sha256}


@dataclass(frozen=True, eq=False)
class SurfaceLoads(Loads):
    """The loads of a problem: tractions on sets of boundary triangles (``surfaces``: (node
    ids (k, 3), value [Pa] (3,)) pairs) and a constant body force [N/m^3]. The model receives
    consistent nodal forces; FEM integrates the traction on the facets of its own (refined)
    meshes that lie in those triangles."""

    surfaces: tuple = ()
    points: np.ndarray = None        # the mesh's node coordinates [m] (the triangles' corners)

    def nodal_forces(self, mesh):
        if not self.surfaces and self.body_force is None:
            return None
        f = np.zeros_like(mesh.points)
        for faces, value in self.surfaces:
            p = mesh.points[faces]
            area = 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)
            # a third of traction x area to each vertex: exact for P1 shape functions
            np.add.at(f, faces.ravel(), np.repeat(area / 3, 3)[:, None] * np.asarray(value))
        if self.body_force is not None:
            f += body_forces(mesh, self.body_force)
        return f

    def scaled(self, k):
        return SurfaceLoads(surfaces=tuple((faces, tuple(v * k for v in value))
                                           for faces, value in self.surfaces),
                            points=self.points, body_force=None if self.body_force is None
                            else tuple(v * k for v in self.body_force))

    def fem_traction(self, tol):
        if not self.surfaces:
            return None
        loaded = [(self.points[faces], np.asarray(value)) for faces, value in self.surfaces]

        def traction(points, normals):
            out = np.zeros_like(points)
            for corners, value in loaded:
                out += np.where(on_triangles(points, corners, tol)[..., None], value, 0.0)
            return out
        return traction


def on_triangles(points, corners, tol):
    """bool (...,): which of ``points`` (..., 3) lie on one of the triangles ``corners``
    (k, 3, 3), within ``tol`` of its plane (a facet of a refined mesh lies in a facet of the
    mesh it was refined from)."""
    flat = points.reshape(-1, 3)
    tree = cKDTree(corners.mean(axis=1))
    k = min(CANDIDATES, len(corners))
    out = np.zeros(len(flat), bool)
    for lo in range(0, len(flat), CHUNK):
        p = flat[lo:lo + CHUNK]
        _, near = tree.query(p, k=k)
        c = corners[near.reshape(len(p), -1)]                      # (n, k, 3, 3)
        e1, e2, d = c[..., 1, :] - c[..., 0, :], c[..., 2, :] - c[..., 0, :], \
            p[:, None] - c[..., 0, :]
        normal = np.cross(e1, e2)
        off = np.abs(np.einsum("nkj,nkj->nk", d, normal)) / np.linalg.norm(normal, axis=-1)
        d00, d01, d11 = (np.einsum("nkj,nkj->nk", a, b) for a, b in ((e1, e1), (e1, e2),
                                                                     (e2, e2)))
        d20, d21 = np.einsum("nkj,nkj->nk", d, e1), np.einsum("nkj,nkj->nk", d, e2)
        den = d00 * d11 - d01 ** 2
        v, w = (d11 * d20 - d01 * d21) / den, (d00 * d21 - d01 * d20) / den
        inside = (off <= tol) & (np.minimum(np.minimum(v, w), 1 - v - w) >= -1e-9)
        out[lo:lo + CHUNK] = inside.any(axis=1)
    return out.reshape(points.shape[:-1])


class ProblemCase(Case):
    """The case of a user's problem; :func:`case_of` makes the subclass of one spec."""

    name = "problem"
    title = "A user's problem"
    spec: ClassVar[object] = None
    settings_class = ProblemSettings
    meshes = quick_meshes = ("mesh",)
    bcs = (BC,)
    quick = {"p2_levels": 1}
    narrative = "cases.library.problem.narrative:ProblemNarrative"

    def __reduce__(self):
        """Pickled as the TOML it was read from (a worker process reads it again)."""
        return (_rebuilt, (str(self.spec.path),))

    # ------------------------------------------------------------------ settings
    def settings(self, quick=False, **kw):
        """The TOML's material and references, then ``quick``'s overrides, then ``kw``."""
        spec = self.spec
        own = {"E": spec.material.E, "nu": spec.material.nu, "rho": spec.material.rho,
               "nh_levels": spec.nh_levels, **spec.digests}
        if not quick:
            own["p2_levels"] = spec.p2_levels
        return super().settings(quick, **{**own, **{k: v for k, v in kw.items()
                                                    if v is not None}})

    # ------------------------------------------------------------------ declaration
    def mesh(self, family, s):
        return self.spec.mesh

    def dirichlet(self, mesh, bc, s):
        return dict(self.spec.dirichlet)

    def loads(self, mesh, bc, s):
        spec = self.spec
        gravity = None
        if spec.gravity:
            gravity = tuple(-s.rho * spec.gravity * (k == spec.up) for k in range(3))
        return SurfaceLoads(surfaces=tuple((f.faces, f.value) for f in spec.surfaces),
                            points=mesh.points, body_force=gravity)

    def driven(self, mesh, bc, s):
        first = next((m for m in self.spec.measures if m.kind == "reaction"), None)
        return None if first is None else (first.nodes, first.axis)

    def quantities(self, mesh, u, reaction, s, bc):
        return {m.key: measured(m, mesh, u, reaction) for m in self.spec.measures}

    def quantity_metrics(self, q, ref_q, bc):
        return {err_name(m.key): M.rel_l2(np.asarray(q[m.key]), np.asarray(ref_q[m.key]))
                for m in self.spec.measures if not m.scalar}

    def params(self, s):
        spec = self.spec
        return {**s.problem(), "mesh_file": spec.mesh_file.name, "unit": spec.unit,
                "up": AXES[spec.up], "gravity_m_s2": spec.gravity,
                "nodes": spec.mesh.n_nodes, "tets": spec.mesh.n_tets}

    # ------------------------------------------------------------------ phases
    def solve_reference(self, mesh, bc, s, probe):
        """The default references, the neo-Hookean one at the load only where the TOML asks
        for it."""
        full = not s.static_only
        return reference(self, mesh, bc, s, probe, extra=full,
                         nonlinear=full and self.spec.neohookean)

    def solve_static(self, pm, mesh, bc, s, ref):
        """The model at the load only where a reference there judges it."""
        return super().solve_static(pm, mesh, bc, s, ref) if self.spec.neohookean else None


def measured(m, mesh, u, reaction):
    """The value of measure ``m`` for a displacement ``u`` (n, 3) [m] and reaction (n, 3)."""
    if m.kind == "reaction":
        return float(reaction_along(reaction, (m.nodes, m.axis)))
    if m.kind == "displacement":
        return float(u[m.node, m.component] / MM)
    return (mesh.interpolate(u, m.located)[:, m.component] / MM).tolist()


def declare(spec):
    """Declare the spec's measured quantities in the metric catalogue (their FEM twins and
    errors follow), or a ProblemError naming a measure whose names the suite's metrics hold
    with another meaning."""
    for i, m in enumerate(spec.measures, 1):
        wanted = _metrics(m)
        for name, metric in wanted.items():
            if catalogue.known(name) and catalogue.metric(name) != metric:
                raise ProblemError(f"{spec.path.name}: measure[{i}].name: {m.name!r} gives the "
                                   f"run key {name}, a metric of the suite with another "
                                   "meaning; rename the measure")
        # a scalar's FEM twin and error derive from its declaration; a profile's error is
        # a relative L2 error, declared as such
        for metric in [wanted[m.key]] + ([] if m.scalar else [wanted[err_name(m.key)]]):
            catalogue.declare(metric.name, metric.unit, metric.label, metric.definition,
                              metric.direction, metric.shown, metric.digits)


# what each kind of measure means, in the catalogue's words (the same text for every problem:
# two problems may measure under one name in one process)
MEANING = {"reaction": ("N", ("mN", 1e3), 4, "the reaction on a selection of the problem's "
                        "nodes along an axis, signed as reaction_n (minus the summed force of "
                        "the supports: a face pushed along -z reads positive along z; its "
                        "[[measure]] of that name)"),
           "displacement": ("mm", None, 4, "a displacement component at the node nearest a "
                            "point of the problem (its [[measure]] of that name)"),
           "profile": ("mm", None, 3, "a displacement component at points along a line of "
                       "the problem, interpolated in its tetrahedra (its [[measure]] of that "
                       "name)")}


def _metrics(m):
    """{run key: Metric} that measure ``m`` brings: its value, its FEM twin and its error."""
    unit, shown, digits, meaning = MEANING[m.kind]
    value = catalogue.Metric(m.key, unit, m.name, meaning + ".", None, shown, digits)
    twin = catalogue.Metric(ref_name(m.key), unit, f"FEM {m.name}",
                            f"the {m.name} of the FEM reference's solution.", None, shown,
                            digits)
    error = (catalogue.Metric(err_name(m.key), "1", f"{m.name} err",
                              f"|model / FEM - 1| of the {m.name}.", "max") if m.scalar else
             catalogue.Metric(err_name(m.key), "1", f"{m.name} err",
                              f"relative L2 error of the profile {m.name} against FEM P2.",
                              "max"))
    return {m.key: value, twin.name: twin, error.name: error}


def case_of(spec):
    """The case of the checked ``spec`` (its quantities declared in the catalogue)."""
    declare(spec)
    first = spec.measures[0]
    scalars = [m.key for m in spec.measures if m.scalar]
    profiles = [err_name(m.key) for m in spec.measures if not m.scalar]
    reaction = any(m.kind == "reaction" for m in spec.measures)
    attrs = {
        "name": spec.name, "spec": spec, "models": spec.models,
        "meshes": (_mesh_name(spec),), "quick_meshes": (_mesh_name(spec),),
        "title": spec.title or (f"The problem {spec.name}: {spec.mesh_file.name} under the "
                                f"boundary conditions of {spec.path.name}"),
        "headline": err_name(first.key),
        # the other side of the answer: the field beside a reaction, the force beside a
        # displacement (where one is measured)
        "headline_pair": ("reaction_rel_err" if first.kind != "reaction" and reaction
                          else "disp_rel_l2_p2"),
        "decomposed": Scalar(first.key, ref_name(first.key), first.name),
        "decomposed_at_load": AT_LOAD if spec.neohookean else None,
        "qoi_errors": tuple(scalars),
        "quantity_compared": tuple(profiles),
        "gated": tuple(err_name(k) for k in scalars) + tuple(profiles),
        "columns": tuple(c for k in scalars for c in (k, ref_name(k), err_name(k)))
        + tuple(profiles)}
    return type(f"Problem_{spec.name.replace('-', '_')}", (ProblemCase,), attrs)()


def _mesh_name(spec):
    """The mesh's name in the runs: its file's stem, in the characters a file name takes."""
    stem = "".join(c if c.isalnum() or c in "-_" else "-" for c in spec.mesh_file.stem)
    return stem or "mesh"


def _rebuilt(path):
    return case_of(load(path))

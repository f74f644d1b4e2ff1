"""The commented template of a problem's TOML (``pbcm problem new``): every key explained,
and as written it runs on the example mesh that ships with pbcm (examples/cylinder), a
uniaxial compression between sliding ends whose answer is known in closed form."""
from pathlib import Path

# the worked example: examples/cylinder of a checkout (its make_mesh.py writes the mesh)
EXAMPLE_MESH = Path(__file__).resolve().parents[3] / "examples" / "cylinder" / "cylinder.msh"

TEMPLATE = '''\
# A pbcm problem: how far is the particle model from FEM on this mesh, under these boundary
# conditions? Run it with
#
#     pbcm run --problem {file} [--quick] [--models NAME ...] [--out DIR]
#
# It writes reports/problems/NAME (report.md, metrics.json, figures, a copy of this file);
# `pbcm bless --metrics reports/problems/NAME --gold DIR` then keeps its values as gold, and
# `pbcm check --metrics reports/problems/NAME --gold DIR` gates later runs on them.
#
# Units: lengths (coordinates, displacements) in the mesh's unit, [mesh] unit; forces in N,
# tractions in Pa, gravity in m/s^2. As written, this file compresses the example cylinder
# (radius 10 mm, height 20 mm, axis z, standing on z = 0) by 1 % between ends that slide:
# the strain is uniform, so the end force is E A strain and the bulge nu strain r exactly.

# name: the problem's name, the case name in metrics.json and the output folder
# reports/problems/NAME; lower-case letters, digits, '-' and '_', no library case's name.
name = "{name}"
# title: one line on what the problem is, for the report (optional).
title = "A cylinder compressed 1 % between sliding ends"
# models: the models run, presets or terms composed with '+' (`pbcm list` names the
# presets); optional, every preset when left out; --models on the command line overrides it.
# models = ["pbcm-variational", "msm", "fem-linear"]
# gravity: the acceleration of gravity [m/s^2], acting along -up (optional, default 0:
# none), e.g. 9.81 for self-weight.
gravity = 0.0

# [mesh]: the body.
[mesh]
# file: the mesh file, any format meshio reads (.msh, .vtu, .vtk, .inp, ...), its path
# relative to this file; its tetrahedra are the body (other cells only name sets, see
# [select]).
file = "{mesh}"
# unit: the length unit of its coordinates, m, cm, mm, um or in.
unit = "mm"
# up: the vertical axis, x, y or z: gravity acts along -up, the report's figures stand on it.
up = "z"

# [material]: a linear elastic (and, at the load, neo-Hookean) solid.
[material]
E = 10e3        # Young's modulus [Pa]
nu = 0.45       # Poisson's ratio, -1 < nu < 0.5
rho = 1000.0    # density [kg/m^3] (what gravity pulls)

# [select]: named sets of nodes that the conditions and measures below refer to. Each is
# one of
#   a plane: {{ axis = "z", at = 0.0, tolerance = 0.01 }}, the nodes within tolerance of the
#            plane (tolerance optional: a millionth of the mesh's diagonal);
#   a box:   {{ min = [x, y, z], max = [x, y, z] }}, the nodes inside it (bounds included);
#   a set:   {{ set = "top" }}, a named set of the mesh file: a point set, a cell set or a Gmsh
#            physical group (the nodes of its cells);
#   a node:  {{ nearest = [x, y, z] }}, the node nearest the point (the report names it).
# A selection that selects no node is an error.
[select]
bottom = {{ axis = "z", at = 0.0 }}
top = {{ set = "top" }}
centre = {{ min = [-0.1, -0.1, -0.1], max = [0.1, 0.1, 0.1] }}
rim = {{ nearest = [10.0, 0.0, 0.0] }}

# [[displacement]]: prescribed displacements, one per selection ("on"), either
#   value = [ux, uy, uz] in the mesh's unit, with components = the ones prescribed (optional,
#           all three by default; the others stay free), or
#   fixed = the components held at zero.
# A node in two selections takes the components of both (two values of one component are an
# error), and together they must hold every rigid motion.
[[displacement]]        # the top pushed 0.2 mm down (1 % strain), free to slide sideways
on = "top"
value = [0.0, 0.0, -0.2]
components = ["z"]

[[displacement]]        # the bottom held along the axis, free to slide sideways
on = "bottom"
fixed = ["z"]

[[displacement]]        # the centre of the bottom held sideways: no translation
on = "centre"
fixed = ["x", "y"]

[[displacement]]        # a node of the bottom's rim held in y: no rotation about the axis
on = "rim"
fixed = ["y"]

# [[traction]] (optional): a uniform force per area [Pa], value = [tx, ty, tz], on the boundary
# triangles whose three nodes are in the selection "on"; the model receives it as consistent
# nodal forces, FEM integrates it. For example, a shear on the top instead of its push:
# [[traction]]
# on = "top"
# value = [10.0, 0.0, 0.0]

# [[measure]]: what is measured, each a quantity of every run, compared with FEM. The FIRST
# is the one the error model splits into model-form and discretisation error, and the
# report's headline: a single number, so a reaction or a displacement. name: lower-case
# letters, digits and '_' (the run key is NAME_n for a force, NAME_mm for a displacement);
# kind: what is measured, one of the three below.
# kind = "reaction": on = a selection, axis = x, y or z; the reaction at its nodes along the
#   axis [N], the force they exert on their supports (a face pushed along -z reads positive
#   along z); the selection must have that component prescribed.
[[measure]]
name = "end_force"
kind = "reaction"
on = "top"
axis = "z"

# kind = "displacement": at = [x, y, z], component = x, y or z; the displacement of the node
#   nearest the point [mm] (the report names the node and its distance).
[[measure]]
name = "bulge"
kind = "displacement"
at = [10.0, 0.0, 10.0]
component = "x"

# kind = "profile": along = x, y or z, through = [x, y, z] a point of the line, from and to
#   its ends along that axis (optional: the mesh's extent), samples = how many points
#   (optional, 11), component; the displacement interpolated at those points [mm], compared
#   by its relative L2 error.
[[measure]]
name = "axial"
kind = "profile"
along = "z"
through = [0.0, 0.0, 0.0]
samples = 11
component = "z"

# [references] (optional): linear FEM P1 on the mesh and converged P2 always;
#   neohookean = true adds the converged neo-Hookean reference at the load as declared (the
#     finite-strain answer), and each model solved there;
#   p2_levels = uniform refinements of the P2 reference (default 2; --quick: 1);
#   nh_levels = those of the neo-Hookean reference (default 1).
[references]
neohookean = false
p2_levels = 2
nh_levels = 1
'''


def template(name, mesh, file=None):
    """The template's text for a problem ``name`` whose mesh file is ``mesh`` (a path
    relative to the TOML, or absolute) and which is saved as ``file``."""
    return TEMPLATE.format(name=name, mesh=Path(mesh).as_posix(),
                           file=file or f"{name}.toml")

"""Writes ``_shear_kernels.py``: the shear kernels with their 24 combinations written out.

Why generated: in a loop over a combination table the edges, lengths and accumulators live in
arrays that numba cannot keep in registers (it cannot prove they do not alias ``x`` and
``out``), and the variational kernel cost 210 ns per tetrahedron; written out, every quantity
is a named scalar and it costs 60 (``pbcm bench``). This file holds the maths once, per
combination, and the generated file is what runs. After editing this file or the helpers in
``_kernels.py`` or ``_blocks.py`` run ``python model/terms/_shear_codegen.py``;
tests/test_terms.py fails while the generated file is stale (and its changed text makes numba
recompile the cached kernels).

The force kernels run over blocks of tetrahedra (``_blocks.py``): ``blocked`` writes each
reading's block function, its serial driver and its threaded twin; ``reference`` writes the
same maths tetrahedron by tetrahedron as ``*_reference``, the kernels the tests hold them to.

Notation of the generated code, for the tetrahedron's corners 0..3:

* ``d01 = x1 - x0`` the six edges (p < q), ``l01 = |d01|^2``, ``iL01 = 1 / |d01|``;
* ``c0..c3`` the doubled face vectors, ``c_j = d(6V)/dx_j``, ``cn_j = |c_j| = 2 S_j``,
  ``V6 = 6V``, ``h_j = cn_j / V6`` = 1 / (height of tip j over its face);
* combination (a, j, m) (corner a, tip j, in-plane edge a -> m) has
  ``D = d_aj . d_am = (l_aj + l_am - l_jm) / 2`` and
  ``gamma = D / L_am * h_j - gamma0`` (the paper's eq. 4, as in shear.py).
"""
import hashlib
import re
import importlib.util
import pathlib

HERE = pathlib.Path(__file__).parent
if __package__:
    from ._kernels import COMBOS, FACE
else:   # run as a script, without importing the package (whose import needs the output)
    _spec = importlib.util.spec_from_file_location("_kernels", HERE / "_kernels.py")
    _kernels = importlib.util.module_from_spec(_spec)
    _spec.loader.exec_module(_kernels)
    COMBOS, FACE = _kernels.COMBOS, _kernels.FACE
TARGET = HERE / "_shear_kernels.py"
PAIRS = [(p, q) for p in range(4) for q in range(p + 1, 4)]


def e(p, q):
    """The name suffix of edge {p, q}."""
    return f"{min(p, q)}{max(p, q)}"


def frame(check):
    """Per tetrahedron: corners, edges, squared and reciprocal lengths, face vectors, 6V,
    reciprocal heights; ``check`` is the flattening test (a string of code, or None). The
    reciprocal lengths and the face norms are markers, written by each variant (``SERIAL``:
    the double-precision root; ``BLOCK``: :func:`model.terms._blocks.rsqrt`)."""
    lines = ["n0, n1, n2, n3 = tets[t, 0], tets[t, 1], tets[t, 2], tets[t, 3]",
             "x0, x1, x2, x3 = vec(x, n0), vec(x, n1), vec(x, n2), vec(x, n3)"]
    for p, q in PAIRS:
        lines += [f"d{p}{q} = sub(x{q}, x{p})", f"l{p}{q} = dot(d{p}{q}, d{p}{q})",
                  f"{INVERSE_LENGTH}{p}{q}"]
    for j in range(4):
        a, m, l = FACE[j]
        lines += [f"c{j} = cross(d{e(a, m)}, d{e(a, l)})", f"{FACE_NORM}{j}"]
    lines += ["V6 = dot(d01, c1)", f"if {check}:", FLATTENED_ACTION, "iV6 = 1.0 / V6"]
    lines += [f"h{j} = cn{j} * iV6" for j in range(4)]
    return lines


def strain(s, a, j, m):
    """D and gamma of combination s = (a, j, m)."""
    return [f"# combination {s}: corner {a}, tip {j}, edge {a} -> {m}",
            f"D = 0.5 * (l{e(a, j)} + l{e(a, m)} - l{e(j, m)})",
            f"gamma = D * iL{e(a, m)} * h{j} - gamma0[t, {s}]"]


def strains():
    body = []
    for s, (a, j, m, _) in enumerate(COMBOS):
        body += strain(s, a, j, m) + [f"gamma_out[t, {s}] = gamma"]
    return ("shear_strains", "x, tets, gamma0, gamma_out",
            "The 24 strains of every tetrahedron into gamma_out (m, 24); returns the first "
            "flattened tetrahedron (6V <= 0), or -1.", [], frame("V6 <= 0.0") + body)


def edge_forces(coef):
    """f_p += k_pq d_pq, f_q += k_qp d_qp for the ordered edge coefficients ``coef(p, q)``."""
    lines = [f"f{i} = (0.0, 0.0, 0.0)" for i in range(4)]
    for p, q in PAIRS:
        lines += [f"f{p} = axpy({coef(p, q)}, d{p}{q}, f{p})",
                  f"f{q} = axpy(-({coef(q, p)}), d{p}{q}, f{q})"]
    return lines


FLATTENED = "V6 <= FLAT * 6.0 * vol0[t]"
# what the serial and the per-tetrahedron (threaded) variants do at these two places
FLATTENED_ACTION, SCATTER, VOLUME = "@flattened@", "@scatter@", "@volume@"
INVERSE_LENGTH, FACE_NORM = "@inverse_length@", "@face_norm@"
SERIAL = {**{f"{FACE_NORM}{j}": [f"cn{j} = np.sqrt(dot(c{j}, c{j}))"] for j in range(4)},
          FLATTENED_ACTION: ["    return t"],
          VOLUME: [],
          SCATTER: [f"add_to(out, n{i}, f{i})" for i in range(4)],
          **{f"{INVERSE_LENGTH}{p}{q}": [f"iL{p}{q} = 1.0 / np.sqrt(l{p}{q})"] for p, q in PAIRS}}
# in a block (model/terms/_blocks.py): the corners from the scratch array, the flattening
# margin kept and counted (the lane goes on: its forces are never added), the forces stored
BLOCK = {"n0, n1, n2, n3 = tets[t, 0], tets[t, 1], tets[t, 2], tets[t, 3]": [],
         "x0, x1, x2, x3 = vec(x, n0), vec(x, n1), vec(x, n2), vec(x, n3)":
         [f"x{c} = (s[{3 * c} * B + i], s[{3 * c + 1} * B + i], s[{3 * c + 2} * B + i])"
          for c in range(4)] + ["@rest_frame@"],
         f"if {FLATTENED}:": ["margin = V6 - FLAT * 6.0 * vol0[t]", "s[FLAG + i] = margin",
                              "n_flat += margin <= 0.0"],
         FLATTENED_ACTION: [],
         # the volume term's pressure forces p dV/dx_j = p c_j / 6, p = -K (V - V0) / V, in
         # the same pass (K = 0 where the model has no volume term): c_j and 6V are the
         # shear's own, and a second gather and scatter is saved
         VOLUME: ["p6 = K6 * (V6 - 6.0 * vol0[t]) * iV6"]
         + [f"f{j} = axpy(p6, c{j}, f{j})" for j in range(4)],
         SCATTER: [f"s[OUT + {3 * c + k} * B + i] = f{c}[{k}]"
                   for c in range(4) for k in range(3)],
         **{f"{INVERSE_LENGTH}{p}{q}": [f"iL{p}{q} = rsqrt(l{p}{q})"] for p, q in PAIRS},
         **{f"{FACE_NORM}{j}": [f"cc{j} = dot(c{j}, c{j})", f"cn{j} = cc{j} * rsqrt(cc{j})"]
            for j in range(4)}}


def corner():
    """f_a += (1/4) tau S_F e = K_am d_am with K_am = G gamma cn_j / (8 L_am), summed over
    the two tips j of each ordered edge a -> m."""
    init = [f"K{a}{m} = 0.0" for a in range(4) for m in range(4) if a != m]
    body = []
    for s, (a, j, m, _) in enumerate(COMBOS):
        body += strain(s, a, j, m)
        body += [f"K{a}{m} += G8 * gamma * cn{j} * iL{e(a, m)}"]
    return ("shear_corner", "x, tets, vol0, gamma0, G, out",
            "Literal eq. 5: f_a += (1/4) tau S_F e, tau = G gamma, S_F = cn_j / 2, "
            "e = d_am / L_am; returns the first flattened tetrahedron, or -1.",
            ["G8 = 0.125 * G"], frame(FLATTENED) + init + body
            + edge_forces(lambda p, q: f"K{p}{q}") + [VOLUME, SCATTER])


def balanced():
    """f_j -= w d_am on the tip, + w d_am / 3 on each of a, m, l (w = tau S_F / L_am): with
    U_i = sum over the combinations of tip i of w d_am and T = sum_i U_i,
    f_i = T / 3 - (4/3) U_i. U_j collects the edges p < q of the face opposite j."""
    init = [f"B{j}_{e(p, q)} = 0.0" for j in range(4) for p, q in PAIRS if j not in (p, q)]
    body = []
    for s, (a, j, m, _) in enumerate(COMBOS):
        sign = "+=" if a < m else "-="       # d_am = -d_ma
        body += strain(s, a, j, m)
        body += [f"B{j}_{e(a, m)} {sign} G2 * gamma * cn{j} * iL{e(a, m)}"]
    forces = []
    for j in range(4):
        u = "(0.0, 0.0, 0.0)"
        for p, q in PAIRS:
            if j not in (p, q):
                u = f"axpy(B{j}_{p}{q}, d{p}{q}, {u})"
        forces.append(f"U{j} = {u}")
    forces.append("T = (U0[0] + U1[0] + U2[0] + U3[0], U0[1] + U1[1] + U2[1] + U3[1], "
                  "U0[2] + U1[2] + U2[2] + U3[2])")
    forces += [f"f{i} = lin(1.0 / 3.0, T, -4.0 / 3.0, U{i})" for i in range(4)]
    return ("shear_balanced", "x, tets, vol0, gamma0, G, out",
            "f_j -= tau S_F e on the tip, + tau S_F e / 3 on each base vertex a, m, l; returns "
            "the first flattened tetrahedron, or -1.",
            ["G2 = 0.5 * G"], frame(FLATTENED) + init + body + forces + [VOLUME, SCATTER])


def variational():
    """f = -dW/dx, W = (c/2) G V0 sum_s gamma_s^2 (cG = c G). W depends on x through the six
    squared lengths l, the four face norms cn_j and 6V; cn_j^2 = l_am l_al - D_j^2 is itself a
    function of its face's l, so

        f = -sum_edges 2 dW/dl_pq (d_pq at q, -d_pq at p) - dW/d(6V) c_j.

    Per combination, with g = h_j / L_am, E = w g / 2 (w = cG V0 gamma) and P = E D:
    dW/dl_aj += E, dW/dl_jm -= E, dW/dl_am += E - P / l_am, dW/dcn_j += 2 P / cn_j,
    dW/d(6V) -= 2 P / (6V)."""
    init = [f"W{p}{q} = 0.0" for p, q in PAIRS] + [f"P{j} = 0.0" for j in range(4)]
    body = ["half = 0.5 * cG * vol0[t]"]
    for s, (a, j, m, _) in enumerate(COMBOS):
        am = e(a, m)
        body += strain(s, a, j, m)
        body += [f"E = half * gamma * iL{am} * h{j}", "P = E * D",
                 f"W{e(a, j)} += E", f"W{e(j, m)} -= E",
                 f"W{am} += E - P * iL{am} * iL{am}", f"P{j} += P"]
    faces = []
    for j in range(4):
        a, m, l = FACE[j]
        # dcn/dl_am = (l_al - D) / (2 cn), dcn/dl_al = (l_am - D) / (2 cn), dcn/dl_ml = D / (2 cn)
        faces += [f"b = P{j} / (cn{j} * cn{j})",
                  f"D = 0.5 * (l{e(a, m)} + l{e(a, l)} - l{e(m, l)})",
                  f"W{e(a, m)} += b * (l{e(a, l)} - D)", f"W{e(a, l)} += b * (l{e(a, m)} - D)",
                  f"W{e(m, l)} += b * D"]
    forces = ["A = 2.0 * (P0 + P1 + P2 + P3) * iV6"]        # -dW/d(6V)
    forces += edge_forces(lambda p, q: f"2.0 * W{e(p, q)}")   # l_pq is symmetric
    forces += [f"f{j} = axpy(A, c{j}, f{j})" for j in range(4)]
    return ("shear_variational", "x, tets, vol0, gamma0, cG, out",
            "f = -dW/dx, W = (c/2) G V0 sum_s gamma_s^2 (cG = c G); returns the first "
            "flattened tetrahedron, or -1.",
            [], frame(FLATTENED) + init + body + faces + forces + [VOLUME, SCATTER])


def expand(lines, variant):
    return [new for line in lines for new in
            ([line[:len(line) - len(line.lstrip())] + n for n in variant[line.strip()]]
             if line.strip() in variant else [line])]


def reference(name, args, doc, before, per_tet):
    """The tetrahedron-by-tetrahedron kernel ``name_reference``: each tetrahedron's forces
    added into ``out`` as they are computed. What the blocked kernels are tested against."""
    return strains_function(f"{name}_reference", args,
                            f"{doc} Tetrahedron by tetrahedron (the reference of ``{name}``).",
                            before, per_tet)


def rest_frame():
    """The rest shape's reciprocal lengths and reciprocal heights of one lane, from its six
    rest squared lengths ``z01 .. z23`` (what a block streams instead of 24 rest strains: a
    quarter of the bytes): 36 V0^2 is the Gram determinant of the edges at corner 0, and a
    face's doubled area follows from its lengths, |u x w|^2 = |u|^2 |w|^2 - (u . w)^2."""
    lines = [f"z{p}{q} = r0[{k} * B + i]" for k, (p, q) in enumerate(PAIRS)]
    lines += [f"iZ{p}{q} = rsqrt(z{p}{q})" for p, q in PAIRS]
    gram = {(p, q): f"0.5 * (z0{p} + z0{q} - z{p}{q})" for p, q in ((1, 2), (1, 3), (2, 3))}
    lines += [f"G{p}{q} = {g}" for (p, q), g in gram.items()]
    lines += ["Vz = z01 * (z02 * z03 - G23 * G23) - G12 * (G12 * z03 - G23 * G13)"
              " + G13 * (G12 * G23 - z02 * G13)", "iVz6 = rsqrt(Vz)"]
    for j in range(4):
        a, m, l = FACE[j]
        lines += [f"Ez = 0.5 * (z{e(a, m)} + z{e(a, l)} - z{e(m, l)})",
                  f"ccz{j} = z{e(a, m)} * z{e(a, l)} - Ez * Ez",
                  f"hz{j} = ccz{j} * rsqrt(ccz{j}) * iVz6"]
    return lines


def rest_strain(s):
    """gamma0 of combination s from the lane's rest frame (:func:`rest_frame`)."""
    a, j, m, _ = COMBOS[int(s)]
    return (f"0.5 * (z{e(a, j)} + z{e(a, m)} - z{e(j, m)}) * iZ{e(a, m)} * hz{j}")


def in_block(line):
    """A line of the per-tetrahedron maths as it reads lane i of block blk (_blocks.py)."""
    line = re.sub(r"gamma0\[t, (\d+)\]", lambda g: f"({rest_strain(g.group(1))})", line)
    return line.replace("vol0[t]", "v0[i]")


def blocked(name, args, doc, before, per_tet):
    """The kernel ``name`` over blocks of tetrahedra (model/terms/_blocks.py): ``name_block``
    computes one block's lanes (what the compiler vectorises), with the volume term's forces
    for its factor ``K`` (0: none), ``name`` gathers, computes and adds into ``out`` block by
    block, and ``name_range`` is its twin for the threaded mode (the blocks [first, stop),
    scattered with ``scatter_routed``; model.terms._threads.SplitBlocks). Per-tetrahedron
    data are in the blocked layout."""
    pad = " " * 8
    # the block streams the rest squared lengths (m, 6) in place of gamma0 (m, 24)
    data = args[len("x, tets, "):-len(", out")].replace("gamma0", "rest") + ", K"
    lane = [in_block(x) for x in expand(expand(per_tet, BLOCK), {"@rest_frame@": rest_frame()})]
    compute = "\n".join(
        ["", "", "", "@njit(**OPTIONS)", f"def {name}_block(s, blk, {data}):",
         f'    """{name} on the lanes of block blk: positions from s, forces and flattening '
         'margins into s; returns the count of flattened lanes."""']
        + [f"    {line}" for line in before]
        # the block's own slices: an index the compiler sees is never negative (so no
        # wraparound select, and SIMD loads rather than gathers)
        + ["    K6 = -K / 6.0", "    r0 = rest[blk * 6 * B:(blk + 1) * 6 * B]",
           "    v0 = vol0[blk * B:(blk + 1) * B]", "    n_flat = 0", "    for i in range(B):"]
        + [pad + x for x in lane] + ["    return n_flat"])
    serial = "\n".join(
        ["", "", "", "@njit(**OPTIONS)", f"def {name}(x, tb, m, {data}, out):",
         f'    """{doc} With the volume term\'s forces for K > 0."""',
         "    s = np.empty(SCRATCH)",
         "    nb = (m + B - 1) // B",
         "    for blk in range(nb):",
         "        ahead(tb, blk, nb)",
         "        ahead(vol0, blk, nb)",
         "        ahead(rest, blk, nb)",
         "        gather(x, tb, blk, s)",
         f"        if {name}_block(s, blk, {data}) > 0:",
         "            return first_flat(s, blk, m)",
         "        scatter(out, tb, blk, m, s)",
         "    return -1"])
    twin = "\n".join(
        ["", "", "", "@njit(**OPTIONS)",
         f"def {name}_range(x, tb, m, {data}, first, stop, late, route, buf, out):",
         f'    """{name} over the blocks [first, stop), the forces of routed corners into '
         'buf."""',
         "    s = np.empty(SCRATCH)",
         "    nb = (m + B - 1) // B",
         "    for blk in range(first, stop):",
         "        ahead(tb, blk, nb)",
         "        ahead(vol0, blk, nb)",
         "        ahead(rest, blk, nb)",
         "        gather(x, tb, blk, s)",
         f"        if {name}_block(s, blk, {data}) > 0:",
         "            return first_flat(s, blk, m)",
         "        if late[blk]:",
         "            scatter_routed(out, tb, blk, m, s, route, buf)",
         "        else:",
         "            scatter(out, tb, blk, m, s)",
         "    return -1"])
    return compute + serial + twin


def strains_function(name, args, doc, before, per_tet):
    """A kernel ``name`` that runs ``per_tet`` tetrahedron by tetrahedron: the strains
    (calibration and stresses) and each reading's reference forces."""
    pad = " " * 8
    return "\n".join(
        ["", "", "", "@njit(cache=True, fastmath=FAST)", f"def {name}({args}):",
         f'    """{doc}"""']
        + [f"    {line}" for line in before]
        + ["    for t in range(tets.shape[0]):"] + [pad + x for x in expand(per_tet, SERIAL)]
        + ["    return -1"])


def source():
    """The text of ``_shear_kernels.py``."""
    helpers = hashlib.sha256((HERE / "_kernels.py").read_bytes()).hexdigest()[:16]
    blocks = hashlib.sha256((HERE / "_blocks.py").read_bytes()).hexdigest()[:16]
    head = ['"""GENERATED by model/terms/_shear_codegen.py: do not edit (see its docstring).',
            "", "Each reading's derivation is in the docstring of its writer there.", "",
            f"_kernels.py sha256 {helpers}", f"_blocks.py sha256 {blocks}", '"""',
            "import numpy as np", "from numba import njit", "",
            "from ._blocks import (B, FLAG, OPTIONS, OUT, SCRATCH, ahead, first_flat, gather, rsqrt,",
            "                      scatter, scatter_routed)",
            "from ._kernels import add_to, axpy, cross, dot, lin, sub, vec",
            "from .volume import FLAT", "",
            "# fast maths without reassociation: the serial and the per-tetrahedron twins then",
            "# round the same way (the two-thread mode's bit-for-bit promise)",
            'FAST = {"nnan", "ninf", "nsz", "arcp", "contract", "afn"}']
    forces = (corner(), balanced(), variational())
    return "\n".join(head) + strains_function(*strains()) \
        + "".join(blocked(*f) for f in forces) + "".join(reference(*f) for f in forces) + "\n"


if __name__ == "__main__":
    TARGET.write_text(source())
    print(f"wrote {TARGET}")

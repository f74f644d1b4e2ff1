"""The blocked force kernels (model/terms/_blocks.py) against the tetrahedron-by-tetrahedron
kernels they replaced, kept as each term's ``reference_kernel()``: the same forces to round-off
on lattice and unstructured meshes at random deformations, the threaded mode the same bits
as the serial kernel for any number of shares, the shear and volume terms fused into one pass
the same forces as the two, and the same first flattened element."""
import numba
import numpy as np
import pytest

from model import Material
from model.terms import make_term
from model.terms._blocks import B, blocked
from model.mesh import cube

from conftest import perturbed

MAT = Material(E=10e3, nu=0.45, rho=1000.0)
# every term whose kernel has a reference, with its parameters (c fixed: no calibration)
TERMS = {
    "corner": ("shear", {"reading": "corner", "c": 0.4}),
    "balanced": ("shear", {"reading": "balanced", "c": 0.6}),
    "variational": ("shear", {"reading": "variational", "c": 0.3}),
    "normal_edge": ("normal_edge", {"c": 0.7}),
    "fem_corotated": ("fem_corotated", {}),
    "fem_linear": ("fem_linear", {}),
    "fem_neohookean": ("fem_neohookean", {}),
    "springs": ("springs", {}),
}
# the terms whose kernel reports an edge of zero length rather than a flattened tetrahedron
COLLAPSED_EDGE = {"normal_edge", "springs"}
# lattice and unstructured meshes; sizes not a multiple of the block (a padded last block)
MESHES = {"five": lambda: cube(6, 0.03, "five"), "six": lambda: cube(5, 0.02, "six"),
          "bcc": lambda: cube(4, 0.03, "bcc"),
          "unstructured": lambda: cube(5, 0.03, "unstructured", seed=2)}
_meshes = {}


def mesh_of(name):
    if name not in _meshes:
        _meshes[name] = MESHES[name]()
    return _meshes[name]


def forces(kernel, x, start):
    fn, args = kernel
    out = start.copy()
    assert fn(x, *args, out) == -1
    return out


def test_meshes_have_a_padded_last_block():
    """At least one test mesh has a tetrahedron count that is not a multiple of the block size B, so
    the kernels are compared on a padded last block."""
    assert any(mesh_of(name).n_tets % B for name in MESHES)


def test_rsqrt_is_the_reciprocal_root_to_round_off():
    """The kernels' rsqrt times sqrt(a) equals 1 to within 4 machine epsilons for a from about 1e-37
    to 1e38 and for random values between 0.5 and 2."""
    from numba import njit
    from model.terms._blocks import rsqrt

    @njit
    def all_of(a):
        return np.array([rsqrt(v) for v in a])

    a = np.concatenate([np.logspace(-36.9, 37.9, 20001),
                        np.random.default_rng(0).uniform(0.5, 2.0, 1000)])
    assert np.abs(all_of(a) * np.sqrt(a) - 1).max() <= 4 * np.finfo(float).eps


def test_blocked_drivers_ask_the_caches_for_the_blocks_ahead():
    """Every blocked force kernel compiles to code that holds prefetch instructions (the hint of
    model.terms._blocks.ahead), and a prefetch run as plain Python does nothing."""
    from numba import njit
    from model.terms._blocks import OPTIONS, prefetch

    x = perturbed(mesh_of("five"), 0.01)
    for key in ("corner", "variational", "normal_edge", "fem_linear"):
        fn, args = make_term(TERMS[key][0], mesh_of("five"), MAT, **TERMS[key][1]).kernel()
        fresh = njit(**dict(OPTIONS, cache=False))(fn.py_func)    # compiled here: its code seen
        fresh(x, *args, np.zeros_like(x))
        assert "prefetch" in "".join(fresh.inspect_asm().values()), key
    assert prefetch(x, 0) is None


def test_blocked_layout():
    """The blocked layout puts row t of an n-by-3 array in block t // B at lane t % B, one component
    after another, and fills the padded lanes of the last block with the last row."""
    a = np.arange(3 * 37, dtype=float).reshape(37, 3)
    b = blocked(a).reshape(-1, 3, B)
    t = np.arange(37)
    assert np.array_equal(b[t // B, :, t % B], a)
    assert np.array_equal(b[-1, :, 37 % B:], np.repeat(a[-1][:, None], B - 37 % B, axis=1))


@pytest.mark.parametrize("key", TERMS)
@pytest.mark.parametrize("family", MESHES)
def test_kernel_equals_its_reference(key, family):
    """Relative 1e-12 of the force scale, adding into a non-zero ``out`` as kernels do."""
    mesh = mesh_of(family)
    t = make_term(*TERMS[key][:1], mesh, MAT, **TERMS[key][1])
    for seed, amplitude in ((1, 0.005), (2, 0.02)):
        x = perturbed(mesh, amplitude, seed=seed)
        start = np.random.default_rng(seed).standard_normal(x.shape)
        want = forces(t.reference_kernel(), x, np.zeros_like(x))
        scale = np.abs(want).max()
        assert scale > 0
        got = forces(t.kernel(), x, start * scale) - start * scale
        assert np.abs(got - want).max() <= 1e-12 * scale


@pytest.mark.parametrize("family", MESHES)
def test_spring_kernel_gives_its_references_bits(family):
    """The spring kernel (a run of edges with one first node summed in registers) adds the
    reference kernel's forces bit for bit into a non-zero ``out``, on every mesh family."""
    mesh = mesh_of(family)
    t = make_term("springs", mesh, MAT)
    x = perturbed(mesh, 0.02, seed=3)
    start = np.random.default_rng(3).standard_normal(x.shape)
    assert np.array_equal(forces(t.kernel(), x, start), forces(t.reference_kernel(), x, start))


@pytest.mark.parametrize("key", TERMS)
def test_kernel_reports_the_first_flattened_tetrahedron_as_its_reference(key):
    """With one or two tetrahedra flattened (an edge collapsed, for the edge-strain term), the
    blocked kernel returns the same element index as the reference kernel, and a non-negative
    one."""
    mesh = cube(6, 0.02, "five")
    t = make_term(*TERMS[key][:1], mesh, MAT, **TERMS[key][1])
    m = mesh.n_tets
    for flatten in ((m - 1,), (3 * B + 5, 40), (7, m - 2)):
        x = mesh.points.copy()
        for k in flatten:       # the edge-strain term sees a collapsed edge, the others a flat one
            x[mesh.tets[k, 3]] = (x[mesh.tets[k, 0]] if key in COLLAPSED_EDGE
                                  else x[mesh.tets[k, :3]].mean(axis=0))
        fn, args = t.kernel()
        ref, ref_args = t.reference_kernel()
        got = fn(x, *args, np.zeros_like(x))
        assert got == ref(x, *ref_args, np.zeros_like(x))
        assert got >= 0        # a tetrahedron flattened, or one turned inside out by the move


THREADED = [k for k in TERMS
            if make_term(*TERMS[k][:1], cube(2, 0.01, "five"), MAT, **TERMS[k][1])
            .threaded_kernel() is not None]


@pytest.mark.skipif(numba.config.NUMBA_NUM_THREADS < 2, reason="one thread")
@pytest.mark.parametrize("key", THREADED)
@pytest.mark.parametrize("family", MESHES)
def test_threaded_kernel_equals_serial_bit_for_bit_and_the_reference(key, family):
    """On two numba threads the threaded kernel's forces, added into a non-zero output, equal the
    serial blocked kernel's bit for bit and the reference kernel's to 1e-12 of the force scale,
    on every mesh family."""
    mesh = mesh_of(family)
    t = make_term(*TERMS[key][:1], mesh, MAT, **TERMS[key][1])
    x = perturbed(mesh, 0.02, seed=5)
    was = numba.get_num_threads()
    numba.set_num_threads(2)
    try:
        start = np.full_like(x, 0.25)
        two = forces(t.threaded_kernel(), x, start)
    finally:
        numba.set_num_threads(was)
    assert np.array_equal(two, forces(t.kernel(), x, start))
    want = forces(t.reference_kernel(), x, np.zeros_like(x))
    assert np.abs(two - start - want).max() <= 1e-12 * np.abs(want).max()


@pytest.mark.parametrize("family", MESHES)
def test_corotated_kernel_equals_its_reference_far_from_rest(family):
    """Large rotations and stretches: the polar iteration runs many steps, lanes of one block
    converging at different steps."""
    from conftest import rotation
    mesh = mesh_of(family)
    t = make_term("fem_corotated", mesh, MAT)
    c = mesh.points.mean(axis=0)
    x = perturbed(mesh, 0.02, seed=3) - c
    # a rotation of 2.5 rad to 3 rad, growing along x, and a stretch: every tetrahedron turned
    # far, and differently
    turn = np.stack([rotation([1, 2, 3], a) for a in 2.5 + 0.5 * x[:, 0] / np.ptp(x[:, 0])])
    x = np.einsum("nij,nj->ni", turn, x * [1.3, 0.8, 1.1]) + c
    want = forces(t.reference_kernel(), x, np.zeros_like(x))
    got = forces(t.kernel(), x, np.zeros_like(x))
    assert np.abs(got - want).max() <= 1e-12 * np.abs(want).max()


@pytest.mark.skipif(numba.config.NUMBA_NUM_THREADS < 2, reason="one thread")
@pytest.mark.parametrize("name", ["fem_linear", "fem_corotated", "fem_neohookean", "volume"])
@pytest.mark.parametrize("family", MESHES)
def test_every_fem_baseline_has_a_two_thread_mode_equal_to_serial_bit_for_bit(name, family):
    """Each FEM baseline's and the volume term's two-thread kernel adds, into a non-zero
    output, the serial kernel's forces bit for bit on every mesh family, and reports the same
    first flattened tetrahedron where one corner is moved onto another."""
    mesh = mesh_of(family)
    t = make_term(name, mesh, MAT)
    x = perturbed(mesh, 0.02, seed=5)
    start = np.full_like(x, 0.25)
    was = numba.get_num_threads()
    numba.set_num_threads(2)
    try:
        two = forces(t.threaded_kernel(), x, start)
        fn, args = t.threaded_kernel()
        bad = x.copy()
        a, b = mesh.tets[len(mesh.tets) // 2, :2]
        bad[a] = bad[b]          # two corners of one tetrahedron on one point: it is flat
        got = fn(bad, *args, np.zeros_like(x))
    finally:
        numba.set_num_threads(was)
    assert np.array_equal(two, forces(t.kernel(), x, start))
    serial, sargs = t.kernel()
    assert got >= 0 and got == serial(bad, *sargs, np.zeros_like(x))


def fused_pair(mesh, reading):
    """A shear term of ``reading`` and a volume term on ``mesh``, and their fused unit."""
    shear = make_term("shear", mesh, MAT, reading=reading, c=0.5)
    volume = make_term("volume", mesh, MAT, scale=0.8)
    return shear, volume, shear.fuse(volume)


@pytest.mark.parametrize("reading", ["corner", "balanced", "variational"])
@pytest.mark.parametrize("family", MESHES)
def test_shear_and_volume_fused_equal_the_two_references(reading, family):
    """The fused shear-and-volume kernel adds, into a non-zero output, the shear reference's
    forces plus the volume term's own (scalar) kernel's to 1e-12 of their scale, on every
    mesh family."""
    mesh = mesh_of(family)
    shear, volume, fused = fused_pair(mesh, reading)
    assert fused is not None and fused.terms == (shear, volume)
    x = perturbed(mesh, 0.02, seed=4)
    want = forces(shear.reference_kernel(), x, np.zeros_like(x))
    want = forces(volume.kernel(), x, want)
    scale = np.abs(want).max()
    start = np.random.default_rng(4).standard_normal(x.shape) * scale
    got = forces(fused.kernel(), x, start) - start
    assert np.abs(got - want).max() <= 1e-12 * scale


def test_a_model_runs_shear_and_volume_as_one_unit_with_the_same_forces():
    """A preset of shear, normal and volume terms runs the shear and volume terms as one
    fused unit and the normal term alone; its forces equal the sum of its terms' own kernels
    to 1e-12 of their scale, and a term that does not fuse stays a unit of its own."""
    from model import build
    mesh = mesh_of("six")
    pm = build("pbcm-variational+normal", mesh, MAT)
    assert [u.name for u in pm.units] == ["shear + volume", "normal_edge"]
    x = perturbed(mesh, 0.02, seed=6)
    want = np.zeros_like(x)
    for term in pm.terms:
        want = forces(term.kernel(), x, want)
    assert np.abs(pm.forces(x) - want).max() <= 1e-12 * np.abs(want).max()
    assert [u.name for u in build("msm+volume", mesh, MAT).units] == ["springs", "volume"]


def test_a_fused_unit_reports_a_flattened_tetrahedron_as_the_shear_term():
    """A flattened tetrahedron met by the fused kernel is reported as the shear reference
    reports it: the same first index, in an error naming the shear term."""
    from model.errors import DegenerateTetError
    mesh = cube(6, 0.02, "five")
    shear, _, fused = fused_pair(mesh, "variational")
    x = mesh.points.copy()
    for k in (3 * B + 5, 40):
        x[mesh.tets[k, 3]] = x[mesh.tets[k, :3]].mean(axis=0)
    fn, args = fused.kernel()
    ref, ref_args = shear.reference_kernel()
    got = fn(x, *args, np.zeros_like(x))
    assert got >= 0 and got == ref(x, *ref_args, np.zeros_like(x))
    with pytest.raises(DegenerateTetError, match="term 'shear'"):
        raise fused.degenerate(got)


@pytest.mark.parametrize("shares", [3, 7])
@pytest.mark.parametrize("key", ["variational", "fem_linear", "volume", "springs"])
def test_threaded_mode_is_the_serial_bits_for_any_number_of_shares(key, shares):
    """Cut into 3 or 7 shares (more than the threads that run them), the threaded kernel
    adds the serial kernel's forces bit for bit into a non-zero output, on an unstructured
    mesh."""
    from model.terms._blocks import blocked_tets
    from model.terms._threads import SplitBlocks
    mesh = mesh_of("unstructured")
    name, params = TERMS.get(key, (key, {}))
    t = make_term(name, mesh, MAT, **params)
    elements = t.edge if key == "springs" else mesh.tets
    split = SplitBlocks(blocked_tets(elements), len(elements), mesh.n_nodes, shares=shares)
    _, (kernel_range, args, *_) = t.threaded_kernel()
    fn, args = split.kernel(kernel_range, args)
    x = perturbed(mesh, 0.02, seed=8)
    start = np.full_like(x, -0.5)
    was = numba.get_num_threads()
    numba.set_num_threads(2)
    try:
        got = forces((fn, args), x, start)
    finally:
        numba.set_num_threads(was)
    assert len(split.dest) > 0          # some forces did wait for an earlier share
    assert np.array_equal(got, forces(t.kernel(), x, start))


_SERIAL_THEN_THREADED = """
import sys, numpy as np
from model import Material
from model.mesh import cube
from model.terms import make_term
mesh, mat = cube(6, 0.02, "unstructured", seed=3), Material(E=1e4, nu=0.45, rho=1000.0)
rng = np.random.default_rng(7)
x = mesh.points + 1e-4 * rng.standard_normal(mesh.points.shape)
got = []
for name, params in [("fem_linear", {}), ("fem_neohookean", {}), ("normal_edge", {"c": 0.5}),
                     ("springs", {}), ("volume", {})]:
    t = make_term(name, mesh, mat, **params)
    fn, args = t.threaded_kernel() if sys.argv[1] == "threaded" else t.kernel()
    out = np.full_like(x, 0.25)
    assert fn(x, *args, out) == -1
    got.append(out)
np.save(sys.argv[2], np.array(got))
"""


@pytest.mark.skipif(numba.config.NUMBA_NUM_THREADS < 2, reason="one thread")
def test_threaded_bits_do_not_hang_on_which_process_compiled_the_serial_kernel(tmp_path):
    """With an empty numba cache, one process compiles and runs the serial kernels (and caches
    them); a second process, which loads the cached serial pieces, compiles and runs the
    threaded kernels: their forces are the same bits, for the small kernels (FEM blocks, the
    edge normal term, the springs, the volume term) a compiler may inline in one process and
    not in the other."""
    import os
    import subprocess
    import sys
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache")}
    for mode in ("serial", "threaded"):
        subprocess.run([sys.executable, "-c", _SERIAL_THEN_THREADED, mode,
                        str(tmp_path / f"{mode}.npy")], env=env, check=True)
    assert np.array_equal(np.load(tmp_path / "serial.npy"), np.load(tmp_path / "threaded.npy"))

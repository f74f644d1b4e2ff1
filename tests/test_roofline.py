"""The bench's roofline: operations counted by running a kernel on counting numbers, the
compulsory bytes a kernel's arrays make, the machine's peaks, and the fraction of the
attainable rate."""
import json
import os
import subprocess
import sys
from types import SimpleNamespace

import numpy as np
import pytest

from cases.tools import flops, roofline


def test_counted_numbers_count_each_operation_once():
    """A Counted number counts +, -, *, /, negation, sqrt and log applied to it (a float on
    either side), and nothing for comparisons or conversions."""
    flops.Counted.ops = 0
    a, b = flops.Counted(2.0), flops.Counted(3.0)
    c = -(a * b + 1.0) / b - 2.0 * a          # 6 operations
    assert flops.Counted.ops == 6 and float(c) == pytest.approx(-(7.0 / 3.0) - 4.0)
    _ = a < b, a == 2.0, float(a)
    assert flops.Counted.ops == 6
    arr = flops.counted(np.array([4.0]))
    assert float(np.sqrt(arr)[0]) == 2.0 and flops.Counted.ops == 7


def test_fem_linear_counts_its_hand_counted_operations_and_its_own_forces():
    """fem-linear's force evaluation, run uncompiled on counting numbers, takes 189 operations
    per tetrahedron, the count by hand: the deformation gradient 78 (edges 9, F 54 with the
    multiplication by 1.0, det F 14, its margin over the flattening bound 1), the stress 27,
    the corner forces 84 (three corners at 27: a dot, a negation and a product per component,
    three additions into the node, three into corner 0; corner 0's three additions); and its
    counted forces are the numpy twin's."""
    code = ("import json, numpy as np; from cases.tools import flops; "
            "from model import build; from cases.framework import DEFAULT_MATERIAL; "
            "from cases.library.common import bench_mesh; "
            "n, f = flops.count_here('fem-linear'); "
            "m = bench_mesh(flops.COUNT_TETS); pm = build('fem-linear', m, DEFAULT_MATERIAL); "
            "ref = pm.terms[0].forces_numpy(flops.pushed(m.points)); "
            "print(json.dumps([n, float(np.abs(f - ref).max() / np.abs(ref).max())]))")
    got = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env={**os.environ, flops.JIT_OFF: "1"}, check=True)
    per_tet, diff = json.loads(got.stdout.strip().splitlines()[-1])
    assert per_tet == 189.0
    assert diff < 1e-12


def test_counting_refuses_to_run_compiled():
    """Counting in a process whose jit is on is refused with what to do."""
    with pytest.raises(RuntimeError, match="NUMBA_DISABLE_JIT"):
        flops.count_here("fem-linear")


def test_bytes_and_the_attainable_fraction():
    """The compulsory bytes count each kernel array once (one shared by two kernels once),
    with the positions read and the forces read and written; the fraction is the rate over
    min(FMA peak, bandwidth x intensity)."""
    tets = np.zeros((10, 4), dtype=np.int64)          # 320 bytes
    per = np.zeros(10)                                # 80 bytes
    pm = SimpleNamespace(mesh=SimpleNamespace(points=np.zeros((5, 3)), n_tets=10),
                         kernels=lambda: [(None, (tets, per, 1.0)), (None, (tets,))])
    assert roofline.bytes_per_tet(pm) == pytest.approx((320 + 80 + 3 * 120) / 10)
    peak = {"fma_gflop_s": 20.0, "copy_gb_s": 5.0}
    assert roofline.fraction(100.0, 50.0, 10.0, peak) == (10.0, 10.0, 1.0)   # memory bound
    assert roofline.fraction(100.0, 1.0, 10.0, peak) == (10.0, 20.0, 0.5)    # compute bound
    assert roofline.fraction(None, 1.0, 10.0, peak) == (None, None, None)


def test_the_peaks_are_measured_rates():
    """The copy's bandwidth and the FMA loop's rate are finite and positive."""
    pk = roofline.peaks()
    assert all(np.isfinite(v) and v > 0 for v in pk.values())
    assert set(pk) == {"copy_gb_s", "fma_gflop_s"}

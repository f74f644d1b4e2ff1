"""What causes the bulge/neck artefact of the paper (section 5), and which reading of its
equations did it use? A controlled study on the paper's cube: the mesh (the mirrored five
split, six, bcc, reconstructions of the paper's 374-tetrahedron mesh, the five split refined),
the shear reading (calibrated and literal), normal stress, msm with and without a shear term,
the base and the load, each cell's alternation against the continuum's; the factors that
switch the pattern on and off, and the answers computed from them.
"""
from ...framework import Study
from ...library import paper_cube as P
from ...running.store import OFF
from . import report
from .study import ArtefactSettings, bench_costs, lines_joined, recorded_lines, run


class Artefact(Study):
    name = "artefact"
    runs_recorded = ("cells",)
    selections = ()           # its meshes and models are the controlled factors
    title = ("the bulge/neck pattern of the paper's cube over mesh, reading, normal stress, "
             "base and load")

    settings_class = ArtefactSettings
    takes = ()                # the material alone
    recorded_keys = ("cells", "references", "step_vs_msm")
    record_files = ("cells", "lines")

    def definitions(self):
        from .analysis import CLEAR, DECIDING_LEAK, GROWS, LEAK_SHARE
        return [
            "configuration (size, base) (artefact study): the study's unit of analysis, one "
            "number of nodes per side with one base; it has one mesh per split (n = 1), so "
            "its uncertainty is the metric's leak alone.",
            "signature leak (artefact study): the period-2 signature is exactly 0 (to "
            "round-off) on the reference and on polynomials up to degree 2; any other smooth "
            "field (a barrel, a Gaussian bulge, an end layer, each varying over two layer "
            "spacings or more) scores a small leak, largest on few layers, and an end layer "
            "sharper than that a larger one (the sharp leak); a configuration decides only "
            f"where its worst smooth test field leaks below {LEAK_SHARE:g} of the clear level "
            f"{CLEAR:g} ({DECIDING_LEAK:g}).",
            "stable, flutter (artefact study): one definition, the glossary's growth: a mode "
            f"flutters where its growth rate at rest is above {GROWS:g} 1/s; stable means rate "
            f"0 (a rate below {P.RATE_ROUND_OFF:g} of the model's largest frequency is the "
            "eigensolver's round-off, read as 0); a flutter grows beyond the mass damping we assume where its rate exceeds half "
            "of it; linearised at rest with each base's constraints, and read on the clamped "
            "base only (the paper fixes its base nodes)."]

    def run(self, s, workers=None, log=True, bench=None, store=None):
        return run(s, workers=workers, log=log, bench=bench, store=store or OFF)

    def write(self, out, s, data):
        return report.write(out, self, s, data)

    def redrawn(self, s, data, metrics):
        # the cost is the checkout's bench at the paper's size, the number every other report
        # prints; the recorded one only where the checkout has no bench
        from ...reporting.costs import load
        data["cells"] = recorded_lines(lines_joined(data["cells"], metrics["lines"]))
        bench = load()
        if bench:
            data.update(bench_costs(bench, list(s.models)))
        else:
            data.update({k: metrics.get(k) for k in ("step_vs_msm_range", "step_vs_msm_sizes",
                                                       "sim_vs_msm_sizes", "bench_spread")})
        for c in data["cells"]:     # the glossary's flutter: a growth rate above 0
            if c.get("growth_rate_1_s") is not None:
                c["flutter"] = c["growth_rate_1_s"] > 0.0
        return data


STUDY = Artefact()

"""`pbcm fit`: a model's constants fitted to the FEM references of chosen cases."""
from pathlib import Path

from ..running.output import StagedFolder
from .common import add_term_files, case_named, choose, number, poisson

def add(sub):
    """The command's parser."""
    ft = sub.add_parser(
        "fit", help="fit a model's constants to the FEM references of chosen cases",
        description="Fit the constants of MODEL's terms (shear c, normal c_n, spring stiffness "
                    "scale) by least squares (scipy) to the FEM displacements of --cases, and "
                    "cross-validate on the cases left out (--validate; default every other "
                    "case with a static problem): error before and after. Writes fit.json and "
                    "report.md/.html to --out (default reports/fit/MODEL).")
    ft.add_argument("model", help="a preset or composed model")
    ft.add_argument("--cases", nargs="+", required=True, help="cases to fit on")
    ft.add_argument("--validate", nargs="*", help="cases left out, to cross-validate on")
    ft.add_argument("--quick", action="store_true", help="each case's quick settings")
    ft.add_argument("--against", choices=("p1", "continuum"), default="p1",
                    help="the reference fitted to: FEM P1 on the same tetrahedra (default: "
                         "the model-form error) or the converged continuum")
    ft.add_argument("--meshes", nargs="+", help="mesh families of every case (default: each "
                                                "case's own)")
    ft.add_argument("--bcs", nargs="+", help="boundary conditions of every case (default: "
                                             "each case's own)")
    ft.add_argument("--out", help="output folder (default reports/fit/MODEL)")
    ft.add_argument("--E", type=number("--E", "Young's modulus in Pa, a number > 0", low=0),
                    help="Young's modulus [Pa] (default: each case's)")
    ft.add_argument("--nu", type=poisson, help="Poisson's ratio, -1 < nu < 0.5 (default: each "
                    "case's)")
    add_term_files(ft)
    ft.set_defaults(func=run)


def run(args):
    import json
    from model.compose import label, slug
    from ..registry import CASES
    from .fitting import check_cases, fit, fitted_terms, report
    name = label(args.model)
    fitted_terms(name)                       # a model with nothing to fit: refused now
    train = [case_named(c) for c in args.cases]
    validate = [case_named(c) for c in args.validate] if args.validate is not None else [
        c for n, c in CASES.items() if c.static and n not in args.cases]
    check_cases(train, validate)
    for c in [*train, *validate]:
        choose("mesh", args.meshes, c.meshes)
        choose(f"boundary condition of {c.name}", args.bcs, c.bcs)
    overrides = {k: v for k, v in {"E": args.E, "nu": args.nu, "meshes": args.meshes and
                                   tuple(args.meshes), "bcs": args.bcs and tuple(args.bcs)
                                   }.items() if v is not None}
    with StagedFolder(Path(args.out) if args.out else Path("reports") / "fit" / slug(name),
                      mark="fit.json") as out:
        doc = fit(name, train, validate, quick=args.quick, overrides=overrides,
                  against=args.against)
        (out.path / "fit.json").write_text(json.dumps(doc, indent=1) + "\n")
        report(doc).write(out.path)
        path = out.commit()
    for k, v in doc["constants_fitted"].items():
        print(f"{k:<24} auto {doc['constants_auto'][k]:.5g} -> fitted {v:.5g} "
              f"(factor {doc['scales'][k.split('.')[0]]:.4g}, rel. s.e. "
              f"{doc['scale_rel_se'][k.split('.')[0]]:.2g})")
    print(f"condition number {doc['condition_number']:.3g}; report written to {path}")
    return 0


"""`pbcm check`: measured metrics against the gold values (cases.running.gate)."""
import sys
from pathlib import Path

def add(sub):
    """The command's parser."""
    c = sub.add_parser("check", help="compare the latest metrics with the gold values "
                       "(exit 0 pass, 1 fail, 2 missing or malformed, 3 pass with new models)",
                       description="Compare every metrics.json under --metrics with the gold "
                                   "values of --gold (quick mode: gold/CASE.quick.jsonl; full "
                                   "mode: the committed reports/CASE/metrics.json), two-sided, "
                                   "with the tolerance policy of gold/policy.toml. Exit status "
                                   "0: every value holds; 1: some metric left its band, or was "
                                   "n/a in the gold and is a number now (or the reverse); 2: "
                                   "gold without a metric, a metric without gold for a model "
                                   "that has gold, a NaN, a malformed or missing file, or "
                                   "metrics run at other problem parameters than the gold's; "
                                   "3: every value holds, and some model (a new preset or "
                                   "composed model) has no gold at all in that case and mode: "
                                   "listed as 'new, not gated yet' (--allow-new turns 3 into "
                                   "0).")
    c.add_argument("--allow-new", action="store_true",
                   help="exit 0 rather than 3 when the only news is models without gold")
    c.add_argument("--only-run", action="store_true",
                   help="gate only the gold rows of the runs in --metrics (a run of some "
                        "models, meshes or bcs); the gold's other rows are set aside and "
                        "counted, never deleted")
    c.add_argument("--models", nargs="+", metavar="MODEL",
                   help="gate these models only (the gold of the others is left out of the "
                        "comparison, never deleted)")
    c.add_argument("--verbose", action="store_true",
                   help="print every compared value (default: the failures and the totals)")
    c.add_argument("--junit", metavar="FILE",
                   help="also write the comparison as JUnit XML (one test case per gated "
                        "value) for a CI dashboard")
    c.add_argument("--metrics", default="reports", help="a metrics.json or a folder of them "
                   "(default reports)")
    c.add_argument("--gold", default="gold",
                   help="the gold folder (default gold in the current folder: the "
                        "repository's own when run from a checkout)")
    c.set_defaults(func=run)


LEGEND = ("margin: how far inside its band a value is, as a fraction of the band's "
          "half-width (100 % at the gold value, 0 at its edge, negative outside); band: the "
          "gold value +- the tolerance of gold/policy.toml (rtol relative, atol absolute, "
          "one-sided where the metric's better direction allows)")


def run(args):
    from ..running.gate import NEW, CheckError, check, flip_message, load, measured
    from ..running.output import OutputError, writable_folder
    try:
        if args.junit:      # before comparing anything
            if Path(args.junit).is_dir():
                raise OutputError(f"--junit {args.junit} is a folder; give a file name")
            writable_folder(Path(args.junit).resolve().parent, "--junit's folder")
        v = check(load(args.gold, hint="--gold"), measured(args.metrics), args.only_run,
                  args.models)
    except (CheckError, OutputError) as exc:
        print(f"pbcm check: error: {exc}", file=sys.stderr)
        return 2
    failed = [r for r in v.rows if not r[2]]
    shown = v.rows if args.verbose else failed
    if shown:
        print(f"{'metric':<66} {'measured':>11} {'band':>23} {'margin':>8}  result")
    for b, value, ok in shown:
        name = f"{b.case}/{b.mesh}/{b.bc}/{b.model}/{b.metric}"
        low, high = b.band
        print(f"{name:<66} {value:>11.5g} [{low:>10.5g},{high:>10.5g}] "
              f"{b.margin(value):>8.1%}  {'PASS' if ok else 'FAIL'}")
    print(LEGEND)
    print(f"{len(v.rows) - len(failed)} passed, {len(failed) + len(v.flips)} failed"
          + (f" ({v.aside} gold rows of runs not in the metrics set aside)" if v.aside else "")
          + ("" if args.verbose or not v.rows else " (--verbose prints every value)"))
    worse = [r for r in failed if r[0].verdict(r[1]).startswith("worse")]
    # beside a regression, a value that moved the other way moved with it: not an improvement
    moved = [r for r in failed if r not in worse] if worse else []
    for b, value, _ in [r for r in failed if r not in moved]:
        low, high = b.band
        print(f"FAIL {b.metric} of {b.case}/{b.mesh}/{b.bc}/{b.model}: {value:.6g} outside "
              f"[{low:.6g}, {high:.6g}] ({b.verdict(value)})")
    if moved:
        print(f"{len(moved)} value(s) moved with the regression above (do not bless them: "
              "fix the regression first):")
    for b, value, _ in moved:
        low, high = b.band
        print(f"FAIL {b.metric} of {b.case}/{b.mesh}/{b.bc}/{b.model}: {value:.6g} outside "
              f"[{low:.6g}, {high:.6g}] (moved with the regression: do not bless)")
    for key, gold, now in v.flips:
        print(flip_message(key, gold, now))
    for case, mode, name, n in v.new:
        print(f"NEW  {case} ({mode}) {name}: new, not gated yet ({n} metrics without gold; "
              "`pbcm bless` gates them)")
    if v.new:
        print(f"{len(v.new)} model(s) new, not gated yet")
    if args.junit:
        _write_junit(args.junit, v, flip_message)
    return 0 if v.status == NEW and args.allow_new else v.status



def _write_junit(path, v, flip_message):
    """The verdict as JUnit XML: one test case per gated value (its class the run, its name
    the metric), a failure for each value out of its band or flipped to or from n/a."""
    import xml.etree.ElementTree as ET
    from ..running.output import write_atomic
    suite = ET.Element("testsuite", name="pbcm check", tests=str(len(v.rows) + len(v.flips)),
                       failures=str(sum(not ok for _, _, ok in v.rows) + len(v.flips)))
    for b, value, ok in v.rows:
        case = ET.SubElement(suite, "testcase", classname=f"{b.case}/{b.mesh}/{b.bc}/{b.model}",
                             name=b.metric)
        if not ok:
            low, high = b.band
            ET.SubElement(case, "failure", message=f"{value:.6g} outside [{low:.6g}, "
                          f"{high:.6g}] ({b.verdict(value)})")
    for key, gold, now in v.flips:
        case = ET.SubElement(suite, "testcase", classname="/".join(key[2:5]), name=key[5])
        ET.SubElement(case, "failure", message=flip_message(key, gold, now))
    write_atomic(path, ET.tostring(ET.ElementTree(suite).getroot(), encoding="unicode",
                                   xml_declaration=True) + "\n")

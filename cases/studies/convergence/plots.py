"""Figures of the convergence study (millimetres on every axis): error against h per problem,
directional Young's modulus per lattice, error against step cost."""
import numpy as np
from matplotlib.ticker import NullLocator

from ...reporting.figures import plt

# drawn last, dashed: fem-linear (FEM P1's explicit twin) shows underneath
P1_STYLE = {"color": "k", "lw": 2.0, "ls": "--", "marker": "o", "ms": 4, "zorder": 10}


def _colours(models):
    cmap = plt.get_cmap("tab10")
    return {m: cmap(i % 10) for i, m in enumerate(models)}


def error_vs_h(path, title, families, models, series, yardstick):
    """One log-log panel per mesh family: each model's error against h (``series[(family,
    model)] = (h, e)``), FEM P1 on the same mesh as the thick black yardstick."""
    colours = _colours(models)
    fig, axes = plt.subplots(1, len(families), figsize=(3.6 * len(families), 3.8),
                             sharey=True, squeeze=False)
    hs = sorted({h for (fam, _), (hh, _) in series.items() for h in hh}, reverse=True)
    for ax, fam in zip(axes[0], families):
        for m in models:
            if (fam, m) in series:
                h, e = series[(fam, m)]
                ax.loglog(h, e, "-s", ms=3, color=colours[m], label=m)
        if (fam, yardstick) in series:
            h, e = series[(fam, yardstick)]
            ax.loglog(h, e, label=yardstick, **P1_STYLE)
        ax.set_title(fam, fontsize=9)
        ax.set_xlabel("h [mm]")
        ax.set_xticks(hs, [f"{h:.3g}" for h in hs])
        ax.xaxis.set_minor_locator(NullLocator())
        ax.invert_xaxis()
        ax.grid(alpha=0.3, which="both")
    axes[0][0].set_ylabel("displacement error (rel. L2)")
    handles, labels = axes[0][0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=5, fontsize=7)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout(rect=(0, 0.12, 1, 1))
    fig.savefig(path, dpi=90)
    plt.close(fig)


def directional_young(path, angles_deg, families, models, curves, E):
    """One panel per lattice: E(d) / E for d turning in the x-y plane from [100] through
    [110] (45 degrees) to [010], one line per model (``curves[(family, model)]``), the
    isotropic target as a dashed line."""
    colours = _colours(models)
    angles = np.asarray(angles_deg)
    keep = angles <= 180.0
    fig, axes = plt.subplots(1, len(families), figsize=(3.6 * len(families), 3.8),
                             sharey=True, squeeze=False)
    for ax, fam in zip(axes[0], families):
        ax.axhline(1.0, color="k", ls="--", lw=1.5, label="isotropic target")
        for m in models:
            if (fam, m) in curves:
                ax.semilogy(angles[keep], np.asarray(curves[(fam, m)])[keep] / E,
                            color=colours[m], label=m)
        ax.set_title(fam, fontsize=9)
        ax.set_xticks([0, 45, 90, 135, 180], ["[100]", "[110]", "[010]", "[-110]", "[-100]"],
                      fontsize=7)
        ax.grid(alpha=0.3, which="both")
    axes[0][0].set_ylabel("E(d) / E")
    handles, labels = axes[0][0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=5, fontsize=7)
    fig.suptitle("Directional Young's modulus in the x-y plane, per lattice", fontsize=10)
    fig.tight_layout(rect=(0, 0.12, 1, 1))
    fig.savefig(path, dpi=90)
    plt.close(fig)


def pareto(path, groups, models, floor):
    """One panel per (case, bc): every run as (step cost, error), the Pareto front joined;
    errors below ``floor`` (exact: the reference's own level) are drawn on it."""
    colours = _colours(models)
    fig, axes = plt.subplots(1, len(groups), figsize=(3.8 * len(groups), 3.9), sharey=True,
                             squeeze=False)
    for ax, g in zip(axes[0], groups):
        pts = g["points"]
        for m in models:
            mine = [p for p in pts if p["model"] == m]
            if mine:
                ax.loglog([p["cost_us"] for p in mine],
                          [max(p["disp_rel_l2"], floor) for p in mine],
                          "o", ms=3.5, color=colours[m], alpha=0.8, label=m)
        front = [pts[i] for i in g["front"]]
        ax.loglog([p["cost_us"] for p in front], [max(p["disp_rel_l2"], floor) for p in front],
                  "k-", lw=1, label="Pareto front")
        ax.axhline(floor, color="grey", lw=0.8, ls=":")
        ax.set_title(f"{g['case']} {g['bc']}", fontsize=9)
        ax.set_xlabel("cost of one RK4 step [us]")
        ax.grid(alpha=0.3, which="both")
    axes[0][0].set_ylabel("displacement error (rel. L2)")
    handles, labels = axes[0][0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=5, fontsize=7)
    fig.suptitle("Accuracy per cost: every model, mesh family and h", fontsize=10)
    fig.tight_layout(rect=(0, 0.12, 1, 1))
    fig.savefig(path, dpi=90)
    plt.close(fig)


__all__ = ["error_vs_h", "directional_young", "pareto"]

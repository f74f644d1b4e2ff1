"""Matplotlib figures of a case (millimetres on every axis)."""
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # noqa: E402
from model.units import MM  # noqa: E402

FACES = np.array([[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]])


def boundary_faces(tets):
    """Boundary triangles (k, 3) and the tetrahedron each belongs to."""
    f = tets[:, FACES].reshape(-1, 3)
    key = np.sort(f, axis=1)
    _, inv, counts = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    once = counts[inv.ravel()] == 1
    return f[once], np.repeat(np.arange(len(tets)), 4)[once]


SCALE_PERCENTILE = 99.0     # a stress panel's scale: robust to a few extreme tetrahedra


def stress_panels(path, panels, title, magnify, up="y"):
    """The analogue of the paper's Figure 1: each panel (label, mesh, u, max_tau) drawn
    deformed (displacement x ``magnify``), standing on the axis ``up``, boundary faces
    coloured by max |tau| on one shared scale: blue at or below 0.01 of it, red at or above
    0.9. The scale is the largest panel's SCALE_PERCENTILE-th percentile over its
    tetrahedra, not its maximum: one sliver's spike would turn every other face blue."""
    scale = max(float(np.percentile(p[3], SCALE_PERCENTILE)) for p in panels)
    if not scale > 0:
        scale = max(float(np.max(p[3])) for p in panels) or 1.0
    # the paper's normalisation: max |tau| / scale, blue at or below 0.01, red from 0.9
    norm = matplotlib.colors.Normalize(vmin=0.01, vmax=0.9, clip=True)
    cmap = plt.get_cmap("jet")
    cols = min(4, len(panels))
    rows = int(np.ceil(len(panels) / cols))
    fig = plt.figure(figsize=(3.2 * cols, 3.2 * rows + 0.6))
    for k, (label, mesh, u, tau) in enumerate(panels):
        ax = fig.add_subplot(rows, cols, k + 1, projection="3d")
        tri, owner = boundary_faces(mesh.tets)
        x = (mesh.points + magnify * u) / MM
        ax.add_collection3d(Poly3DCollection(x[tri], facecolors=cmap(norm(tau[owner] / scale)),
                                             edgecolors="k", linewidths=0.2))
        lo, hi = mesh.points.min(axis=0) / MM, mesh.points.max(axis=0) / MM
        pad = 0.06 * (hi - lo).max()
        ax.set_xlim(lo[0] - pad, hi[0] + pad), ax.set_ylim(lo[1] - pad, hi[1] + pad)
        ax.set_zlim(lo[2] - pad, hi[2] + pad)
        ax.view_init(elev=20, azim=-60, vertical_axis=up)
        ax.set_box_aspect(tuple(hi - lo + 2 * pad))
        ax.set_title(label, fontsize=9)
        ax.set_axis_off()
    sm = matplotlib.cm.ScalarMappable(norm=norm, cmap=cmap)
    fig.colorbar(sm, ax=fig.axes, shrink=0.6, extend="both", ticks=[0.01, 0.25, 0.5, 0.75, 0.9],
                 label=f"max |tau| / {scale:.4g} Pa, the {SCALE_PERCENTILE:g}th percentile "
                       "(blue <= 0.01, red >= 0.9)")
    fig.suptitle(f"{title} (displacement x{magnify:g})", fontsize=10)
    fig.savefig(path, dpi=90)
    plt.close(fig)


def _finish(fig, ax, path, xlabel, ylabel, title, grid_axis="both"):
    """Labels, grid, legend, and the PNG written and closed: the end of every chart here."""
    if xlabel:
        ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=10)
    ax.grid(alpha=0.3, axis=grid_axis)
    if ax.get_legend_handles_labels()[1]:   # beside the axes: a legend never covers data
        ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def _draw(ax, series, highlight, plot, markers="-s"):
    """Each (label, data) of ``series`` through ``plot(data, fmt, **style)``: in colour with
    ``markers`` where ``highlight`` (default: all) holds it, else a thin grey line under one
    legend entry."""
    grey = False
    for label, data in series:
        if highlight is None or label in highlight:
            plot(data, markers, ms=4, label=label, zorder=2)
        else:
            plot(data, "-", color="0.75", lw=1, zorder=1,
                 label=None if grey else "the others (close to the reference)")
            grey = True


def profiles(path, layers_mm, series, fem, title, highlight=None, fem_label="FEM P2 (converged)"):
    """Layer profiles: mean outward lateral displacement per y-layer, models against FEM;
    the models in ``highlight`` (default: all) in colour, the rest in grey."""
    fig, ax = plt.subplots(figsize=(7.5, 4))
    ax.plot(fem, layers_mm, "k-o", lw=2.5, label=fem_label, zorder=3)
    _draw(ax, series, highlight, lambda p, f, **kw: ax.plot(p, layers_mm, f, **kw))
    _finish(fig, ax, path, "mean outward lateral displacement [mm]", "layer y [mm]", title)


def heatmap(path, rows, cols, values, title, label, limit):
    """A table of numbers as colours: ``values[i][j]`` (None: hatched grey) for row ``rows[i]``
    and column ``cols[j]``, on a diverging scale from -limit to +limit, the value written in
    each cell."""
    v = np.array([[np.nan if x is None else x for x in r] for r in values], float)
    fig, ax = plt.subplots(figsize=(1.0 + 0.62 * len(cols), 1.2 + 0.24 * len(rows)))
    ax.set_facecolor("0.85")
    im = ax.imshow(v, cmap="coolwarm", vmin=-limit, vmax=limit, aspect="auto")
    for i in range(len(rows)):
        for j in range(len(cols)):
            if np.isfinite(v[i, j]):
                ax.text(j, i, f"{v[i, j]:.3f}", ha="center", va="center", fontsize=5.5)
    ax.set_xticks(range(len(cols)), cols, rotation=45, ha="right", fontsize=7)
    ax.set_yticks(range(len(rows)), rows, fontsize=6.5)
    ax.set_title(title, fontsize=9)
    fig.colorbar(im, ax=ax, label=label, shrink=0.8)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def grouped_bars(path, groups, labels, values, ylabel, title, log=False):
    """values[g][l] for each group g and label l."""
    fig, ax = plt.subplots(figsize=(max(6, 1.3 * len(groups)), 4))
    w = 0.8 / len(labels)
    for i, lab in enumerate(labels):
        ax.bar(np.arange(len(groups)) + i * w, [values[g][i] for g in range(len(groups))], w,
               label=lab)
    ax.set_xticks(np.arange(len(groups)) + 0.4 - w / 2, groups, fontsize=8)
    if log and any(v is not None and v > 0 for row in values for v in row):
        ax.set_yscale("log")     # a figure of failed runs only has nothing to put on a log axis
    _finish(fig, ax, path, None, ylabel, title, grid_axis="y")


def reaction_history(path, series, fem_level, fem_transient, title, level_label):
    """The top reaction against time: every model, the FEM transient (label, t, r) on the
    same boundary motion, and the static FEM level."""
    fig, ax = plt.subplots(figsize=(6, 4))
    label, t, r = fem_transient
    ax.plot(t, r, "k-", lw=2.5, label=label)
    for label, t, r in series:
        ax.plot(t, r, label=label)
    ax.axhline(fem_level, color="k", ls="--", label=level_label)
    _finish(fig, ax, path, "time [s]", "reaction on the driven nodes [N]", title)


def curves(path, x, fem, fem_label, series, xlabel, ylabel, title, markers="-s",
           highlight=None):
    """Model curves y(x) against the reference's, on one chart; the models in ``highlight``
    (default: all) in colour, the rest in grey."""
    fig, ax = plt.subplots(figsize=(7.5, 4))
    ax.plot(x, fem, "k-o", lw=2.5, label=fem_label, zorder=3)
    _draw(ax, series, highlight, lambda y, f, **kw: ax.plot(x, y, f, **kw), markers)
    _finish(fig, ax, path, xlabel, ylabel, title)


def loglog(path, series, xlabel, ylabel, title):
    """Lines y(x) on log-log axes, one per (label, x, y)."""
    fig, ax = plt.subplots(figsize=(6, 4.5))
    for label, x, y in series:
        ax.loglog(x, y, "-o", ms=3, label=label)
    _finish(fig, ax, path, xlabel, ylabel, title)


def error_against_cost(path, series, budget, xlabel, ylabel, title):
    """Error against cost on log-log axes, one line per (label, costs, errors), and the
    budget drawn as a vertical line (what lies left of it fits the budget)."""
    fig, ax = plt.subplots(figsize=(6, 4.5))
    for label, x, y in series:
        ax.loglog(x, y, "-o", ms=3, label=label)
    ax.axvline(budget, color="k", ls="--", lw=1, label="real time")
    _finish(fig, ax, path, xlabel, ylabel, title)


def measured_layers(path, layers, columns, title, highlight=None):
    """Measured against modelled quantities per bead layer: one column per entry of
    ``columns`` = (column title, rows), each row (ylabel, measured, floor, references,
    models): the measurement with its noise (``floor``) as error bars, the references ((label, values))
    in black, the models ((label, values)) in colour where ``highlight`` holds them (default:
    all), else grey. ``layers`` the layer positions on the x axis."""
    n_rows = len(columns[0][1])
    fig, axes = plt.subplots(n_rows, len(columns), figsize=(3.3 * len(columns) + 2.4,
                                                            2.9 * n_rows), squeeze=False)
    for c, (column, rows) in enumerate(columns):
        for r, (ylabel, measured, floor, references, models) in enumerate(rows):
            ax = axes[r][c]
            ax.errorbar(layers, measured, yerr=floor, fmt="ko", ms=5, capsize=3, zorder=4,
                        label="measured (bars: its noise)")
            for (label, values), style in zip(references, ("k-", "k--", "k:")):
                ax.plot(layers, values, style, lw=1.6, label=label, zorder=3)
            _draw(ax, models, highlight, lambda v, f, **kw: ax.plot(layers, v, f, **kw))
            ax.set_title(column if r == 0 else "", fontsize=9)
            ax.set_ylabel(ylabel if c == 0 else "", fontsize=8)
            ax.set_xlabel("bead layer k (1: fixed plate)" if r == n_rows - 1 else "",
                          fontsize=8)
            ax.grid(alpha=0.3)
    handles, labels = axes[0][0].get_legend_handles_labels()
    fig.legend(handles, labels, fontsize=7, loc="upper left", bbox_to_anchor=(0.79, 0.95))
    fig.suptitle(title, fontsize=10)
    fig.tight_layout(rect=(0, 0, 0.78, 0.95))
    fig.savefig(path, dpi=90)
    plt.close(fig)

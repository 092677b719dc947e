"""The final scalars known before any work (validation_scalars.py) are those a run reports, for
every model of the package: the sweep refuses a plot of any other name before it writes
anything, and the two lists can never drift apart. The study plots (sweep.png,
convergence.png) say what they show: axes named by their quantities, log axes where slopes are
read, the measured slope of every line, a reference slope, a legend off the data, no text over
other text, and the user's matplotlib session untouched."""
import json
import subprocess
import sys

import pytest
import ufl
from mpi4py import MPI

import damage_dolfinx as dd
from conftest import ENV
from damage_dolfinx.catalogue.examples import catalogue
from damage_dolfinx.geometries.rectangle import rectangle, side
from damage_dolfinx.runtime.loop import Run
from damage_dolfinx.problem.scalars import final_scalar_names

#: one example of every model (n: a tiny structured mesh; None: the gmsh mesh as it is), with
#: the data that select columns (2.2-ex3 and 3.3-ex2: a probe; 3.2-ex2: two named contact
#: faces) and both dimensions
EXAMPLES = {"2.1-ex2a": None, "2.1-ex3": None, "2.2-ex3": 2, "2.3-ex1": 2, "2.4-ex1": 2,
            "3.1-ex1": 2, "3.2-ex2": 2, "3.3-ex2": 2, "2.2-ex1-3d": 1, "3.3-ex1-3d": 2}


def rect_mesh(comm, n):  # 1 left, 2 right, 3 bottom
    return rectangle(comm, (0.0, 0.0), (2.0, 0.5), 4 * n, n,
                     {1: side(0, 0.0), 2: side(0, 2.0), 3: side(1, 0.0)})


def own(model, roles, **params):
    return dd.Problem(model=model, mesh=rect_mesh, n=1, T=0.1, k=0.05, boundaries=roles,
                      traction=lambda x, t: ufl.as_vector((10.0 * t, 0.0)), params=params)


OWN = {
    "2.1 with a bilateral part": lambda: own("2.1", {"clamped": 1, "traction": 2,
                                                      "bilateral": 3}),
    "2.1 without contact": lambda: own("2.1", {"clamped": 1, "traction": 2}),
    "2.4 with coulomb": lambda: own("2.4", {"clamped": 1, "traction": 2, "coulomb": 3}),
    "2.3 without contact": lambda: own("2.3", {"clamped": 1, "traction": 2}),
}


def _finals(case, out, n=None):
    """(predicted names, the names of the run's final block) after one step."""
    comm = MPI.COMM_WORLD
    first = Run.prepare(case, out, n=n, progress=False, figures=False, comm=comm)
    k = first.configured.time.k
    r = Run.prepare(case, out, n=n, k=k, T=k, progress=False, figures=False, comm=comm)
    c = r.configured
    predicted = final_scalar_names(c, c.make_geometry(comm, c.n, c.h), comm)
    for _ in r.steps():
        pass
    final = [key for key, value in r.summary["final"].items()
             if isinstance(value, (int, float)) and not isinstance(value, bool)]
    return predicted, final


@pytest.mark.parametrize("example", list(EXAMPLES))
def test_catalogue_scalars_known_before_the_run(example, tmp_path):
    predicted, final = _finals(example, tmp_path / "o", EXAMPLES[example])
    assert sorted(predicted) == sorted(final)
    assert len(set(predicted)) == len(predicted)


def test_every_model_of_the_package_is_covered():
    models = {catalogue()[e].model_id for e in EXAMPLES}
    assert models == {ex.model_id for ex in catalogue().values()}


@pytest.mark.parametrize("name", list(OWN))
def test_own_problem_scalars_known_before_the_run(name, tmp_path):
    predicted, final = _finals(OWN[name](), tmp_path / "o")
    assert sorted(predicted) == sorted(final)


def test_sweep_refuses_an_unknown_plot_before_any_work(tmp_path):
    out = tmp_path / "s"
    with pytest.raises(dd.InputError, match="'bogus' is not one of the final scalars"):
        dd.sweep("2.1-ex2a", out, {"kappa": [1.0, 2.0]}, T=0.02, plot="bogus", progress=False)
    assert not out.exists()
    cmd = [sys.executable, "-m", "damage_dolfinx.cli", "sweep", "2.1-ex1", "--n", "5", "--k",
           "0.25", "--set", "kappa=1,2", "--plot", "bogus", "--out", str(out)]
    proc = subprocess.run(cmd, env=ENV, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.strip().count("\n") == 0 and "reports: u_L2" in proc.stderr
    assert proc.stdout == "" and not out.exists()


def _drawn(monkeypatch, name):
    """Capture the figure a study plot hands to ``figstyle.<name>`` (drawn, before it is
    saved and closed): its axes, legend texts, all visible text boxes."""
    import matplotlib.text
    from damage_dolfinx.viz import figstyle
    seen = {}
    original = getattr(figstyle, name)

    def capture(fig, path, *args, **kwargs):
        fig.canvas.draw()
        renderer = fig.canvas.get_renderer()
        ax = fig.axes[0]
        legend = ax.get_legend()
        hidden = set()  # labels of ticks outside the view: kept by matplotlib, not drawn
        for axis in (ax.xaxis, ax.yaxis):
            lo, hi = sorted(axis.get_view_interval())
            for tick in axis.get_major_ticks() + axis.get_minor_ticks():
                if not lo * (1 - 1e-9) <= tick.get_loc() <= hi * (1 + 1e-9):
                    hidden.update({id(tick.label1), id(tick.label2)})
        texts = [t for t in fig.findobj(matplotlib.text.Text)
                 if t.get_visible() and t.get_text().strip() and id(t) not in hidden]
        seen.update(ax=dict(xscale=ax.get_xscale(), yscale=ax.get_yscale(),
                            xlabel=ax.get_xlabel(), ylabel=ax.get_ylabel(),
                            title=ax.get_title() or (fig._suptitle.get_text()
                                                     if fig._suptitle else "")),
                    legend=[t.get_text() for t in legend.get_texts()] if legend else [],
                    legend_box=legend.get_window_extent(renderer) if legend else None,
                    axes_box=ax.get_window_extent(renderer),
                    boxes=[(t.get_text(), t.get_window_extent(renderer)) for t in texts],
                    sizes=[t.get_fontsize() for t in texts])
        return original(fig, path, *args, **kwargs)
    monkeypatch.setattr(figstyle, name, capture)
    return seen


def _no_text_over_text(boxes):
    """No two visible texts of the figure overlap (a pixel of contact allowed)."""
    clash = []
    for i, (a, ba) in enumerate(boxes):
        for b, bb in boxes[i + 1:]:
            if (min(ba.x1, bb.x1) - max(ba.x0, bb.x0) > 1
                    and min(ba.y1, bb.y1) - max(ba.y0, bb.y0) > 1):
                clash.append((a, b))
    return clash


def _session():
    import matplotlib
    return matplotlib.get_backend(), dict(matplotlib.rcParams)


def test_convergence_plot_reads_as_a_convergence_plot(tmp_path, monkeypatch):
    """Errors of a known order (0.8 in h + k on every line): the legend prints slope 0.80 for
    every time step and the fit, a reference slope is drawn, both axes are logarithmic and
    named, the legend lies under the axes, no text covers another and the session's backend
    and rcParams are unchanged."""
    import math
    from damage_dolfinx.studies import convergence_tables as tables
    rows = [dict(n=n, h=5 * math.sqrt(2) / n, k=k, h_plus_k=5 * math.sqrt(2) / n + k,
                 error=0.03 * (5 * math.sqrt(2) / n + k) ** 0.8)
            for n in (5, 10, 20) for k in (0.1, 0.05, 0.025)]
    rates = tables.fitted_rates(rows, [5, 10, 20], [0.1, 0.05, 0.025])
    seen = _drawn(monkeypatch, "save_as_laid_out")
    before = _session()
    tables.plot_convergence(tmp_path / "convergence.png", rows, rates, "2.1-ex1", 40, 0.0125,
                            "max_n (||u - u_hk||_V + ||zeta - zeta_hk||_L2)",
                            title="2.1-ex1: a title long enough to be wrapped over two lines "
                                  "of the column")
    assert _session() == before
    assert (tmp_path / "convergence.png").stat().st_size > 1000
    assert seen["ax"]["xscale"] == seen["ax"]["yscale"] == "log"
    assert "$h + k$" in seen["ax"]["xlabel"] and "\\Vert" in seen["ax"]["ylabel"]
    assert seen["legend"] == [f"$k$ = {k:g}: slope 0.80" for k in (0.1, 0.05, 0.025)] + [
        "fit, all cells: slope 0.80", "reference slope 1"]
    assert "reference $n$ = 40, $k$ = 0.0125" in seen["ax"]["title"]
    assert seen["legend_box"].y1 <= seen["axes_box"].y0  # under the axes, off the data
    assert not _no_text_over_text(seen["boxes"]), _no_text_over_text(seen["boxes"])
    assert min(seen["sizes"]) >= 6.5  # legible in a journal column at 300 dpi
    assert [t for t, _ in seen["boxes"]].count("1") == 2  # the triangle's legs, labelled


def test_sweep_plot_names_its_quantities(tmp_path, monkeypatch):
    """sweep.png: the swept parameter and the scalar named by what they are (symbol and
    --set name), a log axis over a decade, a tick at every swept value, one line per value of
    the other parameter named in a legend under the axes, no text over text, the session
    untouched."""
    from damage_dolfinx.studies.sweep_folder import plot_sweep
    grid = {"kappa": [0.01, 0.1, 1.0], "lam_u_plus": [500.0, 1000.0]}
    rows = [dict(kappa=a, lam_u_plus=b, zeta_min=1 - b * 1e-7 / (1 + a))
            for a in grid["kappa"] for b in grid["lam_u_plus"]]
    seen = _drawn(monkeypatch, "save")
    before = _session()
    plot_sweep(tmp_path / "sweep.png", rows, grid, "zeta_min", "2.1-ex1")
    assert _session() == before
    ax = seen["ax"]
    assert ax["xscale"] == "log" and ax["yscale"] == "linear"
    assert ax["xlabel"] == "damage diffusion $\\kappa$ (kappa)"
    assert "min $\\zeta$" in ax["ylabel"] and "zeta_min" in ax["ylabel"]
    assert seen["legend"] == ["$\\lambda_u^+$ = 500", "$\\lambda_u^+$ = 1000"]
    assert seen["legend_box"].y1 <= seen["axes_box"].y0
    labels = [t for t, _ in seen["boxes"]]
    assert {"0.01", "0.1", "1"} <= set(labels)
    assert not _no_text_over_text(seen["boxes"]), _no_text_over_text(seen["boxes"])
    assert (tmp_path / "sweep.png").stat().st_size > 1000

"""The history figure of every run: every history.csv column with a number in it is drawn, one
panel per group, without touching the session's matplotlib backend or rcParams."""
import sys

import numpy as np


def _csv(path):
    t = np.linspace(0, 1, 11)
    cols = {"step": np.arange(11), "t": t, "u_L2": t, "eps_u_L2": 2 * t, "zeta_min": 1 - t / 2,
            "zeta_max": np.ones(11), "zeta_mean": 1 - t / 4, "damage_its": np.ones(11),
            "mech_its": [""] * 11, "snes_its": np.full(11, 3), "step_time_s": t / 100,
            "contact_force_x": -t, "contact_force_y": t, "probe": t ** 2}
    lines = [",".join(cols)] + [",".join(str(cols[c][i]) for c in cols) for i in range(11)]
    path.write_text("\n".join(lines) + "\n")


def test_groups_and_session_untouched(tmp_path):
    import matplotlib
    from damage_dolfinx.viz.history_figure import plot_run_history
    _csv(tmp_path / "history.csv")
    backend, rc = matplotlib.get_backend(), dict(matplotlib.rcParams)
    had_pyplot = "matplotlib.pyplot" in sys.modules
    groups = dict(plot_run_history(tmp_path / "history.csv", tmp_path / "history.png", "x"))
    assert groups == {"zeta": ["zeta_min", "zeta_mean", "zeta_max"], "u_L2": ["u_L2"],
                      "eps_u_L2": ["eps_u_L2"], "its": ["damage_its", "snes_its"],
                      "step_time_s": ["step_time_s"],
                      "contact_force": ["contact_force_x", "contact_force_y"], "probe": ["probe"]}
    assert (tmp_path / "history.png").stat().st_size > 20_000
    assert matplotlib.get_backend() == backend and dict(matplotlib.rcParams) == rc
    assert had_pyplot or "matplotlib.pyplot" not in sys.modules


def test_no_history_no_figure(tmp_path):
    from damage_dolfinx.viz.history_figure import plot_run_history
    (tmp_path / "history.csv").write_text("step,t\n")
    assert plot_run_history(tmp_path / "history.csv", tmp_path / "h.png") == []
    assert not (tmp_path / "h.png").exists()

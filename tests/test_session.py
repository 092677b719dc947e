"""The package leaves the user's session alone: a run with figures changes neither the
matplotlib backend nor any rcParam, and neither the import nor a run configures the root
logger (handlers, level, warnings capture); the user's own log lines appear. Each check is
shown to fail on a planted side effect (the old global style: figstyle.pyplot_styled)."""
import subprocess
import sys
import textwrap

from conftest import ENV

SCRIPT = textwrap.dedent(r"""
    import logging, sys, warnings
    import matplotlib
    matplotlib.use("svg")                      # the user's backend (not Agg)
    matplotlib.rcParams["font.size"] = 13.0    # and style
    matplotlib.rcParams["figure.dpi"] = 77.0

    def state():
        root = logging.getLogger()
        return (matplotlib.get_backend(), dict(matplotlib.rcParams), list(root.handlers),
                root.level, list(root.filters),
                getattr(logging, "_warnings_showwarning", None) is not None)

    before = state()
    import damage_dolfinx as dd
    assert state() == before, "import damage_dolfinx changed the session"
    out = sys.argv[1]
    dd.run("2.1-ex1", out + "/a", n=5, T=0.05, overwrite=True, progress=False)  # figures on
    after = state()
    assert after[0] == before[0], f"backend {before[0]} -> {after[0]}"
    changed = sorted(k for k in before[1] if before[1][k] != after[1][k])
    assert not changed, f"rcParams changed: {changed}"
    assert after[2:] == before[2:], f"root logger changed: {before[2:]} -> {after[2:]}"
    assert not logging.getLogger().handlers        # FFCx's basicConfig at import undone
    logging.basicConfig(level=logging.INFO, format="USER %(message)s", stream=sys.stdout)
    logging.info("my own line")                    # the user's configuration takes effect
    configured = state()
    dd.run("2.1-ex1", out + "/b", n=5, T=0.05, overwrite=True, progress=False)
    assert state()[2:] == configured[2:], "a run changed the configured root logger"
    logging.info("my second line")
    # planted: the old global style is caught by the same comparison
    from damage_dolfinx.viz import figstyle
    figstyle.pyplot_styled()
    planted = state()
    assert planted[0] != before[0] and planted[1] != before[1], "the check cannot fail"
    print("SESSION OK")
""")


def test_run_leaves_matplotlib_and_logging_alone(tmp_path):
    env = {k: v for k, v in ENV.items() if k != "MPLBACKEND"}
    proc = subprocess.run([sys.executable, "-c", SCRIPT, str(tmp_path)], env=env,
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    assert "SESSION OK" in proc.stdout
    assert "USER my own line" in proc.stdout and "USER my second line" in proc.stdout
    assert (tmp_path / "a" / "fields_final.png").is_file()  # the figures were drawn


def test_cli_log_level_and_quiet():
    """--log-level sets the package logger's level for the command (root untouched)."""
    from damage_dolfinx.cli import main
    import logging
    root = logging.getLogger()
    handlers, level = list(root.handlers), root.level
    assert main(["list", "--log-level", "debug"]) == 0
    assert list(root.handlers) == handlers and root.level == level
    assert not [h for h in logging.getLogger("damage_dolfinx").handlers
                if not isinstance(h, logging.NullHandler)]  # the command's handler removed

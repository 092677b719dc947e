"""The command line of the field (-h with defaults, --version, show ID), plugins found as a
file, a module of the current folder or a module on the path, a plugin's model run by id
(run, converge, sweep), and PETSc options from scripts checked like the command line's."""
import json
import os
import subprocess
import sys
import textwrap
import warnings

import pytest

from conftest import ENV, tool_lines

PLUGIN = textwrap.dedent('''
    import ufl
    import damage_dolfinx as dd
    from damage_dolfinx.geometries.rectangle import rectangle, side


    @dd.register_model
    class PluginElastic(dd.model_class("2.1")):
        id = "plugin-elastic"
        title = "model 2.1 on a bar, from a plugin"

        @classmethod
        def example(cls):
            def bar(comm, n):
                return rectangle(comm, (0, 0), (1, 0.25), 4 * n, n,
                                 {1: side(0, 0.0), 2: side(0, 1.0)})
            return dd.Problem(model=cls, mesh=bar, n=2, T=0.1, k=0.05, name=cls.id,
                              boundaries={"clamped": 1, "traction": 2},
                              traction=lambda x, t: ufl.as_vector((t, 0.0)))
''')


def cli(args, cwd, plugins=None):
    env = {k: v for k, v in ENV.items() if k not in ("PYTHONPATH", "DAMAGE_DOLFINX_PLUGINS")}
    if plugins:
        env["DAMAGE_DOLFINX_PLUGINS"] = plugins
    exe = os.path.join(os.path.dirname(sys.executable), "damage-dolfinx")
    return subprocess.run([exe, *args], cwd=cwd, env=env, capture_output=True, text=True,
                          timeout=300)


def test_help_version_and_show(tmp_path):
    top = cli(["-h"], tmp_path)
    assert top.returncode == 0 and top.stdout.startswith("usage: damage-dolfinx")
    assert "show" in top.stdout and "--version" in top.stdout
    run = cli(["run", "-h"], tmp_path)
    assert run.returncode == 0
    assert "(default: 120.0)" in run.stdout  # --checkpoint-seconds
    assert "--log-level" in run.stdout and "(default: warning)" in run.stdout
    assert "default: (" not in run.stdout and "(default: None)" not in run.stdout
    assert cli(["--version"], tmp_path).stdout.strip().startswith("damage-dolfinx 0.")
    size = cli(["run", "2.1-ex2a", "-h", "0.5", "--out", "x"], tmp_path)
    assert size.returncode == 2 and "did you mean --h?" in size.stderr
    show = cli(["show", "2.1-ex1", "--set", "kappa=0.5"], tmp_path)
    assert show.returncode == 0, show.stderr
    assert "n = 20 cells per side" in show.stdout and "k = 0.01, T = 1, 100 steps" in show.stdout
    assert "kappa             = 0.5" in show.stdout
    assert not (tmp_path / "x").exists()


def test_plugin_file_module_and_model_id(tmp_path):
    (tmp_path / "my_plugin.py").write_text(PLUGIN)
    bad = cli(["run", "plugin-elastic", "--out", "r0"], tmp_path)
    assert bad.returncode == 2 and "unknown example id 'plugin-elastic'" in bad.stderr
    as_file = cli(["run", "plugin-elastic", "--plugin", "./my_plugin.py", "--quiet",
                   "--no-figures", "--out", "r1"], tmp_path)
    assert as_file.returncode == 0, as_file.stderr
    summary = json.loads((tmp_path / "r1" / "summary.json").read_text())
    assert summary["status"] == "completed" and summary["num_steps"] == 2
    listed = cli(["list"], tmp_path, plugins="my_plugin")  # a module of the current folder
    assert listed.returncode == 0, listed.stderr
    assert "plugin-elastic [registered] model 2.1 on a bar" in listed.stdout
    conv = cli(["converge", "plugin-elastic", "--plugin", "my_plugin", "--ref-n", "4",
                "--ref-k", "0.05", "--n", "1", "2", "--k", "0.05", "--quiet", "--out", "c"],
               tmp_path)
    assert conv.returncode == 0, conv.stderr
    assert json.loads((tmp_path / "c" / "summary.json").read_text())["errors"]
    sweep = cli(["sweep", "plugin-elastic", "--plugin", "./my_plugin.py", "--set",
                 "kappa=0.5,1", "--no-figures", "--quiet", "--out", "s"], tmp_path)
    assert sweep.returncode == 0, sweep.stderr
    assert len((tmp_path / "s" / "sweep.csv").read_text().splitlines()) == 3
    missing = cli(["list", "--plugin", "./nowhere.py"], tmp_path)
    assert missing.returncode == 2 and "does not exist" in missing.stderr
    nomodule = cli(["list"], tmp_path, plugins="no_such_plugin_module")
    assert nomodule.returncode == 2 and "cannot be imported" in nomodule.stderr


def test_a_model_id_where_an_example_id_belongs(tmp_path):
    """A model id is not an example id: the message says which it is and what runs it, for the
    package's models and for a registered model of one's own without example()."""
    (tmp_path / "bare_model.py").write_text(textwrap.dedent('''
        import damage_dolfinx as dd

        @dd.register_model
        class Bare(dd.model_class("2.1")):
            id = "bare"
    '''))
    own = cli(["run", "bare", "--plugin", "./bare_model.py", "--out", "r"], tmp_path)
    assert own.returncode == 2 and own.stderr.count("\n") == 1, own.stderr
    assert "'bare' is a registered model without an example" in own.stderr
    assert "classmethod example()" in own.stderr
    package = cli(["show", "2.4-nc"], tmp_path)
    assert package.returncode == 2 and package.stderr.count("\n") == 1, package.stderr
    assert "'2.4-nc' is a model id, not an example id" in package.stderr
    assert not (tmp_path / "r").exists()


def test_baselines_plugin_from_the_checkout():
    """The README's command: DAMAGE_DOLFINX_PLUGINS=reproduction.baselines from the checkout."""
    repo = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    proc = cli(["list"], repo, plugins="reproduction.baselines")
    assert proc.returncode == 0, proc.stderr


def test_petsc_options_of_the_api(tmp_path):
    import damage_dolfinx as dd
    from petsc4py import PETSc
    kw = dict(n=5, T=0.05, progress=False, figures=False)
    with pytest.raises(dd.InputError, match="unknown option -mehc_ksp_type: not a PETSc option"):
        dd.run("2.1-ex1", tmp_path / "a", petsc_options={"mehc_ksp_type": "cg"}, **kw)
    with pytest.raises(dd.InputError, match="PETSc refuses the options -mech_ksp_type nonsense"):
        dd.run("2.1-ex1", tmp_path / "a", petsc_options={"-mech_ksp_type": "nonsense"}, **kw)
    with pytest.raises(dd.InputError, match="mapping"):
        dd.converge("2.1-ex1", tmp_path / "a", n=[5], k=[0.05], ref_n=10, ref_k=0.05,
                    petsc_options="-mech_ksp_type cg")
    assert not (tmp_path / "a").exists()  # refused before any work
    opts = PETSc.Options()
    opts["mech_ksp_rtol"] = "1e-3"  # the user's own value, restored after the call

    def friction_ksp_type():  # a model run earlier in this process may have put its default
        return opts.getString("friction_ksp_type") if opts.hasName("friction_ksp_type") else None
    before = friction_ksp_type()
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            summary = dd.run("2.1-ex1", tmp_path / "b", **kw, petsc_options={
                "mech_ksp_rtol": 1e-12, "friction_ksp_type": "cg"})
        assert summary["status"] == "completed"
        messages = [str(w.message) for w in caught if "PETSc option" in str(w.message)]
        assert messages == ["no solver of this run read the PETSc option(s) "
                            "-friction_ksp_type: they had no effect"]
        assert opts.getString("mech_ksp_rtol") == "1e-3"
        assert friction_ksp_type() == before  # the database as it was before the call
    finally:
        opts.delValue("mech_ksp_rtol")
    got = dd.petsc_options_from_argv(["--n", "5", "-mech_ksp_type", "cg", "-damage_snes_monitor",
                                      "-log_view", "out.txt", "extra"])
    assert got == {"mech_ksp_type": "cg", "damage_snes_monitor": "", "log_view": "out.txt"}
    with pytest.raises(dd.InputError, match="unknown option -mehc_ksp_type"):
        dd.petsc_options_from_argv(["-mehc_ksp_type", "cg"])


def test_petsc_options_set_by_hand_are_checked(tmp_path):
    """Options a script puts into PETSc.Options() itself meet the command line's checks when a
    call starts: a misspelt prefix and a bad value are refused with one line before any work
    (no folder), an unread option is warned about; a prefix that is nobody's near-miss (the
    script's own solver) and the package's own defaults are left alone."""
    import damage_dolfinx as dd
    from petsc4py import PETSc
    kw = dict(n=5, T=0.05, progress=False, figures=False)
    opts = PETSc.Options()
    refused = {"mehc_ksp_type": ("cg", "unknown PETSc option -mehc_ksp_type in the options "
                                       "database.*did you mean -mech_ksp_type\\?"),
               "dmage_snes_monitor": ("", "did you mean -damage_snes_monitor"),
               "mech_ksp_type": ("nonsense", "PETSc refuses the options -mech_ksp_type "
                                             "nonsense \\(set in the PETSc options database\\)")}
    for name, (value, message) in refused.items():
        opts[name] = value
        try:
            with pytest.raises(dd.InputError, match=message) as caught:
                dd.run("2.1-ex1", tmp_path / "a", **kw)
            assert "\n" not in str(caught.value)
            with pytest.raises(dd.InputError, match=message):
                dd.sweep("2.1-ex1", tmp_path / "a", {"kappa": [1.0, 2.0]}, n=5, T=0.05,
                         progress=False)
        finally:
            opts.delValue(name)
        assert not (tmp_path / "a").exists()  # refused before any work
    opts["mech_snes_nonsense_flag"] = "1"  # under a package prefix: read by no solver
    opts["p_ksp_type"] = "cg"              # the script's own solver: not a near-miss
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            assert dd.run("2.1-ex1", tmp_path / "b", **kw)["status"] == "completed"
            assert dd.run("2.1-ex1", tmp_path / "c", **kw)["status"] == "completed"
        messages = [str(w.message) for w in caught if "PETSc option" in str(w.message)]
        assert messages == ["no solver of this run read the PETSc option(s) "
                            "-mech_snes_nonsense_flag (set in the PETSc options database "
                            "before the call): they had no effect"] * 2  # defaults not named
        assert opts.getString("mech_snes_nonsense_flag") == "1"  # the user's: kept
    finally:
        opts.delValue("mech_snes_nonsense_flag")
        opts.delValue("p_ksp_type")

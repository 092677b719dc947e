"""The layer contract (tests/layers.py): every folder of the installed package imports only the
floors below it, no import runs across one floor's folders, no circle, nothing loose at the
package root but its face; and the check fails on a planted upward import."""
import layers


def test_the_package_keeps_its_floors():
    all_edges = layers.edges()
    assert layers.upward(all_edges) == []
    assert layers.circles(all_edges) == []
    modules = layers.package_files()
    roots = {m for m in modules if m.count(".") == 1}
    folders = {n for names in layers.LAYERS for n in names}
    assert {layers.folder(m) for m in roots} <= folders, "a loose module at the package root"
    assert {layers.folder(m) for m in modules} <= folders, "a folder with no floor"


def test_a_planted_upward_import_is_caught():
    planted = [("damage_dolfinx.core.tags", "damage_dolfinx.runtime.loop", 1)]
    bad = layers.upward(layers.edges(extra=planted))
    assert [(a, b) for a, b, *_ in bad] == [("damage_dolfinx.core.tags",
                                             "damage_dolfinx.runtime.loop")]


def test_a_planted_import_across_one_floor_and_a_circle_are_caught():
    across = [("damage_dolfinx.studies.sweep", "damage_dolfinx.catalogue.examples", 1)]
    assert layers.upward(layers.edges(extra=across))
    loop = [("damage_dolfinx.core.tags", "damage_dolfinx.core.parameters", 1),
            ("damage_dolfinx.core.parameters", "damage_dolfinx.core.tags", 1)]
    assert ["damage_dolfinx.core.parameters", "damage_dolfinx.core.tags"] in \
        layers.circles(layers.edges(extra=loop))


def test_the_face_is_the_only_module_at_the_root_and_old_names_warn():
    import importlib
    import warnings
    import damage_dolfinx as dd
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        old = importlib.import_module("damage_dolfinx.blocks")
    assert old is importlib.import_module("damage_dolfinx.models.blocks")
    assert any("damage_dolfinx.models.blocks" in str(w.message) for w in seen)
    assert dd.blocks is old and dd.Problem.__module__ == "damage_dolfinx.problem.problem"

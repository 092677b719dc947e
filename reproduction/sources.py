"""Where the report's data come from: the figure runs (``<results>/figures/index.json``, full
resolution, else ``figures-quick``), the convergence studies (``<results>/convergence/<study>/``
if present, else the committed outputs in ``benchmarks/reference_output/convergence/``), the
thesis tables beside ours (benchmarks/reproduction/fidelity.py) and the bridge summary.
"""
from __future__ import annotations

import json
import re
from pathlib import Path

from reproduction.records import REFERENCE, REPO


def _load_json(path: Path):
    return json.loads(path.read_text()) if path.is_file() else None


def _figures_index(results: Path):
    for name in ("figures", "figures-quick"):
        index = _load_json(results / name / "index.json")
        if index:
            return results / name, index
    return None, None


def _study_folder(results: Path, name: str):
    for folder in (results / "convergence" / name, REFERENCE / "convergence" / name,
                   REFERENCE / "convergence" / f"{name}-reduced"):
        if (folder / "errors.md").is_file():
            return folder
    return None


def _fidelity(results: Path):
    """benchmarks/reproduction/fidelity.py's comparison and the function writing
    ``fidelity.json`` / ``fidelity.md`` (returning the Markdown); ({"tables": []}, None) if the
    script is absent. The report writes them once its record holds every verdict."""
    import importlib.util
    script = REPO / "benchmarks" / "reproduction" / "fidelity.py"
    if not script.is_file():
        return {"tables": []}, None
    spec = importlib.util.spec_from_file_location("damage_dolfinx_fidelity", script)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)

    def write(result, folder):
        module.write(result, folder)
        return (folder / "fidelity.md").read_text()
    return module.compare(results), write


class Figures:
    """Where each PNG comes from: the full-resolution run if it has it, else the quick run
    (marked), with the panel data (.npz) of field figures for the verdicts."""

    def __init__(self, results: Path):
        self.sources = []
        for name, mode in (("figures", "full"), ("figures-quick", "quick")):
            index = _load_json(results / name / "index.json")
            if index:  # the mode the runs were made in (a quick run may sit in figures/)
                self.sources.append((results / name, index, index.get("mode", mode)))
        self.results = results

    def find(self, file):
        """(png path, mode, npz path or None, index entry) of the best source, or None."""
        for folder, index, mode in self.sources:
            if (folder / file).is_file():
                entry = next((f for f in index["figures"] if f["file"] == file), {})
                return folder / file, mode, self._npz(folder, index, entry), entry
        return None

    def _npz(self, folder, index, entry):
        run = next((r for r in index["runs"] if r["example"] == entry.get("example")
                    and r["variant"] == entry.get("variant")), None)
        if run is None or not entry.get("source"):
            return None
        for base in (Path(run["folder"]), folder / "runs" / Path(run["folder"]).name):
            npz = base / Path(entry["source"]).with_suffix(".panel.npz")
            if npz.is_file():
                return npz
        return None

    def run_folder(self, entry):
        """The run folder behind a figure entry of an index (None if unknown)."""
        for folder, index, _ in self.sources:
            run = next((r for r in index["runs"] if r["example"] == entry.get("example")
                        and r["variant"] == entry.get("variant")), None)
            if run:
                for base in (Path(run["folder"]), folder / "runs" / Path(run["folder"]).name):
                    if base.is_dir():
                        return base
        return None

    def runs(self, example):
        return [(mode, r) for _, index, mode in self.sources[:1] for r in index["runs"]
                if r["example"] == example]

    def extra(self, example, thesis_files):
        """Non-thesis PNGs of an example (best source only), without the other variants'
        copies of a thesis figure (e.g. the Coulomb run's copy of the setting 2.22)."""
        stems = {re.sub(r"_(tresca|coulomb|undamaged|damaged|a|b)$", "", Path(f).stem)
                 for f in thesis_files}
        for folder, index, mode in self.sources[:1]:
            return [(folder / f["file"], f) for f in index["figures"] if f["example"] == example
                    and f["file"] not in thesis_files and (folder / f["file"]).is_file()
                    and re.sub(r"_(tresca|coulomb|undamaged|damaged|a|b)$", "",
                               Path(f["file"]).stem) not in stems]
        return []


def _convergence_png(results: Path, example, variant):
    name = example + (f"-{variant}" if variant else "")
    folder = _study_folder(results, name)
    return folder / "convergence.png" if folder and (folder / "convergence.png").is_file() else None


def _bridge_summary(results: Path):
    for path in (results / "figures" / "runs" / "bridge_collapse" / "bridge_summary.json",
                 results / "figures-quick" / "runs" / "bridge_collapse" / "bridge_summary.json",
                 REFERENCE / "bridge" / "bridge_summary.json"):
        s = _load_json(path)
        if s:
            return s, path
    return None, None

"""A notebook that uses the package as a Jupyter user does, executed headlessly (nbclient,
Debian's python3-nbclient and python3-ipykernel): ``%matplotlib inline``, the user's logging,
``dd.run``, then the user's own plot. Checks that the plot is an inline image, that the user's
log line appears, and that the backend is the same before and after the run.

    python benchmarks/platforms/notebook_session.py [--out DIR]   (writes DIR/session.ipynb)

Needs nbclient, nbformat and ipykernel (Debian's python3-nbclient, python3-nbformat and
python3-ipykernel; `make setup` installs them on Debian 12).
"""
import argparse
import json
import os
import sys


CELLS = [
    """%matplotlib inline
import logging, matplotlib
logging.basicConfig(level=logging.INFO, format="USER-LOG %(message)s")
print("backend before:", matplotlib.get_backend())""",
    """import damage_dolfinx as dd
summary = dd.run("2.1-ex1", "nb-run", n=5, T=0.05, overwrite=True, progress=False)
logging.info("my own log line: the run %s", summary["status"])
print("backend after:", matplotlib.get_backend())""",
    """import matplotlib.pyplot as plt
run = dd.read_run("nb-run")
plt.plot(run.history["t"], run.history["zeta_min"], "o-")
plt.xlabel("t"); plt.ylabel("min zeta")
plt.show()""",
]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="results/notebook-session")
    args = ap.parse_args()
    import nbformat  # here: --help works where nbclient is not installed
    from nbclient import NotebookClient
    os.makedirs(args.out, exist_ok=True)
    # a kernel of this interpreter (the one that sees the package: its venv), found through
    # JUPYTER_PATH
    spec = os.path.join(os.path.abspath(args.out), "kernels", "kernels", "this-python")
    os.makedirs(spec, exist_ok=True)
    with open(os.path.join(spec, "kernel.json"), "w") as f:
        json.dump({"argv": [sys.executable, "-m", "ipykernel_launcher", "-f",
                            "{connection_file}"], "display_name": "this python",
                   "language": "python"}, f)
    os.environ["JUPYTER_PATH"] = os.path.join(os.path.abspath(args.out), "kernels")
    nb = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell(c) for c in CELLS])
    NotebookClient(nb, timeout=600, kernel_name="this-python",
                   resources={"metadata": {"path": args.out}}).execute()
    nbformat.write(nb, os.path.join(args.out, "session.ipynb"))
    texts = ["".join(o.get("text", "") for o in cell.outputs) for cell in nb.cells]
    images = [o for o in nb.cells[2].outputs if "image/png" in o.get("data", {})]
    before = next(l for l in texts[0].splitlines() if l.startswith("backend before:")).split(": ")[1]
    after = next(l for l in texts[1].splitlines() if l.startswith("backend after:")).split(": ")[1]
    result = {"backend_before": before, "backend_after": after,
              "user_log_line": [l for l in texts[1].splitlines() if l.startswith("USER-LOG")],
              "inline_images": len(images),
              "image_bytes": len(images[0]["data"]["image/png"]) if images else 0}
    print(json.dumps(result, indent=1))
    ok = before == after and result["user_log_line"] and images
    print("NOTEBOOK", "PASS" if ok else "FAIL")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())

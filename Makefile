# damage-dolfinx: the two commands are `make demo` and `make test`; both run `setup` first.
SHELL := /bin/bash
VENV ?= .venv
PY := $(VENV)/bin/python
NP ?= 2
OUT ?= results
MPIRUN := mpirun -n $(NP)

# OpenMPI refuses root without these; oversubscribe lets -n 2 run on small CI runners.
export OMPI_ALLOW_RUN_AS_ROOT := 1
export OMPI_ALLOW_RUN_AS_ROOT_CONFIRM := 1
export OMPI_MCA_rmaps_base_oversubscribe := 1
# the same for OpenMPI 5 (PRRTE: Debian 13 and later)
export PRTE_MCA_rmaps_default_mapping_policy := :oversubscribe
# Every MPI process start (mpirun's ranks, and a serial `import dolfinx`) probes the network
# transports: under Open MPI 6 libfabric's providers (btl ofi) take about 1 s per process and
# UCX (pml ucx) another 0.1 s. The tests and demos run on one machine: shared memory and TCP
# (btl sm/vader, tcp, pml ob1) are what they use anyway. A value set outside is kept.
export OMPI_MCA_btl ?= ^ofi,uct
export OMPI_MCA_pml ?= ob1
export OMP_NUM_THREADS := 1
export MPLBACKEND := Agg

APT_PACKAGES := python3-dolfinx python3-petsc4py python3-mpi4py python3-ufl python3-basix \
    python3-ffcx python3-gmsh python3-h5py python3-meshio gmsh openmpi-bin python3-pytest python3-matplotlib python3-scipy \
    python3-venv python3-setuptools gcc chromium \
    python3-sphinx python3-myst-parser python3-sphinx-gallery furo libjs-mathjax \
    python3-nbclient python3-nbformat python3-ipykernel
# As root (containers, CI runners) apt-get runs directly; otherwise through sudo. `env` carries
# DEBIAN_FRONTEND through sudo and works without it (an empty $(SUDO) must not leave a bare flag).
SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)
APT := $(SUDO) env DEBIAN_FRONTEND=noninteractive apt-get

.PHONY: setup system-deps demo test docs check-fresh check-paraview test-platforms cross-version bench convergence convergence-quick figures figures-quick \
    report clean

# The package's modules byte-compiled (as a regular pip install does; an editable install writes
# no bytecode where PYTHONDONTWRITEBYTECODE is set, and every process then compiles its ~120
# modules from source, 0.15-0.3 s); only changed sources are compiled again.
setup: $(VENV)/.installed
	@$(PY) -m compileall -q damage_dolfinx forms geometries

# Install the Debian stack only if /usr/bin/python3 cannot already import it.
system-deps:
	@if /usr/bin/python3 -c "import dolfinx, petsc4py, mpi4py, ufl, basix, ffcx, gmsh, h5py, meshio, matplotlib, pytest, scipy, \
	    sphinx, myst_parser, sphinx_gallery, furo, nbclient, nbformat, ipykernel" \
	    2>/dev/null && command -v mpirun >/dev/null && command -v chromium >/dev/null \
	    && [ -f /usr/share/javascript/mathjax/MathJax.js ]; then \
	  echo "setup: Debian FEniCSx stack present"; \
	else \
	  echo "setup: installing the Debian FEniCSx stack (apt-get)"; \
	  $(APT) update && $(APT) install -y $(APT_PACKAGES); \
	fi

$(VENV)/.installed: pyproject.toml setup.py | system-deps
	/usr/bin/python3 -m venv --system-site-packages $(VENV)
	$(PY) -m pip install --quiet --no-build-isolation --no-deps -e .
	touch $@

# Real thesis examples end to end: Section 2.1 Example 2 at the thesis resolution (h = 0.1,
# k = 0.01; tension-only serially, compression-only on $(NP) ranks) and Example 1 at n = 40.
demo: setup
	$(PY) -m damage_dolfinx.cli run 2.1-ex2a --overwrite --out $(OUT)/demo/2.1-ex2a
	$(MPIRUN) $(PY) -m damage_dolfinx.cli run 2.1-ex2b --overwrite --out $(OUT)/demo/2.1-ex2b
	$(MPIRUN) $(PY) -m damage_dolfinx.cli run 2.1-ex1 --n 40 --k 0.005 --overwrite --out $(OUT)/demo/2.1-ex1
	@echo "demo output (XDMF for ParaView, PNG figures, CSV, summary.json) in $(OUT)/demo/"

test: setup
	$(PY) -m pytest -q -ra --durations=25 tests $(PYTEST_ARGS)

# The documentation site (Sphinx, furo theme, sphinx-gallery executing demos/*.py) into
# build/docs/html; warnings are errors. DOCS_BUILD and OUT (where `make report` wrote) can move it.
DOCS_BUILD ?= build/docs
docs: setup
	DAMAGE_DOLFINX_DOCS_BUILD=$(abspath $(DOCS_BUILD)) DAMAGE_DOLFINX_RESULTS=$(abspath $(OUT)) \
	    $(PY) -m sphinx -b html -W --keep-going -d $(DOCS_BUILD)/doctrees docs $(DOCS_BUILD)/html
	@echo "documentation in $(DOCS_BUILD)/html/index.html"

bench: setup
	$(MPIRUN) $(PY) benchmarks/performance/step_timing_2_1.py
	$(PY) benchmarks/performance/memory_cost_2_3.py
	$(PY) benchmarks/studies/friction_cpu_2_2.py
	$(MPIRUN) $(PY) benchmarks/studies/bridge_collapse.py
	$(PY) benchmarks/studies/bridge_sensitivity.py

# All convergence studies at thesis resolution, references on $(NP) ranks (make convergence NP=4).
convergence: setup
	$(PY) benchmarks/reproduction/convergence_all.py --np $(NP) --out $(OUT)/convergence $(if $(RESUME),--resume)

convergence-quick: setup
	$(PY) benchmarks/reproduction/convergence_all.py --quick --np $(NP) --out $(OUT)/convergence-quick $(if $(RESUME),--resume)

# Every thesis figure with a computed result (PNG named after the figure number).
figures: setup
	$(PY) benchmarks/reproduction/figures.py --np $(NP) --out $(OUT)/figures $(if $(RESUME),--resume)

figures-quick: setup
	$(PY) benchmarks/reproduction/figures.py --quick --np $(NP) --out $(OUT)/figures-quick $(if $(RESUME),--resume)

# $(OUT)/report/: REPORT.html with its images, REPORT.md and REPORT.pdf (headless Chromium), one
# folder that still works when moved or zipped.
report: setup
	$(PY) benchmarks/reproduction/report.py --results $(OUT) --pdf

# Platforms (root, debootstrap; roots cached in /var/cache/damage-dolfinx/roots, rebuilt when
# missing): the README's two commands in a bare Debian 12 minbase root (AS_USER=1: as a non-root
# sudoer); the test suite on Debian 13 / DOLFINx 0.9 and Debian unstable / DOLFINx 0.11; the
# same small run per problem on all three versions, compared.
check-fresh:
	bash platforms/check-fresh.sh

test-platforms:
	bash platforms/suite.sh trixie sid

cross-version:
	bash platforms/cross-version.sh $(OUT)/cross_version.md

# ParaView (python3-paraview, ~440 MB, installed here if missing) reads the XDMF of one small run
# per problem; arrays and time steps compared with the runs' own files, one frame rendered each.
check-paraview: setup
	@command -v pvpython >/dev/null && command -v xvfb-run >/dev/null || $(APT) install -y python3-paraview xvfb xauth
	$(PY) benchmarks/platforms/cross_version.py run --out $(OUT)/paraview-runs
	$(PY) -m damage_dolfinx.cli run 2.4-ex1 --n 8 --k 0.01 --T 0.5 --no-figures --quiet --overwrite \
	    --out $(OUT)/paraview-runs/restarted
	$(MPIRUN) $(PY) -m damage_dolfinx.cli run 2.4-ex1 --n 8 --k 0.01 --T 1 --restart --no-figures \
	    --quiet --out $(OUT)/paraview-runs/restarted
	$(PY) benchmarks/platforms/paraview_check.py $$(ls -d $(OUT)/paraview-runs/*/) --out $(OUT)/paraview-check

clean:
	rm -rf $(VENV) results .pytest_cache build *.egg-info docs/_generated docs/demos

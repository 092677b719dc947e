"""The public entry points behind the package's face: run, steps, converge, sweep, gather
(workflow.py) and read_run (results.py)."""

"""Run machinery: the time loop, the run folder, checkpoints, output files, signals, resource checks."""

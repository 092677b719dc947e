"""Studies built on runs: convergence against a fine reference."""

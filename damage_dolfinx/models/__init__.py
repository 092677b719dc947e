"""Time-stepping schemes, one module per thesis problem (Problem VP^{hk} of each section)."""

"""Thesis examples, one module per section; each defines examples() -> [Example]."""

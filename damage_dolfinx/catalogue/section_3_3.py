"""Catalogue entries of thesis Section 3.3 (being written)."""


def examples():
    return []

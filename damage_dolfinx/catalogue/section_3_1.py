"""Catalogue entries of thesis Section 3.1 (being written)."""


def examples():
    return []

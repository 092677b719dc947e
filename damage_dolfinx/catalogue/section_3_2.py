"""Catalogue entries of thesis Section 3.2 (being written)."""


def examples():
    return []

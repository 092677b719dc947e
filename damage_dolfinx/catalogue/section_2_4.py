"""Catalogue entries of thesis Section 2.4 (being written)."""


def examples():
    return []

"""damage-dolfinx: continuum damage in solid mechanics with DOLFINx (Campo 2007 thesis)."""
__version__ = "0.1.0"

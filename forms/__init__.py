"""UFL weak forms, one module per thesis problem (pure functions returning UFL forms)."""

"""The run description (:class:`Problem`), its stages and its checks."""


def __getattr__(name):
    # ``from damage_dolfinx.problem import Problem`` of earlier releases (problem.py was a module)
    if name in ("Problem", "MAX_STEPS", "READINGS"):
        import warnings
        from damage_dolfinx.problem import problem
        warnings.warn(f"damage_dolfinx.problem.{name} is now damage_dolfinx.problem.problem."
                      f"{name} (damage_dolfinx.{name} for Problem)", DeprecationWarning, stacklevel=2)
        return getattr(problem, name)
    raise AttributeError(f"module 'damage_dolfinx.problem' has no attribute {name!r}")

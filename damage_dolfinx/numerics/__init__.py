"""Numerics: constitutive maps, the damage step, contact and friction laws, solvers, time-step limits."""

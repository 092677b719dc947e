"""The ground floor: errors, parameters, the boundary tags, the geometry type and the argument
checks every layer uses. Imports nothing of the package above it."""

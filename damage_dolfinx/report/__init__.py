"""The thesis reproduction: figure and table runs, their checks, and the report document."""

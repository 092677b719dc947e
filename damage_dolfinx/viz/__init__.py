"""Figures: fields on the deformed configuration, the shared style, 3-D sections, hinge lines."""

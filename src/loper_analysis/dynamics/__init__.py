"""Inverse dynamics: the generalised forces (joint moments) of a model's coordinates, and their powers."""

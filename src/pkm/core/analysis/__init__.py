"""Analyses over many configurations: workspace and index maps, reconfiguration through redundant
parameters, the redundant-parameter optimiser."""

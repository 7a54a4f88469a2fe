"""Tests of pkm.cli, one module per module or command of the package."""

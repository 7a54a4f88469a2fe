"""Tests of pkm.viz, one module per module of the package."""

"""Sweep results in a Zarr store."""

"""The engine: one integration advanced call by call, the simulation driver, results."""

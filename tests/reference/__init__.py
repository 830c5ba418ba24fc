"""The slow reference implementation, written from the equations alone."""

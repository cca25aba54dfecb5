"""The cheap modes: fixed sub-steps, each resolving the overlaps found at its end (naive) or
reconstructing when they began (posteriori)."""

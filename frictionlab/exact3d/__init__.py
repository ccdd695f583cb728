"""The exact 3D law: xi against f for self-affine surfaces in exact elastic
half-space contact, converged in the grid, beside MDR's prediction on the same
surfaces (``frictionlab exact3d``, which writes docs/exact-3d-law.md)."""

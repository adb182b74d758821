"""nodeforce: locate the defective sub-models of a nodal building model by forcing its nodes."""

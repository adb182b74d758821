"""Running FMUs: the FMI plumbing (`fmi`) and the simulation of a measured case through it (`run`)."""

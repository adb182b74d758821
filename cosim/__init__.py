"""Running FMUs: the FMI plumbing (`fmi2`) and the simulation of a measured case through it (`run`)."""

"""Shared helpers of every model: physical constants (`constants`), input checks (`checks`),
quaternions and Euler angles (`rotations`), MRPs (`mrp`), the scenario epoch and Julian dates
(`time_utils`)."""

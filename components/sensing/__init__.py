"""Attitude sensing and determination: sensors with seeded noise (`sensors`), TRIAD (`triad`),
the sunline from ephemeris (`sunline`) and air-bearing attitude thresholding (`air_bearing`)."""

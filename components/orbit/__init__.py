"""Orbits and the de-orbit burn: Keplerian elements (`elements`), the Cowell propagator
(`cowell`), the orbit-averaged lifetime model (`averaged`), an analytic circular orbit
(`circular`) and the main de-orbit propulsion with the thesis' sizing (`propulsion`)."""

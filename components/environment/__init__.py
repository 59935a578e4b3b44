"""The space environment: Earth-fixed frame and geodesy (`geodesy`), zonal gravity (`gravity`),
the Sun (`sun`), Earth shadow (`eclipse`), the geomagnetic field (`magnetic_field`), space
weather (`space_weather`, with its data file in data/) and the atmosphere density models
(`atmosphere`)."""

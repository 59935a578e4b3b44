"""The NEIGHBOR mission: operating modes and phases (`modes`), the mission manager (`manager`),
the host's heartbeat (`host`), the ground station (`ground_station`), the power bus (`power_bus`)
and battery (`power`), and data storage and downlink (`data_storage`)."""

"""Attitude dynamics and control: the rigid body (`rigid_body`), the RCS thruster pairs
(`thrusters`, `thruster_control`), the thesis' detumble, slew and de-orbit tracking laws
(`detumble`, `slew`, `deorbit_tracking`), sun-avoidance guidance with its reference tracker
(`sun_avoidance`, `reference_tracking`) and the controller selector (`command_selector`)."""

"""The magnetorquer and momentum-wheel ACS of the ACS mode specification: the ten-mode manager
(`modes`), the per-mode control laws (`control`), the state signals (`signals`), torque coils
(`magnetorquer`), the momentum wheel (`momentum_wheel`), paddles (`paddles`) and the optical
tracker (`optical_tracker`)."""

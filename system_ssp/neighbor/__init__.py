"""The NEIGHBOR application on top of the master and the tools: the thesis' detumble and slew
cases (`thesis`), the de-orbit lifetime study (`deorbit_study`), the mission from deployment to
re-entry (`mission`), the propulsion budget (`propulsion_report`) and the table of every published
thesis number (`validation`). The mission itself (scenarios, spacecraft, systems, GNC sets, the
recorded signals) is defined once in `components.mission.neighbor`. Each command has a
`main(argv)` behind a subcommand of `neighbor-cosim` / `python -m system_ssp`."""

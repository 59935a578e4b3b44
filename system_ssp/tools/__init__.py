"""Generic tools for any SSP system of FMI co-simulation FMUs, nothing NEIGHBOR-specific:
`replace` (swap a component's FMU, checked; also `compare`), `flatten` (system parameters folded
into component bindings), `campaign` (sweeps and Monte Carlo on Dask), `fmu_reference` (a page
per FMU), and `console` (what every command shares). Each command has a `main(argv)` behind a
subcommand of `neighbor-cosim` / `python -m system_ssp`."""

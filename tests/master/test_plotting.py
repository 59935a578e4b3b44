"""Looking at a run (issue 29): Result.to_pandas and Result.plot, the `plot` command on CSV and
Parquet results (units read back), globs, the time axis in the unit that reads best, and bad
input refused with the closest names before any work."""
import json
import re

import matplotlib.image
import numpy as np
import pytest

import system_ssp
from system_ssp.cli import main
from system_ssp.master.plotting import read_result, time_axis


@pytest.fixture(scope="module")
def detumble(ssp_paths):
    return system_ssp.simulate(ssp_paths["detumble"])


def test_to_pandas_has_every_column_and_the_units(detumble):
    df = detumble.to_pandas()
    assert list(df.columns) == list(detumble.data.dtype.names)
    np.testing.assert_array_equal(df["dynamics.omega_BN_B[1]"].to_numpy(), detumble["dynamics.omega_BN_B[1]"])
    assert df.attrs["units"]["time"] == "s" and df.attrs["units"]["dynamics.omega_BN_B[1]"] == "rad/s"


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_a_written_result_reads_back_with_its_units(detumble, tmp_path, suffix):
    path = tmp_path / f"run{suffix}"
    detumble.write(path)
    columns, units = read_result(path)
    assert list(columns) == list(detumble.data.dtype.names)
    np.testing.assert_array_equal(columns["dynamics.q_BN[4]"], detumble["dynamics.q_BN[4]"])
    assert units == {n: detumble.units.get(n) for n in columns}


def test_plot_command_draws_globbed_signals_with_units(detumble, tmp_path, capsys):
    result = tmp_path / "run.csv"
    detumble.write(result)
    assert main(["plot", str(result), "dynamics.omega_BN_B*", "detumble.torque_cmd_B[[]1]"]) == 0
    assert "4 signal(s)" in capsys.readouterr().out
    image = matplotlib.image.imread(tmp_path / "run.png")
    assert image.shape[0] > 300 and image.std() > 0.05  # drawn, not blank
    assert main(["plot", str(result), "dynamics.q_BN*", "--out", str(tmp_path / "q.svg")]) == 0
    assert "dynamics.q_BN[4]" in (tmp_path / "q.svg").read_text()


def test_html_plot_is_one_file_that_needs_no_network(detumble, tmp_path):
    out = detumble.plot(["dynamics.omega_BN_B*"], tmp_path / "run.html", title="detumble")
    text = out.read_text()
    assert "dynamics.omega_BN_B[2]" in text and "rad\\u002fs" in text and "time (s)" in text  # plotly escapes /
    assert '<script src="http' not in text  # plotly.js is inside the page


def test_bad_signal_or_format_is_refused_with_the_closest_names(detumble, tmp_path, ssp_paths, capsys):
    result = tmp_path / "run.csv"
    detumble.write(result)
    assert main(["plot", str(result), "dynamics.omega_BN"]) == 2
    assert "did you mean 'dynamics.omega_BN_B[" in capsys.readouterr().err
    assert main(["plot", str(result), "--out", str(tmp_path / "x.jpg")]) == 2
    assert "unknown format '.jpg'" in capsys.readouterr().err
    assert main(["plot", str(tmp_path / "missing.csv")]) == 2
    # run --plot with a format it cannot write: refused before the run (no results written)
    assert main(["run", str(ssp_paths["detumble"]), "--output", str(tmp_path / "r.csv"), "--plot",
                 str(tmp_path / "r.pdf")]) == 2
    assert not (tmp_path / "r.csv").exists()


def test_run_plot_and_the_time_axis(ssp_paths, tmp_path, capsys):
    assert main(["run", str(ssp_paths["detumble"]), "--outputs", "dynamics.omega_BN_B[1]", "--plot",
                 str(tmp_path / "r.png")]) == 0
    assert (tmp_path / "r.png").stat().st_size > 10000
    assert time_axis(np.array([0.0, 40 * 3.15576e7]))[1] == "yr"
    assert time_axis(np.array([0.0, 5 * 86400.0]))[1] == "d"
    assert time_axis(np.array([0.0, 90.0]))[1] == "s"
    assert json.dumps(time_axis(np.array([0.0, 7200.0]))[1]) == '"h"'


def test_run_one_fmu_alone(fmu_paths, tmp_path, capsys):
    """`run MODEL.fmu` runs the FMU as a system of one (it used to answer 'malformed XML'); what it
    cannot know is asked for by name."""
    assert main(["run", str(fmu_paths["Gyro"]), "--stop-time", "1", "--step-size", "0.1", "--output",
                 str(tmp_path / "gyro.csv"), "--plot", str(tmp_path / "gyro.png")]) == 0
    out = capsys.readouterr().out
    assert "steps:       10 (h = 0.1 s" in out and "Gyro.omega_meas_B[1] =" in out
    assert re.search(r"Gyro.omega_meas_B\[1\] = \S+ rad/s\n", out)  # final values with their units
    columns, units = read_result(tmp_path / "gyro.csv")
    assert units["Gyro.omega_meas_B[1]"] == "rad/s" and len(columns["time"]) == 11
    assert (tmp_path / "gyro.png").is_file()
    assert main(["run", str(fmu_paths["Gyro"]), "--step-size", "0.1"]) == 2
    assert "Gyro.fmu: no stop time: pass --stop-time" in capsys.readouterr().err
    (tmp_path / "x.csv").write_text("time\n0\n")
    assert main(["run", str(tmp_path / "x.csv")]) == 2
    assert "expected a system (.ssp, .ssd, a folder with SystemStructure.ssd) or an FMU (.fmu)" \
        in capsys.readouterr().err
    assert main(["run", str(tmp_path)]) == 2  # a folder without a system: the master says so
    assert f"{tmp_path / 'SystemStructure.ssd'}: file not found" in capsys.readouterr().err


def test_thesis_says_which_case_did_not_finish(ssp_paths, capsys):
    """`thesis` says which case runs (--progress) and exits 1 naming each case that did not finish
    and why (it printed a bare "NO")."""
    assert main(["thesis", "--ssp-dir", str(ssp_paths["slew"].parent), "--slew-stop-time", "1", "--progress"]) == 1
    err = capsys.readouterr().err
    assert "thesis: detumble_case1\n" in err and "thesis: slew_case3_x\n" in err  # progress: which case runs
    assert "slew_case1: did not finish: its stop condition was still false at t = 1 s, the run's limit" in err
    assert "detumble_case1: did not finish" not in err  # the detumbles finish


COMMANDS = ("run", "info", "plot", "campaign", "thesis", "deorbit-study", "mission", "propulsion", "validation",
            "replace", "compare", "flatten")


def test_every_option_of_every_command_says_what_it_does(monkeypatch, capsys):
    """Each argument of each subcommand has a help text (many had none)."""
    import argparse

    silent = []
    original = argparse._ActionsContainer.add_argument

    def recording(self, *args, **kwargs):
        action = original(self, *args, **kwargs)
        if action.help is None and not isinstance(action, (argparse._HelpAction, argparse._SubParsersAction,
                                                           argparse._VersionAction)):
            silent.append(f"{getattr(self, 'prog', '?')} {'/'.join(action.option_strings) or action.dest}")
        return action

    monkeypatch.setattr(argparse._ActionsContainer, "add_argument", recording)
    for command in COMMANDS:
        assert main([command, "--help"]) == 0
    capsys.readouterr()
    assert silent == []


def test_bad_stop_conditions_times_and_output_places_are_refused_up_front(ssp_paths, tmp_path, capsys):
    """Issue 30: a stop condition on an input stopped at t = 0 with exit 0; --stop-time 1e308 was an
    OverflowError (exit 3); validation checked its --json/--markdown places after its 2-minute run."""
    detumble = str(ssp_paths["detumble"])
    assert main(["run", detumble, "--stop-when", "detumble.enabled"]) == 2
    assert "stop condition 'detumble.enabled' must be an output of its component (its causality is input)" in \
        capsys.readouterr().err
    assert main(["run", detumble, "--stop-time", "1e308"]) == 2
    assert "more communication steps than can be counted" in capsys.readouterr().err
    assert main(["validation", "--ssp-dir", str(ssp_paths["detumble"].parent), "--json",
                 str(tmp_path / "missing" / "v.json")]) == 2
    assert f"--json {tmp_path / 'missing' / 'v.json'}: folder" in capsys.readouterr().err
    assert main(["validation", "--ssp-dir", str(ssp_paths["detumble"].parent), "--markdown",
                 str(tmp_path / "v.txt")]) == 2
    assert "unknown format '.txt' (expected .md or .markdown)" in capsys.readouterr().err

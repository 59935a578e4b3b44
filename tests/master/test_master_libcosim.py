"""Our Jacobi algorithm against libcosim's fixed-step algorithm (libcosim runs in a subprocess)."""
import numpy as np
import pytest

from master_fixtures import helpers as h
from paths import DATA
import system_ssp

pytest.importorskip("libcosimpy")
libcosim_rows = h.libcosim_rows


@pytest.fixture(scope="session")
def fmus(tmp_path_factory):
    return h.build_fixture_fmus(tmp_path_factory.mktemp("master_fmus"))


def _conn(name, kind):
    return f'<ssd:Connector name="{name}" kind="{kind}"><ssc:Real/></ssd:Connector>'


def test_jacobi_matches_libcosim(fmus, tmp_path):
    # i1: x' = u, u = gain.y = -0.5 * i1.x + 0.2 ; i2: x' = i1.x ; g2 = 3 * i2.x (feedthrough at the end)
    el = (h.component("i1", "integ.fmu", _conn("u", "input") + _conn("x", "output"),
                      '<ssd:ParameterBinding source="i1.ssv"/>')
          + h.component("gain", "gain.fmu", _conn("u", "input") + _conn("y", "output"),
                        '<ssd:ParameterBinding source="gain.ssv"/>')
          + h.component("i2", "integ.fmu", _conn("u", "input") + _conn("x", "output"))
          + h.component("g2", "gain.fmu", _conn("u", "input") + _conn("y", "output"),
                        '<ssd:ParameterBinding source="g2.ssv"/>'))
    co = (h.connection("i1.x", "gain.u") + h.connection("gain.y", "i1.u") + h.connection("i1.x", "i2.u")
          + h.connection("i2.x", "g2.u"))
    files = {"i1.ssv": h.ssv_text([("x0", "Real", "1.5", None)]),
             "gain.ssv": h.ssv_text([("k", "Real", "-0.5", None), ("b", "Real", "0.2", None)]),
             "g2.ssv": h.ssv_text([("k", "Real", "3", None)])}
    folder = tmp_path / "sys"
    h.write_system(folder, fmus, {"integ.fmu": "integrator", "gain.fmu": "gain"}, h.ssd_text(el, co),
                   extra_files=files)
    names = ["i1.x", "i1.u", "gain.y", "i2.x", "g2.y"]
    step, n = 0.05, 40
    ref = libcosim_rows(folder, step, n, names, tmp_path)
    r = system_ssp.simulate(folder / "SystemStructure.ssd", step_size=step, stop_time=n * step, algorithm="jacobi")
    ours = np.column_stack([r.data[name][1:] for name in names])
    assert ours.shape == ref.shape
    np.testing.assert_allclose(ours, ref, rtol=0, atol=1e-9)
    # and it is a genuine Jacobi trajectory (differs from Gauss-Seidel)
    gs = system_ssp.simulate(folder / "SystemStructure.ssd", step_size=step, stop_time=n * step)
    assert abs(gs.data["i2.x"][-1] - r.data["i2.x"][-1]) > 1e-6


def test_libcosim_demo_crane_runs_on_its_own_step_and_equals_libcosim(tmp_path):
    """libcosim's own demo system, as its authors wrote it: the step is only in OSP's annotation
    (baseStepSize 1e-4) and the two FMUs form a feedthrough loop, so a fixed-step Jacobi run as
    libcosim's algorithm is. Nothing passed but a stop time: ours must take both from the file.

    The two masters differ in the last bit of the times they pass: libcosim counts integer
    nanoseconds and steps by t(k+1) - t(k), ours passes t = k h and exactly h. The crane amplifies
    that from 1 ulp at the third step to 1e-13 of each signal's size at 0.05 s and 1e-8 at 0.5 s;
    with libcosim's time arithmetic patched into ours, the runs were bitwise equal over 1 s."""
    ssp = DATA / "libcosim" / "demo.ssp"
    names = [f"{comp}.{var}[{i}]" for comp, var in (("CraneController", "p_Crane.e"),
                                                     ("KnuckleBoomCrane", "p_Crane.f"),
                                                     ("KnuckleBoomCrane", "Act_Limits")) for i in (1, 2, 3)]
    n = 500  # 0.05 s
    ref = libcosim_rows(ssp, "file", n, names, tmp_path)
    own = system_ssp.simulate(ssp, outputs=names)  # the file's own experiment: two steps
    assert own.steps == 2 and own.stop_time == 2e-4
    np.testing.assert_array_equal(np.column_stack([own.data[name][1:] for name in names]), ref[:2])
    r = system_ssp.simulate(ssp, stop_time=0.05, outputs=names)
    assert r.step_size == 1e-4 and r.algorithm == "jacobi" and r.steps == n
    assert r.step_size_source == f"osp:FixedStepAlgorithm baseStepSize at {ssp}!/SystemStructure.ssd:75"
    ours = np.column_stack([r.data[name][1:] for name in names])
    assert ours.shape == ref.shape == (n, 9)
    assert np.ptp(ref, axis=0).min() > 0  # every signal moves: the comparison is not of constants
    size = np.abs(ref).max(axis=0)
    assert (np.abs(ours - ref) / size).max() < 1e-9


def test_reference_fmus_mixed_with_ours_equal_libcosim(fmus, tmp_path):
    """A system of FMUs from three origins: the Reference FMUs VanDerPol and Feedthrough (C, from
    the Modelica project) and our gain and integrator (Python, our runtime), chained:
    vdp.x0 -> ft (passes it through) -> gain (y = -0.5 u + 0.2) -> integ. Jacobi, against libcosim."""
    import shutil
    folder = tmp_path / "sys"
    h.write_system(folder, fmus, {"gain.fmu": "gain", "integ.fmu": "integrator"}, h.ssd_text(
        h.component("vdp", "VanDerPol.fmu", _conn("x0", "output") + _conn("x1", "output"))
        + h.component("ft", "Feedthrough.fmu", _conn("Float64_continuous_input", "input")
                      + _conn("Float64_continuous_output", "output"))
        + h.component("gain", "gain.fmu", _conn("u", "input") + _conn("y", "output"),
                      '<ssd:ParameterBinding source="gain.ssv"/>')
        + h.component("integ", "integ.fmu", _conn("u", "input") + _conn("x", "output")),
        h.connection("vdp.x0", "ft.Float64_continuous_input") + h.connection("ft.Float64_continuous_output", "gain.u")
        + h.connection("gain.y", "integ.u")),
        extra_files={"gain.ssv": h.ssv_text([("k", "Real", "-0.5", None), ("b", "Real", "0.2", None)])})
    for m in ("VanDerPol", "Feedthrough"):
        shutil.copy(DATA / "reference_fmus" / "2.0" / f"{m}.fmu", folder / "resources" / f"{m}.fmu")
    names = ["vdp.x0", "vdp.x1", "ft.Float64_continuous_output", "gain.y", "integ.x"]
    step, n = 0.05, 100
    ref = libcosim_rows(folder, step, n, names, tmp_path)
    r = system_ssp.simulate(folder / "SystemStructure.ssd", step_size=step, stop_time=n * step, algorithm="jacobi")
    ours = np.column_stack([r.data[name][1:] for name in names])
    assert np.ptp(ours, axis=0).min() > 0.05  # every signal moves
    np.testing.assert_allclose(ours, ref, rtol=0, atol=1e-12)

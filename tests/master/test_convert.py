"""`neighbor-cosim convert`: a system written in SSP 2.0 (or back in 1.0) runs as before; the
files say the version asked for and pass that version's schemas (the master checks them)."""
import zipfile

import numpy as np
import pytest
from lxml import etree

import system_ssp
from system_ssp import cli
from system_ssp.errors import SSPError
from system_ssp.tools.convert import convert_system


def versions(ssp):
    """{member: [version of every SSP root element in it]} of an .ssp's SSD, SSV and SSM files."""
    out = {}
    with zipfile.ZipFile(ssp) as z:
        for name in z.namelist():
            if name.endswith((".ssd", ".ssv", ".ssm")):
                root = etree.fromstring(z.read(name))
                out[name] = [el.get("version") for el in root.iter() if isinstance(el.tag, str)
                             and etree.QName(el).localname in ("SystemStructureDescription", "ParameterSet",
                                                                "ParameterMapping")]
    return out


def test_detumble_in_ssp2_and_back_runs_the_same(ssp_paths, tmp_path, capsys):
    two, one = tmp_path / "detumble2.ssp", tmp_path / "detumble1.ssp"
    assert cli.main(["convert", str(ssp_paths["detumble"]), "--ssp-version", "2.0", "--out", str(two)]) == 0
    assert "SSP 2.0 (8 files: SystemStructure.ssd, parameters/detumble_case1.ssv" in capsys.readouterr().out
    assert {v for vs in versions(two).values() for v in vs} == {"2.0"}
    convert_system(two, "1.0", one)
    assert {v for vs in versions(one).values() for v in vs} == {"1.0"}
    runs = [system_ssp.simulate(p, stop_time=1.5) for p in (ssp_paths["detumble"], two, one)]
    for r in runs[1:]:
        assert r.names == runs[0].names
        for name in r.names:
            np.testing.assert_array_equal(r.data[name], runs[0].data[name])


def test_ssp2_sized_types_become_ssp1_types(ssp_paths, tmp_path):
    folder = tmp_path / "sys"
    with zipfile.ZipFile(ssp_paths["detumble"]) as z:
        z.extractall(folder)
    for path in [folder / "SystemStructure.ssd", *folder.rglob("*.ssv")]:
        text = path.read_text().replace('version="1.0"', 'version="2.0"')
        text = text.replace('<?xml version="2.0"', '<?xml version="1.0"')
        path.write_text(text.replace("<ssc:Real", "<ssc:Float64").replace("<ssv:Real ", "<ssv:Float64 "))
    assert "<ssc:Float64" in (folder / "SystemStructure.ssd").read_text()
    convert_system(folder / "SystemStructure.ssd", "1.0", tmp_path / "back.ssp")
    with zipfile.ZipFile(tmp_path / "back.ssp") as z:
        text = z.read("SystemStructure.ssd").decode()
    assert "Float64" not in text and "<ssc:Real" in text
    a = system_ssp.simulate(ssp_paths["detumble"], stop_time=0.3)
    b = system_ssp.simulate(tmp_path / "back.ssp", stop_time=0.3)
    assert a.names == b.names
    for name in a.names:
        np.testing.assert_array_equal(a.data[name], b.data[name])


def test_convert_refuses_before_writing(ssp_paths, tmp_path):
    out = tmp_path / "x.ssp"
    with pytest.raises(SSPError, match=r"--ssp-version '3.0': expected one of 1.0, 2.0"):
        convert_system(ssp_paths["detumble"], "3.0", out)
    with pytest.raises(SSPError, match=r"--out .*x.txt"):
        convert_system(ssp_paths["detumble"], "2.0", tmp_path / "x.txt")
    assert not out.exists() and not (tmp_path / "x.txt").exists()

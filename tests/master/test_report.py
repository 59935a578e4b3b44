"""Reports (issue 29): one HTML file per run (`run --report`), opened in a real browser (headless
Chromium): the figures render, the console stays quiet, no network is used; mode bands and the
thesis comparison's shading."""
import matplotlib.image
import numpy as np

from browser import open_page
from system_ssp.cli import main
from system_ssp.master import report


def test_run_report_renders_in_a_browser(ssp_paths, tmp_path, capsys):
    page = tmp_path / "detumble.html"
    assert main(["run", str(ssp_paths["detumble"]), "--outputs", "dynamics.omega_BN_B[1],detumble.torque_cmd_B[1]",
                 "--report", str(page)]) == 0
    assert f"report:      {page}" in capsys.readouterr().out
    text = page.read_text()
    assert "<script src=" not in text and "stop condition detumble.done" in text
    dom, console = open_page(page, screenshot=tmp_path / "detumble.png")
    assert console == [], console
    assert dom.count('class="main-svg"') >= 2  # plotly drew the figure
    assert "dynamics.omega_BN_B[1]" in dom and "N.m" in dom and "neighbor-cosim" in dom
    shot = matplotlib.image.imread(tmp_path / "detumble.png")
    assert shot.std() > 0.05  # a page, not a blank screen


def test_html_plot_renders_in_a_browser(ssp_paths, tmp_path):
    csv = tmp_path / "run.csv"
    assert main(["run", str(ssp_paths["detumble"]), "--output", str(csv)]) == 0
    assert main(["plot", str(csv), "dynamics.q_BN*", "--out", str(tmp_path / "q.html")]) == 0
    dom, console = open_page(tmp_path / "q.html")
    assert console == [] and dom.count('class="main-svg"') >= 2


def test_report_rejects_what_it_cannot_write(ssp_paths, tmp_path, capsys):
    assert main(["run", str(ssp_paths["detumble"]), "--report", str(tmp_path / "r.pdf")]) == 2
    assert "unknown format '.pdf' (expected .html)" in capsys.readouterr().err
    assert main(["run", str(ssp_paths["detumble"]), "--report", str(tmp_path / "nowhere" / "r.html")]) == 2


def test_mode_bands_fold_short_spans_and_tables_shade_far_rows():
    t = np.arange(10.0)
    codes = np.array([1, 1, 1, 2, 1, 1, 3, 3, 3, 3])
    assert report.bands(t, codes, {1: "idle", 3: "deorbit"}) == [
        (0.0, 3.0, "idle"), (3.0, 4.0, "2"), (4.0, 6.0, "idle"), (6.0, 9.0, "deorbit")]
    assert report.bands(t, codes, {1: "idle", 3: "deorbit"}, shortest=1.5) == [(0.0, 6.0, "idle"),
                                                                            (6.0, 9.0, "deorbit")]
    html = report.markdown("title line\n| quantity | ours | thesis | difference |\n|---|---|---|---|\n"
                           "| burn | 40.1 | 38.7 | +3.6 % |\n| slew | 30 | 20 | +50.0 % |\n", far_beyond=10.0)
    assert html.count("<table>") == 1 and "<p>title line</p>" in html
    assert html.count('class="far"') == 1 and html.index('class="far"') > html.index("burn")

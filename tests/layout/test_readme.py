"""The README keeps its promises (issue 54): its test command is the one CI runs, word for word,
and it stays a short front page (the reference material is in docs/)."""
import re

from paths import REPO


def _commands():
    text = (REPO / "README.md").read_text()
    return text, re.findall(r"```bash\n(.*?)\n```", text, re.S)


def test_readme_test_command_is_what_ci_runs():
    text, blocks = _commands()
    test_command = next(block for block in blocks if "pytest" in block)
    assert "\n" not in test_command, test_command  # one line a user pastes
    ci_lines = (REPO / ".ci" / "run").read_text().splitlines()
    assert test_command in ci_lines, f".ci/run must run the README's test command as written: {test_command}"


def test_readme_is_a_front_page():
    text, blocks = _commands()
    assert len(text.splitlines()) <= 200
    for target in re.findall(r"\]\(([^)#]+)(?:#[^)]*)?\)", text):
        if not target.startswith("http"):
            assert (REPO / target).exists(), f"README links to {target}, which is not there"

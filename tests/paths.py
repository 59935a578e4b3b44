"""Where the tests find the repository's files (tests/ is on sys.path, see pyproject.toml)."""
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
TESTS = REPO / "tests"
DATA = TESTS / "data"
SYSTEMS = REPO / "system_ssp" / "systems"
MASTER_FIXTURES = TESTS / "master" / "master_fixtures"
SHARED = REPO.parent / "shared"  # the shared reference data beside the repository (not shipped)

"""Shared pytest set-up: hypothesis without wall-clock deadlines (CI machines are noisy);
``--update-goldens`` to rewrite golden-image baselines."""

import pytest
from hypothesis import HealthCheck, settings

settings.register_profile("rend3r", deadline=None, suppress_health_check=[HealthCheck.too_slow])
settings.load_profile("rend3r")


def pytest_addoption(parser: pytest.Parser) -> None:
    parser.addoption(
        "--update-goldens",
        action="store_true",
        default=False,
        help="Rewrite the golden-image baselines under programs/golden/ instead of checking them.",
    )


@pytest.fixture
def update_goldens(request: pytest.FixtureRequest) -> bool:
    """True when pytest ran with ``--update-goldens``."""
    return bool(request.config.getoption("--update-goldens"))

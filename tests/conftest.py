"""Shared pytest set-up: hypothesis without wall-clock deadlines (CI machines are noisy)."""

from hypothesis import HealthCheck, settings

settings.register_profile("rend3r", deadline=None, suppress_health_check=[HealthCheck.too_slow])
settings.load_profile("rend3r")
